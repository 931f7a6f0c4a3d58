// The editor's preview: a short run of the edited scene in a background thread, by the engine's
// own run code (engine/run) into a fresh run directory, and the view following its stored frames
// as they are written (read back from the frame files, never from the solver).
#pragma once
#include <nlohmann/json.hpp>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "engine/scene/scene.hpp"

namespace furrow::cli {

// What a preview may cost: a few seconds of CPU, whatever the scene.
struct PreviewCaps {
  double seconds = 0.2;          // simulated time at most
  size_t max_particles = 20000;  // dx is doubled (while the scene stays valid) until below this
  int64_t max_steps = 4000;      // solver.max_steps at most
  int frames = 20;               // frames over the previewed time
};

// The scene as previewed: end time, dx and steps capped, a frame every seconds/frames, pressure
// stored (what the view shows: the bed has it from its first frame). `what`, when given, says
// which caps changed the scene (for the result line). Throws SceneError if the capped scene is
// not valid.
Scene preview_scene(const Scene& scene, const PreviewCaps& caps, nlohmann::json* what = nullptr);

class PreviewRun {
 public:
  // Starts `scene` (as given: cap it first) into out_dir in a background thread. Throws
  // std::runtime_error naming out_dir when it exists: a preview never replaces anything.
  PreviewRun(const Scene& scene, const std::string& out_dir);
  ~PreviewRun();  // waits for the run
  PreviewRun(const PreviewRun&) = delete;
  PreviewRun& operator=(const PreviewRun&) = delete;

  bool done() const { return done_; }
  // The newest stored frame: its number and where to read it now (in the run's temporary
  // directory while it runs, in out_dir after); -1 and "" before the first.
  std::pair<int64_t, std::string> latest() const;
  // Waits for the end: {"ok": true, "path", "frames", "steps", "particles", "wall_seconds"} from
  // run.json, or {"ok": false, "error"}.
  nlohmann::json finish();
  const std::string& out_dir() const { return out_dir_; }

 private:
  std::string out_dir_;
  mutable std::mutex m_;
  int64_t latest_ = -1;
  std::string latest_path_;
  std::atomic<bool> done_{false};
  nlohmann::json result_;
  std::thread thread_;
};

}  // namespace furrow::cli
