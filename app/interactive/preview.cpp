#include "app/interactive/preview.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "engine/io/field_store.hpp"
#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

Scene preview_scene(const Scene& scene, const PreviewCaps& caps, nlohmann::json* what) {
  Scene s = scene;
  nlohmann::json changed = nlohmann::json::object();
  if (s.solver.end_time_s > caps.seconds) {
    s.solver.end_time_s = caps.seconds;
    changed["solver.end_time_s"] = caps.seconds;
    // forces are averaged over the whole preview: the scene's window may lie beyond its end
    s.outputs.average_from_s = 0.0, s.outputs.average_to_s = -1.0;
    s.outputs.average_from_m = s.outputs.average_to_m = -1.0;
    changed["outputs.average_window"] = "the whole run";
  }
  // coarser cells while too many particles, as long as the scene stays valid (a body or bed
  // thinner than the cells would not be)
  while (estimate_particle_count(s) > caps.max_particles) {
    Scene coarser = s;
    coarser.domain.dx_m *= 2.0;
    try {
      coarser = parse_scene(scene_to_json(coarser), "preview of " + scene.name);
    } catch (const SceneError&) {
      break;
    }
    s = coarser;
    changed["domain.dx_m"] = s.domain.dx_m;
  }
  if (s.solver.max_steps > caps.max_steps) {
    s.solver.max_steps = int(caps.max_steps);
    changed["solver.max_steps"] = caps.max_steps;
  }
  s.outputs.frame_interval_s = s.solver.end_time_s / std::max(1, caps.frames);
  if (std::find(s.outputs.fields.begin(), s.outputs.fields.end(), "pressure") == s.outputs.fields.end())
    s.outputs.fields.push_back("pressure");
  s.outputs.movies.clear();  // a preview shows frames; movies would only cost time
  if (what) *what = changed;
  return parse_scene(scene_to_json(s), "preview of " + scene.name);  // still valid, or SceneError says why
}

PreviewRun::PreviewRun(const Scene& scene, const std::string& out_dir) : out_dir_(out_dir) {
  if (fs::exists(out_dir)) throw std::runtime_error(out_dir + " already exists: a preview never replaces anything");
  thread_ = std::thread([this, scene] {
    nlohmann::json r;
    try {
      RunOptions o;
      o.out_dir = out_dir_;
      o.write_paraview = false;
      o.frame_written = [this](int64_t index, const std::string& path) {
        std::lock_guard<std::mutex> lock(m_);
        latest_ = index, latest_path_ = path;
      };
      const RunSummary summary = run_scene(scene, o);
      const nlohmann::json& j = summary.run_json;
      r = {{"ok", true}, {"path", out_dir_}, {"frames", j.at("frames")}, {"steps", j.at("steps")},
           {"particles", j.at("particles")}, {"end_time_s", j.at("end_time_s")}, {"wall_seconds", j.at("wall_seconds")}};
    } catch (const std::exception& e) {
      r = {{"ok", false}, {"error", std::string("preview run: ") + e.what()}};
    }
    std::lock_guard<std::mutex> lock(m_);
    result_ = r;
    done_ = true;
  });
}

PreviewRun::~PreviewRun() {
  if (thread_.joinable()) thread_.join();
}

std::pair<int64_t, std::string> PreviewRun::latest() const {
  std::lock_guard<std::mutex> lock(m_);
  if (latest_ < 0) return {-1, ""};
  // once done and renamed into place, the frames are read from the run directory itself
  if (done_ && result_.value("ok", false)) return {latest_, frame_path(out_dir_, latest_)};
  return {latest_, latest_path_};
}

nlohmann::json PreviewRun::finish() {
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(m_);
  return result_;
}

}  // namespace furrow::cli
