// `furrow inspect`: argument handling only; the inspector's state, actions and drawing live in
// render/inspector.
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "app/commands.hpp"
#include "render/inspector.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

namespace {

int inspect_main(const Parsed& p) {
  const std::string run_dir = p.positional[0];
  if (!fs::is_directory(run_dir)) {
    std::cerr << "furrow inspect: run directory '" << run_dir << "' does not exist\n";
    return 1;
  }
  if (!p.has("--headless")) {
    const char* display = std::getenv("DISPLAY");
    std::cerr << "furrow inspect: the interactive window is not built yet"
              << (display && *display ? "" : " (and there is no DISPLAY)")
              << "; use --headless --script FILE\n";
    return 2;
  }
  if (!p.has("--script")) throw UsageError("--headless needs --script FILE (the actions to replay)");
  int width = 1280, height = 720;
  if (p.has("--size")) {
    const std::string s = p.get("--size");
    const size_t x = s.find('x');
    char* end1 = nullptr;
    char* end2 = nullptr;
    const long w = x == std::string::npos ? 0 : std::strtol(s.substr(0, x).c_str(), &end1, 10);
    const long h = x == std::string::npos ? 0 : std::strtol(s.substr(x + 1).c_str(), &end2, 10);
    if (x == std::string::npos || *end1 || *end2 || w < 400 || h < 300 || w > 8192 || h > 8192)
      throw UsageError("--size: expected WxH with W in 400..8192 and H in 300..8192, got '" + s + "'");
    width = int(w), height = int(h);
  }
  // the whole script is checked before anything runs
  const std::string script = p.get("--script");
  const std::vector<render::ScriptStep> steps = render::parse_inspect_script(script);

  render::InspectorState state = render::open_run(run_dir, p.get("--field"));
  render::InspectorView view(width, height, p.has("--smooth"));
  for (const auto& step : steps) {
    nlohmann::json r;
    try {
      r = render::apply_action(state, step.action, &view);
    } catch (const std::exception& e) {
      std::cerr << "furrow inspect: " << script << ":" << step.line << ": " << e.what() << "\n";
      return 1;
    }
    r["line"] = step.line;
    std::cout << r.dump() << "\n" << std::flush;
  }
  return 0;
}

}  // namespace

Command command_inspect() {
  return {"inspect",
          "inspect a stored run: probe, profile, measure, screenshot (headless script)",
          "furrow inspect RUN_DIR --headless --script FILE [--field NAME] [--size WxH] [--smooth]",
          std::string("Opens the frames stored in RUN_DIR (frames/*.vdb, forces.csv) and replays the actions of\n"
                      "FILE against an off-screen view, printing one JSON object per action on stdout (SI units;\n"
                      "every object has \"action\" and the script \"line\"; a value where there is no material is\n"
                      "null). The whole script is checked first: a bad line is an error naming FILE, the line and\n"
                      "what was expected, and nothing runs. Colour ranges are fixed over the run, as in movies.\n"
                      "A screenshot never replaces an existing file.\n\n") +
              render::kInspectScriptHelp,
          {{"--headless", false, false, "no window: replay --script off-screen"},
           {"--script", true, false, "the actions to replay, one per line", "FILE"},
           {"--field", true, false, "field selected at the start (default: strain_rate, else pressure, ...)", "NAME"},
           {"--size", true, false, "screenshot size (default 1280x720; the panel takes a third, up to 420 px)", "WxH"},
           {"--smooth", false, false, "draw fields smoothed within the material (display only)"}},
          1,
          1,
          inspect_main};
}

}  // namespace furrow::cli
