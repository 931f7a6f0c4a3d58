// A run: drives a Simulation over a scene and writes its outputs into a run directory
//   scene.json (as run), forces.csv, frames/frame_NNNNN.vdb (+ .vti and frames.pvd, and
//   points_NNNNN.vdb with outputs.points), run.json
// The directory is built under a temporary name beside the target and renamed into place when the
// run completes, so a previous run is never overwritten silently and readers never see half a run.
#pragma once
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace furrow {

class Simulation;

struct RunProgress {
  double fraction = 0.0;  // of the end criterion (time or displacement)
  double time_s = 0.0;
  int64_t steps = 0;
  double wall_s = 0.0;
  double eta_s = 0.0;     // < 0 while unknown
  size_t particles = 0;
  double dt_s = 0.0;
  double particle_steps_per_s = 0.0;  // the solver loop's rate in this segment (start-up aside)
};

struct RunOptions {
  std::string out_dir;          // final run directory
  bool force = false;           // replace an existing out_dir (only once the new run completed)
  bool write_paraview = true;   // .vti per frame + frames.pvd beside the VDB frames
  double progress_interval_s = 0.5;  // wall seconds between progress callbacks
  std::function<void(const RunProgress&)> progress;
  // Called from the running thread after frame `index` is stored complete at `path` (inside the
  // temporary directory until the run is renamed into place): a viewer can follow the run.
  std::function<void(int64_t index, const std::string& path)> frame_written;
  // Checkpoints: the run's whole state saved in DIR.partial-PID/checkpoint every
  // `checkpoint_interval_s` wall seconds (0: never) and when stop_requested() returns true (polled
  // after every step; run_scene then returns with RunSummary::stopped). `resume`: continue from the
  // checkpoint of this scene in a DIR.partial-* left by a stopped or killed run, bit-identically;
  // without one the run starts afresh.
  double checkpoint_interval_s = 0.0;
  std::function<bool()> stop_requested;
  bool resume = false;
  // resume a checkpoint another build of Furrow wrote (refused otherwise: the run would not be
  // bit-identical to an uninterrupted one); run.json then says so ("resumed_across_builds")
  bool resume_any_build = false;
  // Test hook: called after every step, before the step is checked and recorded.
  std::function<void(Simulation&)> after_step;
};

// Per-body force summary over the scene's averaging window.
// forces.csv's header: force and torque (of the media on the body, about its origin, counter-
// clockwise) averaged over the row's interval; position, angle and velocities at the row's time
inline constexpr const char* kForcesHeader =
    "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m,torque_N_m_per_m,angle_deg,vx_m_s,vy_m_s,omega_rad_s";

struct BodyForceSummary {
  std::string name;
  Vec2 mean_N_per_m{0, 0};   // mean over the window (NaN when the window saw no step)
  Vec2 peak_N_per_m{0, 0};   // per component, the value of largest magnitude over the run
  double mean_torque_N = 0.0, peak_torque_N = 0.0;  // N m per metre, likewise
  int64_t window_samples = 0;
};

struct RunSummary {
  nlohmann::json run_json;  // what run.json holds (stopped: only steps and end_time_s)
  std::vector<BodyForceSummary> bodies;
  std::string out_dir;            // stopped: the DIR.partial-PID holding the checkpoint
  bool stopped = false;           // stop_requested() ended the run before its end
  int64_t resumed_from_step = -1; // the checkpoint's step when resumed, else -1
};

// Throws std::runtime_error when out_dir exists and !force, when an output cannot be written, or
// (resume) when a DIR.partial-* checkpoint belongs to another scene, to a process still running
// or (without resume_any_build) to another build.
RunSummary run_scene(const Scene& scene, const RunOptions& options);

// The resolved scene without what cannot change a run's results (solver.threads: runs are
// bit-identical for any thread count; outputs.movies: rendered from the frames afterwards): two
// runs are of the same scene when these are equal. outputs.points is left out when false, so
// scenes from before the key keep their hash.
nlohmann::json result_defining_json(const Scene& scene);
// FNV-1a 64 of result_defining_json(scene).dump() as 16 hex digits; run.json's "scene_hash", so a
// finished run directory says which scene it completed without reparsing its scene.json.
std::string scene_hash(const Scene& scene);

// The DIR.partial-* directories that hold a run checkpoint (stopped or killed runs of out_dir).
std::vector<std::string> checkpoint_dirs(const std::string& out_dir);

// Whether process `pid` exists on this machine (a DIR.partial-PID still being written).
bool process_running(long pid);

// This program's build: Furrow's version and a hash of the running executable, or of the Python
// module that holds the engine (checkpoints and run.json record it; the same sources built the
// same way give the same id).
const std::string& build_id();

// Peak resident memory of this process (bytes).
size_t peak_resident_bytes();

}  // namespace furrow
