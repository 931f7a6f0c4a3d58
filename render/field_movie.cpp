#include "render/field_movie.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <stdexcept>

#include "engine/io/field_store.hpp"
#include "engine/io/point_store.hpp"
#include "render/movie_writer.hpp"
#include "render/point_splat.hpp"

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

// A stored frame with every field the image needs (else an error naming the file). A points file
// (points_NNNNN.vdb) is drawn as discs over its frame file's grid, 4 texels per cell.
FieldFrame read_with_fields(const std::string& path, const std::vector<std::string>& fields) {
  if (fs::path(path).filename().string().rfind("points_", 0) == 0) {
    const std::string name = fs::path(path).filename().string();
    const FieldFrame grid = read_checked((fs::path(path).parent_path() / ("frame_" + name.substr(7))).string());
    PointFrame points;
    try {
      points = read_points(path);
    } catch (const std::exception& e) {
      const std::string what = e.what();
      throw std::runtime_error(what.find(path) == std::string::npos ? path + ": " + what : what);
    }
    return splat_points(points, grid, 4, fields, path);
  }
  FieldFrame f = read_checked(path);
  for (const auto& field : fields) checked_values(f, field, path);
  return f;
}

std::vector<std::string> field_names(const PanelsStyle& style) {
  std::vector<std::string> names;
  for (const auto& s : style.fields) names.push_back(s.field);
  return names;
}

using DrawFrame = std::function<RgbImage(const FieldFrame&)>;
using DrawIndex = std::function<RgbImage(size_t)>;  // the k-th image of a sequence

// The poster beside a movie: movies/strain_rate.mp4 -> movies/strain_rate.png.
std::string poster_path(const std::string& movie_path) {
  return (fs::path(movie_path).parent_path() / (fs::path(movie_path).stem().string() + ".png")).string();
}

void movie_of(size_t count, int width, int height, const DrawIndex& draw, const std::string& out_path, double fps,
              bool overwrite, const FrameProgress& progress) {
  if (count == 0) throw std::runtime_error(out_path + ": no frames to put in the movie");
  const std::string poster = poster_path(out_path);
  if (!overwrite && fs::exists(poster))
    throw std::runtime_error(poster + ": already exists (the movie's poster would go there); not overwriting it");
  MovieWriter movie(out_path, width, height, fps, overwrite);
  RgbImage last;
  for (size_t k = 0; k < count; ++k) {
    last = draw(k);
    movie.add_frame(last);
    if (progress) progress(k + 1, count);
  }
  movie.finish();
  write_png(last, poster, overwrite);  // the last frame: the whole force trace, the flow developed
}

void movie_of(const std::vector<std::string>& paths, const std::vector<std::string>& fields, int width, int height,
              const DrawFrame& draw, const std::string& out_path, double fps, bool overwrite,
              const FrameProgress& progress) {
  movie_of(
      paths.size(), width, height, [&](size_t k) { return draw(read_with_fields(paths[k], fields)); }, out_path, fps,
      overwrite, progress);
}

std::vector<std::string> pngs_of(const std::vector<std::string>& names, const DrawIndex& draw,
                                 const std::string& out_dir, bool overwrite, const FrameProgress& progress) {
  fs::create_directories(out_dir);
  std::vector<std::string> written;
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string out = (fs::path(out_dir) / (fs::path(names[k]).stem().string() + ".png")).string();
    write_png(draw(k), out, overwrite);
    written.push_back(out);
    if (progress) progress(k + 1, names.size());
  }
  return written;
}

std::vector<std::string> pngs_of(const std::vector<std::string>& paths, const std::vector<std::string>& fields,
                                 const DrawFrame& draw, const std::string& out_dir, bool overwrite,
                                 const FrameProgress& progress) {
  return pngs_of(
      paths, [&](size_t k) { return draw(read_with_fields(paths[k], fields)); }, out_dir, overwrite, progress);
}

// Frame k of every run, each checked for its panel's field.
DrawIndex draw_runs(const std::vector<std::vector<std::string>>& runs, const PanelsStyle& style,
                    PanelsRenderer& renderer) {
  return [&runs, &style, &renderer](size_t k) {
    std::vector<FieldFrame> frames;
    for (size_t r = 0; r < runs.size(); ++r) frames.push_back(read_with_fields(runs[r][k], {style.fields[r].field}));
    std::vector<const FieldFrame*> ptrs;
    for (const auto& f : frames) ptrs.push_back(&f);
    return renderer.render(ptrs);
  };
}

void check_runs(const std::vector<std::vector<std::string>>& runs, const PanelsStyle& style) {
  if (runs.empty() || runs.size() != style.fields.size())
    throw std::invalid_argument(std::to_string(runs.size()) + " runs for " + std::to_string(style.fields.size()) +
                                " panels");
  for (const auto& r : runs)
    if (r.size() != runs.front().size())
      throw std::invalid_argument("side-by-side runs need the same number of frames each");
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
  return scan_frames(paths, std::vector<std::string>{field}).front();
}

