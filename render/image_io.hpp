// Images in memory and on disk. Files are published atomically: written under a temporary name in
// the target directory, then moved into place, so a crash never leaves a half-written output.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace furrow::render {

// 8-bit RGB, top row first (the order PNG and ffmpeg's rawvideo expect).
struct RgbImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // width * height * 3
  RgbImage() = default;
  RgbImage(int w, int h, uint8_t r = 0, uint8_t g = 0, uint8_t b = 0);
  const uint8_t* at(int x, int y) const { return &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
  uint8_t* at(int x, int y) { return &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
  // Copies `src` with its top-left corner at (x, y); parts outside are clipped.
  void blit(const RgbImage& src, int x, int y);
};

// A unique temporary name next to `final_path` (same directory, so rename is atomic).
std::string temp_path_for(const std::string& final_path);

// Moves `temp_path` to `final_path`. With overwrite == false an existing `final_path` is left
// untouched and std::runtime_error is thrown naming it (the temp file is removed either way on
// failure).
void publish_file(const std::string& temp_path, const std::string& final_path, bool overwrite);

// `path` if nothing exists there, else the first free "stem_2.ext", "stem_3.ext", ...
std::string next_free_path(const std::string& path);

// PNG via VTK's writer, published atomically. Throws naming the path on failure.
void write_png(const RgbImage& image, const std::string& path, bool overwrite = false);
RgbImage read_png(const std::string& path);

}  // namespace furrow::render
