// The scene and sweep arguments that run, sweep and study share (--set, --threads, --yes, --vary,
// --ladder, --jobs): in the app core so the Python module parses them with the same code.
#include <algorithm>
#include <cstdlib>

#include "app/commands.hpp"
#include "engine/scene/scene_io.hpp"

namespace furrow::cli {

// Shared by run, sweep and demo: resolves scene, output directory and overrides the same way.
Scene load_scene_for_cli(const Parsed& p, const std::string& path) {
  std::vector<std::string> sets = p.all("--set");
  if (p.has("--threads")) sets.push_back("solver.threads=" + p.get("--threads"));
  ValidationOptions v;
  v.allow_large = p.has("--yes");
  return load_scene(path, sets, v);
}

Scene load_varied_scene(const Parsed& p, const std::string& path, const std::vector<sweep::Vary>& varies,
                        const std::vector<size_t>& combo, const std::string& option) {
  Parsed q = p;
  for (const auto& s : sweep::run_overrides(varies, combo)) q.values["--set"].push_back(s);
  try {
    return load_scene_for_cli(q, path);
  } catch (const SceneError& e) {
    for (size_t k = 0; k < varies.size(); ++k)
      for (size_t i = 0; i < varies[k].keys.size(); ++i) {
        const std::string a = varies[k].keys[i] + "=" + varies[k].per_key[combo[k]][i];
        if (e.note == "set by --set " + a || e.note == "in --set " + a)
          throw SceneError(e.file, e.path, e.value, e.expected, "set by " + option + " " + varies[k].spec + " as " + a,
                           e.line, e.column, e.byte);
      }
    throw;
  }
}

std::vector<sweep::Vary> parse_varies(const Parsed& p, const std::string& option, const std::string& if_none) {
  std::vector<sweep::Vary> varies;
  std::vector<std::string> keys;
  for (const auto& spec : p.all(option)) {
    try {
      varies.push_back(sweep::parse_vary(spec));
    } catch (const sweep::VaryError& e) {
      throw UsageError(option + ": " + e.what());
    }
    for (const auto& k : varies.back().keys) {
      if (std::find(keys.begin(), keys.end(), k) != keys.end())
        throw UsageError(option + ": key " + k + " is varied twice");
      keys.push_back(k);
    }
  }
  if (varies.empty()) throw UsageError(if_none);
  return varies;
}

int parse_jobs(const Parsed& p) {
  const std::string s = p.get("--jobs", "1");
  char* end = nullptr;
  const long n = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || n < 1 || n > 1024)
    throw UsageError("--jobs " + s + ": expected a whole number of parallel runs in [1, 1024]");
  return int(n);
}

long long sigterm_self_at(const char* name) {
  const char* v = std::getenv(name);
  if (!v || !*v) return 0;
  char* end = nullptr;
  const long long n = std::strtoll(v, &end, 10);
  return *end == '\0' && n > 0 ? n : 0;
}

std::vector<OptionSpec> scene_run_options() {
  return {{"--set", true, true, "override a scene value, e.g. --set domain.dx_m=0.005", "key.path=value"},
          {"--threads", true, false, "worker threads (default: all cores); same as --set solver.threads=N", "N"},
          {"--yes", false, false, "accept very large scenes (particle or step estimates over the limits)"},
          {"--quiet", false, false, "no progress output"}};
}

}  // namespace furrow::cli
