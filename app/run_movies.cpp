#include "app/run_movies.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "engine/field_store.hpp"
#include "render/frame_renderer.hpp"
#include "render/movie_writer.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

render::ForcePanel read_force_panel(const std::string& run_dir, const Scene& scene) {
  render::ForcePanel panel;
  const std::string path = (fs::path(run_dir) / "forces.csv").string();
  std::ifstream in(path);
  if (!in) return panel;
  std::string line;
  std::getline(in, line);
  if (line.rfind("t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m", 0) != 0)
    throw std::runtime_error(path + ": unexpected header '" + line + "'");
  // the resisting force is the component against the body's direction of travel
  std::map<std::string, size_t> index;
  std::vector<Vec2> start;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string t, name, x, y, fx, fy;
    if (!std::getline(ss, t, ',') || !std::getline(ss, name, ',') || !std::getline(ss, x, ',') ||
        !std::getline(ss, y, ',') || !std::getline(ss, fx, ',') || !std::getline(ss, fy))
      throw std::runtime_error(path + ": malformed row '" + line + "'");
    auto it = index.find(name);
    if (it == index.end()) {
      it = index.emplace(name, panel.series.size()).first;
      panel.series.push_back({name, {}, {}, {}});
      start.emplace_back(std::stod(x), std::stod(y));
    }
    const Vec2 pos(std::stod(x), std::stod(y)), f(std::stod(fx), std::stod(fy));
    Vec2 dir(0.0, -1.0);
    for (const auto& b : scene.bodies)
      if (b.name == name) {
        const Vec2 v = b.motion.kind == Motion::Kind::ConstantVelocity || b.motion.path.empty()
                           ? b.motion.velocity_m_s
                           : b.motion.path.front().velocity_m_s;
        if (v.norm() > 0.0) dir = v.normalized();
      }
    auto& s = panel.series[it->second];
    s.t_s.push_back(std::stod(t));
    s.x.push_back(1e3 * (pos - start[it->second]).norm());
    s.y.push_back(-f.dot(dir));
  }
  return panel;
}

void render_run_movies(const std::string& run_dir, const Scene& scene, bool quiet) {
  if (scene.outputs.movies.empty()) return;
  const auto paths = list_frames(run_dir);
  if (paths.empty()) return;
  std::vector<FieldFrame> frames;
  for (const auto& p : paths) frames.push_back(read_frame(p));
  const render::ForcePanel panel = read_force_panel(run_dir, scene);
  fs::create_directories(fs::path(run_dir) / "movies");
  for (const auto& field : scene.outputs.movies) {
    render::RangeAccumulator acc(field);
    for (const auto& f : frames) acc.add(f);
    render::FrameStyle style;
    style.field = field;
    style.range = acc.range();
    if (!panel.series.empty()) style.panel = panel;
    render::FrameRenderer renderer(style);
    const std::string out = (fs::path(run_dir) / "movies" / (field + ".mp4")).string();
    // 10 frames per second of movie, at least a second long
    render::MovieWriter movie(out, style.width, style.height, 10.0);
    for (const auto& f : frames) movie.add_frame(renderer.render(f));
    movie.finish();
    if (!quiet) std::cerr << "movie: " << out << " (" << frames.size() << " frames)\n";
  }
}

}  // namespace furrow::cli
