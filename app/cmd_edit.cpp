// `furrow edit`: argument handling only; the editor's state and actions live in app/scene_editor,
// the drawing in render/scene_view.
#include <filesystem>
#include <iostream>

#include "app/commands.hpp"
#include "app/scene_editor.hpp"
#include "render/inspector_window.hpp"
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
    return run_edit_window(state, view, w, std::cout, std::cerr);
  }
  return render::replay_script(
      steps, script, "furrow edit", [&](const EditStep& step) { return apply_edit(state, step.action, &view); },
      std::cout, std::cerr);
}

}  // namespace

Command command_edit() {
  return {"edit",
          "edit a scene by script: move and resize bodies, set keys and bed corners, validate, save, screenshot",
          "furrow edit SCENE.json|TEMPLATE [--headless] [--script FILE [--exit-after-script]] [--size WxH]",
          std::string("Opens SCENE.json (or the template of that name, see 'furrow templates') for editing.\n"
                      "The view draws the domain and its grid, the beds,\n"
                      "the walls and the bodies at their start positions to scale, beside a panel listing every\n"
                      "scene key with its value and the validation status. On a display the view opens in a\n"
                      "window: drag a body with the left mouse button to move it (a position that would make\n"
                      "the scene invalid is refused and the panel shows why), the wheel scrolls the panel,\n"
                      "Ctrl+S saves to SCENE.edited.json\n"
                      "(never over an existing file), Esc quits; a --script is replayed there first. With\n"
                      "--headless, the --script FILE is replayed off-screen. Each result is one JSON object on\n"
                      "stdout with \"action\", \"ok\" and the script \"line\". The whole script is checked first:\n"
                      "a bad line is an error naming FILE, the line and what was expected, exit 1, and nothing\n"
                      "runs. The scene is only ever valid: an edit that would make it invalid is refused with\n"
                      "the message of 'furrow validate' (naming the key) and the scene stays as it was. Saves and\n"
                      "screenshots never replace an existing file (save PATH --overwrite does). Exit status 1\n"
                      "when any action was refused or failed.\n\n") +
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
