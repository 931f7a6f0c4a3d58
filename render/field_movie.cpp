#include "render/field_movie.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "engine/field_store.hpp"
#include "render/movie_writer.hpp"

namespace fs = std::filesystem;

namespace furrow::render {

namespace {
FieldFrame read_checked(const std::string& path) {
  try {
    return read_frame(path);
  } catch (const std::exception& e) {
    const std::string what = e.what();
    // the store names the file already; add it only if it did not
    throw std::runtime_error(what.find(path) == std::string::npos ? path + ": " + what : what);
  }
}

std::vector<float> checked_values(const FieldFrame& f, const std::string& field, const std::string& path) {
  try {
    return field_values(f, field);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}
}  // namespace

int time_decimals_for(const std::vector<double>& t) {
  double min_gap = 1e300;
  for (size_t k = 1; k < t.size(); ++k)
    if (t[k] > t[k - 1]) min_gap = std::min(min_gap, t[k] - t[k - 1]);
  if (min_gap >= 1e-3 || min_gap == 1e300) return 3;
  return std::clamp(int(std::ceil(-std::log10(min_gap) - 1e-9)), 3, 9);
}

FrameScan scan_frames(const std::vector<std::string>& paths, const std::string& field) {
  if (paths.empty()) throw std::runtime_error("no frames selected");
  RangeAccumulator acc(field);
  FrameScan scan;
  for (const auto& path : paths) {
    const FieldFrame f = read_checked(path);
    checked_values(f, field, path);  // names the file if the field is missing
    acc.add(f);
    scan.times_s.push_back(f.time_s);
  }
  scan.range = acc.range();
  scan.time_decimals = time_decimals_for(scan.times_s);
  return scan;
}

void render_movie(const std::vector<std::string>& paths, const FrameStyle& style, const std::string& out_path,
                  double fps, bool overwrite, const FrameProgress& progress) {
  if (paths.empty()) throw std::runtime_error(out_path + ": no frames to put in the movie");
  FrameRenderer renderer(style);
  MovieWriter movie(out_path, style.width, style.height, fps, overwrite);
  for (size_t k = 0; k < paths.size(); ++k) {
    const FieldFrame f = read_checked(paths[k]);
    checked_values(f, style.field, paths[k]);
    movie.add_frame(renderer.render(f));
    if (progress) progress(k + 1, paths.size());
  }
  movie.finish();
}

std::vector<std::string> render_pngs(const std::vector<std::string>& paths, const FrameStyle& style,
                                     const std::string& out_dir, bool overwrite, const FrameProgress& progress) {
  fs::create_directories(out_dir);
  FrameRenderer renderer(style);
  std::vector<std::string> written;
  for (size_t k = 0; k < paths.size(); ++k) {
    const FieldFrame f = read_checked(paths[k]);
    checked_values(f, style.field, paths[k]);
    const std::string out = (fs::path(out_dir) / (fs::path(paths[k]).stem().string() + ".png")).string();
    write_png(renderer.render(f), out, overwrite);
    written.push_back(out);
    if (progress) progress(k + 1, paths.size());
  }
  return written;
}

RgbImage render_contact_sheet(const std::vector<std::string>& paths, const FrameStyle& style, int columns,
                              const FrameProgress& progress) {
  if (paths.empty()) throw std::runtime_error("contact sheet: no frames selected");
  const int n = int(paths.size());
  const int cols = columns > 0 ? std::min(columns, n) : int(std::ceil(std::sqrt(double(n))));
  const int rows = (n + cols - 1) / cols;
  const int tile_w = std::max(16, style.width / cols);
  const int tile_h = std::max(16, int(std::lround(double(tile_w) * style.height / style.width)));

  FrameStyle tile = style;
  tile.width = tile_w, tile.height = tile_h;
  tile.show_colorbar = false, tile.show_title = false, tile.show_time = true;
  tile.panel.reset();
  tile.font_scale = std::max(0.7, tile_h / 720.0);  // time labels stay readable on small tiles
  FrameRenderer tiles(tile);

  // the shared legend: the colorbar band of a full-width render of the first frame
  FrameStyle legend_style = style;
  legend_style.panel.reset();
  legend_style.show_colorbar = true;
  FrameRenderer legend(legend_style);
  const FieldFrame first = read_checked(paths[0]);
  checked_values(first, style.field, paths[0]);
  const RgbImage full = legend.render(first);
  const FrameLayout& L = legend.layout();
  const int band_y0 = std::max(0, L.colorbar_y0 - 2), band_y1 = std::min(full.height, L.colorbar_y1 + 2);
  RgbImage band(full.width, band_y1 - band_y0);
  band.blit(full, 0, -band_y0);

  const auto& bg = style.background_rgb;
  RgbImage sheet(cols * tile_w, rows * tile_h + band.height, uint8_t(std::lround(255 * bg[0])),
                 uint8_t(std::lround(255 * bg[1])), uint8_t(std::lround(255 * bg[2])));
  for (int k = 0; k < n; ++k) {
    const FieldFrame f = k == 0 ? first : read_checked(paths[size_t(k)]);
    if (k > 0) checked_values(f, style.field, paths[size_t(k)]);
    sheet.blit(tiles.render(f), (k % cols) * tile_w, (k / cols) * tile_h);
    if (progress) progress(size_t(k + 1), paths.size());
  }
  sheet.blit(band, (sheet.width - band.width) / 2, rows * tile_h);
  return sheet;
}

}  // namespace furrow::render
