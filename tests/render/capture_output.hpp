// Captures what the process writes to stdout and stderr (file descriptors 1 and 2, so C, C++ and
// library output alike) while a callable runs. Render tests use it to prove GL/GLEW stay quiet.
#pragma once
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

namespace furrow::test {

template <class F>
std::string capture_output(F&& f) {
  std::fflush(stdout);
  std::fflush(stderr);
  std::cout.flush();
  std::cerr.flush();
  char path[] = "/tmp/furrow_capture_XXXXXX";
  const int fd = mkstemp(path);
  const int saved_out = dup(1), saved_err = dup(2);
  dup2(fd, 1);
  dup2(fd, 2);
  try {
    f();
  } catch (...) {
    std::fflush(stdout);
    std::fflush(stderr);
    dup2(saved_out, 1);
    dup2(saved_err, 2);
    close(saved_out);
    close(saved_err);
    close(fd);
    unlink(path);
    throw;
  }
  std::cout.flush();
  std::cerr.flush();
  std::fflush(stdout);
  std::fflush(stderr);
  dup2(saved_out, 1);
  dup2(saved_err, 2);
  close(saved_out);
  close(saved_err);
  close(fd);
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  unlink(path);
  return ss.str();
}

inline bool mentions_gl_trouble(const std::string& text) {
  std::string lower = text;
  for (auto& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
  return lower.find("glew") != std::string::npos || lower.find("error") != std::string::npos ||
         lower.find("warning") != std::string::npos;
}

}  // namespace furrow::test
