#include "render/image_io.hpp"

#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

namespace fs = std::filesystem;

namespace furrow::render {

RgbImage::RgbImage(int w, int h, uint8_t r, uint8_t g, uint8_t b) : width(w), height(h) {
  rgb.resize(size_t(w) * size_t(h) * 3);
  for (size_t k = 0; k < rgb.size(); k += 3) {
    rgb[k] = r;
    rgb[k + 1] = g;
    rgb[k + 2] = b;
  }
}

void RgbImage::blit(const RgbImage& src, int x0, int y0) {
  const int xa = std::max(0, x0), xb = std::min(width, x0 + src.width);
  if (xa >= xb) return;
  for (int y = std::max(0, y0); y < std::min(height, y0 + src.height); ++y)
    std::memcpy(at(xa, y), src.at(xa - x0, y - y0), size_t(xb - xa) * 3);
}

std::string temp_path_for(const std::string& final_path) {
  static std::atomic<unsigned> counter{0};
  fs::path p(final_path);
  // Keep the extension last: ffmpeg picks the container from it.
  std::string name = "." + p.stem().string() + ".tmp-" + std::to_string(getpid()) + "-" +
                     std::to_string(counter++) + p.extension().string();
  return (p.parent_path() / name).string();
}

void publish_file(const std::string& temp_path, const std::string& final_path, bool overwrite) {
  int rc = 0;
  if (overwrite) {
    rc = ::rename(temp_path.c_str(), final_path.c_str());
  } else {
    // Atomic "move unless the target exists"; fall back to a check on file systems without it.
    rc = ::renameat2(AT_FDCWD, temp_path.c_str(), AT_FDCWD, final_path.c_str(), RENAME_NOREPLACE);
    if (rc != 0 && (errno == EINVAL || errno == ENOSYS)) {
      if (fs::exists(final_path)) {
        errno = EEXIST;
      } else {
        rc = ::rename(temp_path.c_str(), final_path.c_str());
      }
    }
  }
  if (rc != 0) {
    const int err = errno;
    std::error_code ec;
    fs::remove(temp_path, ec);
    if (err == EEXIST)
      throw std::runtime_error(final_path + ": already exists; not overwriting it");
    throw std::runtime_error(final_path + ": cannot write (" + std::strerror(err) + ")");
  }
}

std::string next_free_path(const std::string& path) {
  if (!fs::exists(path)) return path;
  fs::path p(path);
  for (int k = 2;; ++k) {
    fs::path cand = p.parent_path() / (p.stem().string() + "_" + std::to_string(k) + p.extension().string());
    if (!fs::exists(cand)) return cand.string();
  }
}

void write_png(const RgbImage& image, const std::string& path, bool overwrite) {
  if (image.width <= 0 || image.height <= 0) throw std::runtime_error(path + ": refusing to write an empty image");
  if (!overwrite && fs::exists(path)) throw std::runtime_error(path + ": already exists; not overwriting it");
  vtkNew<vtkImageData> data;
  data->SetDimensions(image.width, image.height, 1);
  data->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* dst = static_cast<uint8_t*>(data->GetScalarPointer());
  const size_t row = size_t(image.width) * 3;
  for (int y = 0; y < image.height; ++y)  // VTK wants bottom row first
    std::memcpy(dst + size_t(image.height - 1 - y) * row, image.at(0, y), row);
  const std::string tmp = temp_path_for(path);
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(tmp.c_str());
  writer->SetInputData(data);
  writer->Write();
  if (writer->GetErrorCode() != 0 || !fs::exists(tmp)) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error(path + ": writing PNG failed (is the directory writable?)");
  }
  publish_file(tmp, path, overwrite);
}

RgbImage read_png(const std::string& path) {
  if (!fs::exists(path)) throw std::runtime_error(path + ": no such file");
  vtkNew<vtkPNGReader> reader;
  if (!reader->CanReadFile(path.c_str())) throw std::runtime_error(path + ": not a PNG file");
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* data = reader->GetOutput();
  int dims[3];
  data->GetDimensions(dims);
  auto* s = vtkUnsignedCharArray::SafeDownCast(data->GetPointData()->GetScalars());
  if (!s) throw std::runtime_error(path + ": unsupported PNG pixel type (expected 8-bit)");
  const int nc = s->GetNumberOfComponents();
  RgbImage img(dims[0], dims[1]);
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < dims[0]; ++x) {
      const uint8_t* px = s->GetPointer(0) + (size_t(dims[1] - 1 - y) * size_t(dims[0]) + size_t(x)) * size_t(nc);
      uint8_t* d = img.at(x, y);
      for (int c = 0; c < 3; ++c) d[c] = px[nc >= 3 ? c : 0];
    }
  return img;
}

}  // namespace furrow::render
