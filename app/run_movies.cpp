#include "app/run_movies.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "app/commands.hpp"
#include "engine/io/field_store.hpp"
#include "render/field_movie.hpp"
#include "render/force_series.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

void render_run_movies(const std::string& run_dir, const Scene& scene, bool quiet) {
  if (scene.outputs.movies.empty() && scene.outputs.layout.name.empty()) return;
  const auto paths = list_frames(run_dir);
  if (paths.empty()) return;
  // the raw trace: since the safety net stopped kicking points (2026-12-04) it carries no single-step
  // ticks, and what fluctuates in it is the flow's
  const render::ForcePanel panel = render::read_force_panel((fs::path(run_dir) / "forces.csv").string());
  fs::create_directories(fs::path(run_dir) / "movies");
  for (const auto& field : scene.outputs.movies) {
    const render::FrameScan scan = render::scan_frames(paths, field);
    render::FrameStyle style;
    style.field = field;
    style.range = scan.range;  // fixed over the whole movie
    style.time_decimals = scan.time_decimals;
    if (!panel.series.empty()) style.panel = panel;
    const std::string out = (fs::path(run_dir) / "movies" / (field + ".mp4")).string();
    render::render_movie(paths, style, out, render::movie_fps(paths.size()), false);
    if (!quiet) std::cerr << "movie: " << out << " (" << paths.size() << " frames)\n";
  }
  const MovieLayout& lay = scene.outputs.layout;
  std::string unstored;  // a layout field this run did not store (velocity_x/y read velocity)
  for (const auto& f : lay.fields) {
    const std::string stored = f.rfind("velocity_", 0) == 0 ? "velocity" : f;
    if (std::find(scene.outputs.fields.begin(), scene.outputs.fields.end(), stored) == scene.outputs.fields.end())
      unstored = f;
  }
  if (!lay.name.empty() && !unstored.empty() && !quiet)
    std::cerr << "movie: " << lay.name << " left out: its field '" << unstored << "' is not stored in this run\n";
  if (!lay.name.empty() && unstored.empty()) {
    // the paper's layout of this case: the same path as `furrow render RUN_DIR --layout`
    static const Command render = command_render();
    Parsed layout;
    layout.command = &render;
    layout.positional = {run_dir};
    layout.values["--layout"] = {};
    layout.values["--out"] = {(fs::path(run_dir) / "movies" / (scene.outputs.layout.name + ".mp4")).string()};
    if (render.main(layout) != 0) throw std::runtime_error(run_dir + ": the layout movie failed (above)");
  }
}

}  // namespace furrow::cli
