#include "engine/io/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace furrow {

void write_atomically(const std::string& path,
                      const std::function<void(const std::string& tmp_path)>& write) {
  static std::atomic<unsigned> counter{0};
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
  // a dot-prefixed temporary name in the same folder: same file system, and ignored by listings
  const fs::path tmp = target.parent_path() / ("." + target.filename().string() + ".tmp" +
                                               std::to_string(::getpid()) + "_" +
                                               std::to_string(counter++));
  try {
    write(tmp.string());
    fs::rename(tmp, target);
  } catch (const std::exception& e) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write " + path + ": " + e.what());
  }
}

void write_file_atomic(const std::string& path, const std::string& bytes) {
  write_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    out.close();
    if (!out) throw std::runtime_error("write to " + tmp + " failed");
  });
}

void write_text_atomically(const std::string& path, const std::string& text, bool replace,
                           const std::string& replace_hint) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw std::runtime_error(path + ": directory " + dir.string() + " does not exist");
  if (fs::is_directory(target)) throw std::runtime_error(path + ": is a directory");
  if (!replace && fs::exists(target))
    throw std::runtime_error(path + ": exists; " + replace_hint);
  const fs::path tmp = dir / ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error(path + ": cannot write " + tmp.string());
    }
  }
  // link() fails if the target appeared meanwhile, so without --force nothing is ever clobbered
  const int rc = replace ? std::rename(tmp.c_str(), target.c_str()) : ::link(tmp.c_str(), target.c_str());
  const int err = errno;
  std::error_code ec;
  if (!replace || rc != 0) fs::remove(tmp, ec);
  if (rc != 0)
    throw std::runtime_error(path + ": " + (err == EEXIST ? std::string("exists; " + replace_hint)
                                                          : std::string(std::strerror(err))));
}

}  // namespace furrow
