// Re-rendering stored frames (OpenVDB files from the field store): movies, single PNGs and
// contact sheets, all with one colour range fixed over the frames involved.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "render/field_panels.hpp"
#include "render/frame_renderer.hpp"

namespace furrow::render {

struct FrameScan {
  FieldRange range;             // over every active cell of every frame scanned
  std::vector<double> times_s;  // one per frame
  int time_decimals = 3;        // enough to tell consecutive frames apart (at least 3)
};

// Reads each frame once for its range and time. Throws naming the file that fails to read or
// lacks the field.
FrameScan scan_frames(const std::vector<std::string>& frame_paths, const std::string& field);
// The same for several fields, reading each frame once: one scan per field, in order.
std::vector<FrameScan> scan_frames(const std::vector<std::string>& frame_paths, const std::vector<std::string>& fields);

// Decimals that tell consecutive times apart: max(3, digits of the smallest spacing).
int time_decimals_for(const std::vector<double>& times_s);

using FrameProgress = std::function<void(size_t done, size_t total)>;

// Frames per second that make a movie of `frames` frames last about kMovieSeconds: 10 s for 20-600
// frames, 20 s for 1200; at least 2 and at most 60 frames per second (which browsers play).
constexpr double kMovieSeconds = 10.0;
double movie_fps(size_t frames);

// Renders every frame with `style` and encodes them at `fps` into `out_path` (see MovieWriter:
// H.264 yuv420p with faststart, even sizes, atomic publish, no overwrite unless asked), and writes
// the last image as a poster PNG beside it (movies/strain_rate.mp4 -> movies/strain_rate.png;
// refused up front when that file exists and overwrite is off).
void render_movie(const std::vector<std::string>& frame_paths, const FrameStyle& style, const std::string& out_path,
                  double fps, bool overwrite, const FrameProgress& progress = {});

// The same with several fields side by side (PanelsRenderer); style.width/height is the movie's size.
void render_movie(const std::vector<std::string>& frame_paths, const PanelsStyle& style, const std::string& out_path,
                  double fps, bool overwrite, const FrameProgress& progress = {});

// Several runs side by side: panel k of `style` draws run k's frames (runs[k], the same count for
// every run; the caller pairs them by time). Poster as above.
void render_movie(const std::vector<std::vector<std::string>>& runs, const PanelsStyle& style,
                  const std::string& out_path, double fps, bool overwrite, const FrameProgress& progress = {});
std::vector<std::string> render_pngs(const std::vector<std::vector<std::string>>& runs, const PanelsStyle& style,
                                     const std::string& out_dir, bool overwrite, const FrameProgress& progress = {});

// One PNG per frame in `out_dir` (created if missing), named like the frame file
// (frame_00042.vdb -> frame_00042.png). Returns the paths written.
std::vector<std::string> render_pngs(const std::vector<std::string>& frame_paths, const FrameStyle& style,
                                     const std::string& out_dir, bool overwrite, const FrameProgress& progress = {});
std::vector<std::string> render_pngs(const std::vector<std::string>& frame_paths, const PanelsStyle& style,
                                     const std::string& out_dir, bool overwrite, const FrameProgress& progress = {});

// The frames as tiles in a grid of `columns` (0: about square), each tile labelled with its time,
// above one shared colorbar. style.width is the sheet width; tiles keep style's aspect ratio.
RgbImage render_contact_sheet(const std::vector<std::string>& frame_paths, const FrameStyle& style, int columns,
                              const FrameProgress& progress = {});
// Several fields: one such sheet per field (each with its colorbar, tiles shaped
// style.width / fields x style.height), side by side in style.width; no force plot.
RgbImage render_contact_sheet(const std::vector<std::string>& frame_paths, const PanelsStyle& style, int columns,
                              const FrameProgress& progress = {});

}  // namespace furrow::render
