// Run directories that sweep and study reuse across invocations: is a directory a finished run
// of this scene, what did it produce, and which half-written ones can go.
#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "app/sweep.hpp"
#include "engine/scene/scene.hpp"

namespace furrow::cli {

std::string read_text(const std::filesystem::path& p);

enum class RunDirState {
  absent,      // nothing there
  incomplete,  // no run.json: the run did not finish (it holds no result)
  same_scene,  // a finished run of this scene (threads aside)
  other_scene  // a finished run of something else: never reused, never overwritten
};
struct RunDirMatch {
  RunDirState state = RunDirState::absent;
  std::string why;  // other_scene: the differing keys (JSON pointers), or why scene.json does not load
};

// run.json's scene_hash decides when it equals this scene's; otherwise (older runs, or another
// scene) the stored scene.json is compared with this one key by key.
RunDirMatch match_run_dir(const std::filesystem::path& dir, const Scene& scene);

// What a finished run directory holds: run.json and the sweep metrics of its forces.csv.
struct FinishedRun {
  nlohmann::json run_json;
  sweep::RunMetrics metrics;
};
FinishedRun read_finished_run(const std::filesystem::path& dir, const Scene& scene);

// Removes NAME.partial-PID directories that killed runs left in `dir` (PID no longer running here).
void remove_stale_partials(const std::filesystem::path& dir);

}  // namespace furrow::cli