std::vector<FrameScan> scan_frames(const std::vector<std::string>& paths, const std::vector<std::string>& fields) {
  if (paths.empty()) throw std::runtime_error("no frames selected");
  std::vector<RangeAccumulator> acc;
  for (const auto& field : fields) acc.emplace_back(field);
  std::vector<double> times_s;
  for (const auto& path : paths) {
    const FieldFrame f = read_with_fields(path, fields);  // names the file if a field is missing
    for (auto& a : acc) a.add(f);
    times_s.push_back(f.time_s);
  }
  std::vector<FrameScan> scans(fields.size());
  for (size_t k = 0; k < fields.size(); ++k) {
    scans[k].range = acc[k].range();
    scans[k].times_s = times_s;
    scans[k].time_decimals = time_decimals_for(times_s);
  }
  return scans;
}

void render_movie(const std::vector<std::string>& paths, const FrameStyle& style, const std::string& out_path,
                  double fps, bool overwrite, const FrameProgress& progress) {
  if (paths.empty()) throw std::runtime_error(out_path + ": no frames to put in the movie");
  FrameRenderer renderer(style);
  movie_of(paths, {style.field}, style.width, style.height, [&](const FieldFrame& f) { return renderer.render(f); },
           out_path, fps, overwrite, progress);
}

void render_movie(const std::vector<std::string>& paths, const PanelsStyle& style, const std::string& out_path,
                  double fps, bool overwrite, const FrameProgress& progress) {
  if (paths.empty()) throw std::runtime_error(out_path + ": no frames to put in the movie");
  PanelsRenderer renderer(style);
  movie_of(paths, field_names(style), style.width, style.height,
           [&](const FieldFrame& f) { return renderer.render(f); }, out_path, fps, overwrite, progress);
}

std::vector<std::string> render_pngs(const std::vector<std::string>& paths, const FrameStyle& style,
                                     const std::string& out_dir, bool overwrite, const FrameProgress& progress) {
  FrameRenderer renderer(style);
  return pngs_of(paths, {style.field}, [&](const FieldFrame& f) { return renderer.render(f); }, out_dir, overwrite,
                 progress);
}

std::vector<std::string> render_pngs(const std::vector<std::string>& paths, const PanelsStyle& style,
                                     const std::string& out_dir, bool overwrite, const FrameProgress& progress) {
  PanelsRenderer renderer(style);
  return pngs_of(paths, field_names(style), [&](const FieldFrame& f) { return renderer.render(f); }, out_dir,
                 overwrite, progress);
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

RgbImage render_contact_sheet(const std::vector<std::string>& paths, const PanelsStyle& style, int columns,
                              const FrameProgress& progress) {
  if (style.fields.empty()) throw std::invalid_argument("contact sheet: no field given");
  const int n = int(style.fields.size());
  const int block_w = style.width / n;
  std::vector<RgbImage> blocks;
  for (int k = 0; k < n; ++k) {
    FrameStyle s = style.fields[size_t(k)];
    s.width = block_w;
    s.height = style.height;  // tiles shaped like one field's panel
    s.panel.reset();
    blocks.push_back(render_contact_sheet(paths, s, columns, [&](size_t done, size_t total) {
      if (progress) progress(size_t(k) * total + done, size_t(n) * total);
    }));
  }
  int height = 0;
  for (const auto& b : blocks) height = std::max(height, b.height);
  const auto& bg = style.fields.front().background_rgb;
  RgbImage sheet(n * block_w, height, uint8_t(std::lround(255 * bg[0])), uint8_t(std::lround(255 * bg[1])),
                 uint8_t(std::lround(255 * bg[2])));
  for (int k = 0; k < n; ++k) sheet.blit(blocks[size_t(k)], k * block_w, 0);
  return sheet;
}

}  // namespace furrow::render

namespace furrow::render {

double movie_fps(size_t frames) {
  return std::clamp(double(frames) / kMovieSeconds, 2.0, 60.0);
}

void render_movie(const std::vector<std::vector<std::string>>& runs, const PanelsStyle& style,
                  const std::string& out_path, double fps, bool overwrite, const FrameProgress& progress) {
  check_runs(runs, style);
  PanelsRenderer renderer(style);
  movie_of(runs.front().size(), style.width, style.height, draw_runs(runs, style, renderer), out_path, fps, overwrite,
           progress);
}

std::vector<std::string> render_pngs(const std::vector<std::vector<std::string>>& runs, const PanelsStyle& style,
                                     const std::string& out_dir, bool overwrite, const FrameProgress& progress) {
  check_runs(runs, style);
  PanelsRenderer renderer(style);
  return pngs_of(runs.front(), draw_runs(runs, style, renderer), out_dir, overwrite, progress);
}

}  // namespace furrow::render
