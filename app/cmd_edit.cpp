// `furrow edit`: argument handling only; the editor's state and actions live in
// app/interactive/scene_editor, the drawing in app/interactive/scene_view.
#include <filesystem>
#include <iostream>

#include "app/commands.hpp"
#include "app/interactive/scene_editor.hpp"
#include "app/interactive/inspector_window.hpp"
#include "render/script.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

namespace {

// Where Ctrl+S saves in the window: SCENE.edited.json beside the file, NAME.edited.json here
// for a template.
std::string edited_path(const std::string& scene) {
  fs::path p(scene);
  if (!fs::is_regular_file(p)) return p.filename().string() + ".edited.json";
  return (p.parent_path() / (p.stem().string() + ".edited.json")).string();
}

int edit_main(const Parsed& p) {
  const std::string scene = p.positional[0];
  ViewOptions o;
  if (const int status = view_options(p, "edit", &o)) return status;
  const bool headless = o.headless;
  const int width = o.width, height = o.height;
  // the whole script is checked before the scene is even read
  const std::string script = p.get("--script");
  const std::vector<EditStep> steps = script.empty() ? std::vector<EditStep>{} : parse_edit_script(script);
  EditorState state = open_scene_for_edit(scene);
  render::SceneView view(width, height);
  if (!headless) {
    EditWindowOptions w;
    w.script = steps, w.script_path = script, w.exit_after_script = p.has("--exit-after-script");
    w.save_path = edited_path(scene);
    w.scene_arg = scene;
    return run_edit_window(state, view, w, std::cout, std::cerr);
  }
  return render::replay_script(
      steps, script, "furrow edit", [&](const EditStep& step) { return apply_edit(state, step.action, &view); },
      std::cout, std::cerr);
}

}  // namespace

Command command_edit() {
  return {"edit",
          "edit a scene in a window (drag bodies, type values) or by script: move, resize, set keys and beds, validate, save, screenshot, preview",
          "furrow edit SCENE.json|TEMPLATE [--headless] [--script FILE [--exit-after-script]] [--size WxH]",
          std::string("Opens SCENE.json (or the template of that name, see 'furrow templates') for editing.\n"
                      "The view draws the domain and its grid, the beds, the walls and the bodies at their\n"
                      "start positions to scale, beside a panel listing every scene key with its value and the\n"
                      "validation status. On a display it opens in a window: drag a body with the left mouse\n"
                      "button to move it (a position that would make the scene invalid is refused and the panel\n"
                      "shows why), the wheel scrolls the panel, a click on a key opens its value for typing\n"
                      "(checked as typed like 'set', Enter sets it, Escape cancels), \"Preview run\" runs the scene\n"
                      "briefly in the background into SCENE.preview and shows its frames as they are stored,\n"
                      "Ctrl+S saves to SCENE.edited.json (never over an existing file), Esc quits; a --script is\n"
                      "replayed there first. With --headless, the\n"
                      "--script FILE is replayed off-screen. Each result is one JSON object on stdout with\n"
                      "\"action\", \"ok\" and the script \"line\". The whole script is checked first: a bad line is\n"
                      "an error naming FILE, the line and what was expected, exit 1, and nothing runs. The scene\n"
                      "is only ever valid: an edit that would make it invalid is refused with the message of\n"
                      "'furrow validate' (naming the key) and the scene stays as it was. Saves and screenshots\n"
                      "never replace an existing file (save PATH --overwrite does). Exit status 1 when any\n"
                      "action was refused or failed.\n\n") +
              kEditScriptHelp,
          {{"--headless", false, false, "no window: replay --script off-screen"},
           {"--script", true, false, "the actions to replay, one per line", "FILE"},
           {"--exit-after-script", false, false, "close the window once the script has run"},
           {"--size", true, false, "screenshot size (default 1280x720; the panel takes two fifths, up to 520 px)", "WxH"}},
          1,
          1,
          edit_main};
}

}  // namespace furrow::cli
