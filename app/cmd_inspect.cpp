// `furrow inspect`: argument handling only; the inspector's state, actions and drawing live in
// app/interactive/inspector.
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "app/commands.hpp"
#include "app/interactive/inspector.hpp"
#include "app/interactive/inspector_window.hpp"
#include "render/script.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

int view_options(const Parsed& p, const std::string& command, ViewOptions* o) {
  o->headless = p.has("--headless");
  if (o->headless && !p.has("--script")) throw UsageError("--headless needs --script FILE (the actions to replay)");
  if (!o->headless && !render::window_unavailable_reason().empty()) {
    std::cerr << "furrow " << command << ": " << render::window_unavailable_reason() << "; use --headless --script FILE\n";
    return 2;
  }
  if (p.has("--exit-after-script") && (o->headless || !p.has("--script")))
    throw UsageError("--exit-after-script is for a --script replayed in the window (without --headless)");
  if (p.has("--size")) {
    parse_size(p.get("--size"), &o->width, &o->height);
    if (o->width < 400 || o->height < 300)
      throw UsageError("--size: the " + command + " view needs at least 400x300, got '" + p.get("--size") + "'");
  }
  return 0;
}

namespace {

int inspect_main(const Parsed& p) {
  const std::string run_dir = p.positional[0];
  if (!fs::is_directory(run_dir)) {
    std::cerr << "furrow inspect: run directory '" << run_dir << "' does not exist\n";
    return 1;
  }
  ViewOptions o;
  if (const int status = view_options(p, "inspect", &o)) return status;
  const bool headless = o.headless;
  const int width = o.width, height = o.height;
  // the whole script is checked before anything runs
  const std::string script = p.get("--script");
  const std::vector<render::ScriptStep> steps = script.empty() ? std::vector<render::ScriptStep>{}
                                                               : render::parse_inspect_script(script);

  render::InspectorState state = render::open_run(run_dir, p.get("--field"));
  render::InspectorView view(width, height, !p.has("--cells"));
  if (!headless) {
    render::WindowOptions w;
    w.script = steps, w.script_path = script, w.exit_after_script = p.has("--exit-after-script");
    return render::run_inspector_window(state, view, w, std::cout, std::cerr);
  }
  return render::replay_script(
      steps, script, "furrow inspect",
      [&](const render::ScriptStep& step) { return render::apply_action(state, step.action, &view); }, std::cout,
      std::cerr);
}

}  // namespace

Command command_inspect() {
  return {"inspect",
          "inspect a stored run in a window, or replay a script headless: probe, profile, measure, screenshot",
          "furrow inspect RUN_DIR [--headless] [--script FILE [--exit-after-script]] [--field NAME] [--size WxH] [--cells]",
          std::string("Opens the frames stored in RUN_DIR (frames/*.vdb, forces.csv). In a window (a display is\n"
                      "needed): the frame and the inspector panel; pick the field and frame in the panel, click\n"
                      "on the bed to probe, Left/Right for the previous/next frame, S for a screenshot\n"
                      "(inspect.png, inspect_2.png, ...), Esc or Q to quit; a --script is replayed there first and\n"
                      "its screenshots are read back from the window. With --headless, replays the actions of\n"
                      "FILE against an off-screen view. Either way each result is one JSON object on stdout (SI units;\n"
                      "every object has \"action\", a script's also its \"line\"; a value where there is no\n"
                      "material is null). The whole script is checked first: a bad line is an error naming FILE, the line and\n"
                      "what was expected, and nothing runs. Colour ranges are fixed over the run, as in movies.\n"
                      "A screenshot never replaces an existing file.\n\n") +
              render::kInspectScriptHelp,
          {{"--headless", false, false, "no window: replay --script off-screen"},
           {"--script", true, false, "the actions to replay, one per line", "FILE"},
           {"--exit-after-script", false, false, "close the window once the script has run"},
           {"--field", true, false, "field selected at the start (default: strain_rate, else pressure, ...)", "NAME"},
           {"--size", true, false, "screenshot size (default 1280x720; the panel takes a third, up to 420 px)", "WxH"},
           {"--cells", false, false, "draw each cell as one flat colour (default: blended within the material)"},
           {"--smooth", false, false, "blend fields within the material: the default, kept for old scripts"}},
          1,
          1,
          inspect_main};
}

}  // namespace furrow::cli
