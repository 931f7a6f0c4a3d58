#include "app/run_dirs.hpp"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

RunDirMatch match_run_dir(const fs::path& dir, const Scene& scene) {
  if (!fs::exists(dir)) return {RunDirState::absent, ""};
  if (!fs::exists(dir / "run.json")) return {RunDirState::incomplete, "it is not a complete run (no run.json)"};
  try {
    const auto run = nlohmann::json::parse(read_text(dir / "run.json"));
    if (run.value("scene_hash", std::string()) == scene_hash(scene)) return {RunDirState::same_scene, ""};
  } catch (const std::exception& e) {
    return {RunDirState::other_scene, std::string("its run.json does not load: ") + e.what()};
  }
  try {
    ValidationOptions v;
    v.allow_large = true;  // the scene itself was checked with the user's --yes
    const Scene stored = parse_scene_text(read_text(dir / "scene.json"), (dir / "scene.json").string(), {}, v);
    const auto patch = nlohmann::json::diff(result_defining_json(stored), result_defining_json(scene));
    if (patch.empty()) return {RunDirState::same_scene, ""};
    std::string keys;
    for (size_t i = 0; i < patch.size() && i < 3; ++i) keys += (i ? ", " : "") + patch[i].value("path", std::string("?"));
    return {RunDirState::other_scene,
            "it holds a run of a different scene (differs at " + keys + (patch.size() > 3 ? ", ..." : "") + ")"};
  } catch (const std::exception& e) {
    return {RunDirState::other_scene, std::string("its scene.json does not load: ") + e.what()};
  }
}

FinishedRun read_finished_run(const fs::path& dir, const Scene& scene) {
  FinishedRun f;
  f.run_json = nlohmann::json::parse(read_text(dir / "run.json"));
  RunSummary s;
  s.run_json = f.run_json;
  s.out_dir = dir.string();
  f.metrics = sweep::run_metrics(scene, s, sweep::read_forces_csv((dir / "forces.csv").string(), scene));
  return f;
}

void remove_stale_partials(const fs::path& dir) {
  if (!fs::exists(dir)) return;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    const auto at = name.rfind(".partial-");
    if (at == std::string::npos) continue;
    const long pid = std::strtol(name.c_str() + at + 9, nullptr, 10);
    if (process_running(pid)) continue;  // still running (another sweep or study)
    fs::remove_all(e.path());
  }
}

}  // namespace furrow::cli
