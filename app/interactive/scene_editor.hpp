// The scene editor behind `furrow edit`: an EditorState (the document as edited, always valid),
// edits as small data values (Move{"plate", {0.3, 0.2}}), and one function that applies an action
// and returns its result as JSON. An edit that would make the scene invalid is refused: the
// result has "ok": false and the SceneError text, and the state is unchanged.
#pragma once
#include <nlohmann/json.hpp>

#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <variant>
#include <vector>

#include "app/interactive/preview.hpp"
#include "engine/scene/scene.hpp"
#include "app/interactive/scene_view.hpp"

namespace furrow::cli {

// ---- actions (one per script line) ---------------------------------------------------------------
// "key.path=value", as --set; `more` are applied with it, all or none (a free DOF and its mass)
struct SetKey {
  std::string assignment;
  std::vector<std::string> more;
};
struct MoveBody { std::string body; Vec2 start_m{0, 0}; };
struct ResizeBody { std::string body; Vec2 size_m{0, 0}; };
struct SetBed { std::string bed; Vec2 min_m{0, 0}, max_m{0, 0}; };
struct Validate {};
struct Save { std::string path; bool overwrite = false; };
struct EditScreenshot { std::string path; };
struct RunPreview { std::string out_dir; double seconds = 0.2; };  // a short run of the scene as edited
using EditAction = std::variant<SetKey, MoveBody, ResizeBody, SetBed, Validate, Save, EditScreenshot, RunPreview>;

// One script line as an action; on a bad line std::nullopt and *error says what was expected
// (blank lines and comments: std::nullopt, empty error).
std::optional<EditAction> parse_edit_line(const std::string& line, std::string* error);

// `set`'s and the panel's value text for `key`: "VALUE" or "VALUE; KEY2 VALUE2; ..." as --set
// assignments, the first for `key`; ';' inside a JSON string does not split. Empty on a part
// that is not "KEY VALUE" (*error says which).
std::vector<std::string> split_assignments(const std::string& key, const std::string& text, std::string* error);

struct EditStep {
  int line = 0;
  EditAction action;
};
// Every action of a script file, parsed before any runs; throws "FILE:LINE: expected ..., got '...'".
std::vector<EditStep> parse_edit_script(const std::string& path);
extern const char* const kEditScriptHelp;

// ---- state ---------------------------------------------------------------------------------------
struct EditorState {
  std::string source;               // the scene file, or "template NAME"
  nlohmann::json doc;               // the document as edited (only valid edits reach it)
  Scene scene;                      // parse_scene(doc)
  std::string refused;              // the last refused edit's message, "" after a valid one
  std::vector<std::string> notes;   // last results, for the panel
  // a value being typed in the panel: its key and what `set` would answer ("" = accepted)
  std::string typing_key, typing_error;
  // the preview run, and its newest stored frame as the view shows it (until the next edit)
  std::shared_ptr<PreviewRun> preview;
  std::optional<render::PreviewFrame> preview_frame;
  int64_t preview_shown = -1;                        // frame number on view
  nlohmann::json preview_capped;                     // what the caps changed in the previewed scene
  std::optional<render::RangeAccumulator> preview_range;
};

// A scene file, else a template name. Throws SceneError for an invalid scene, std::runtime_error
// naming the argument when it is neither a file nor a template.
EditorState open_scene_for_edit(const std::string& file_or_template);

// Applies one action; refused edits and saves give {"ok": false, "error": ...}. A screenshot
// needs a view. A preview runs to its end here (the window runs it in the background instead:
// start_preview, follow_preview, finish_preview).
nlohmann::json apply_edit(EditorState& s, const EditAction& a, render::SceneView* view);

// Starts a preview of the scene as edited (capped by PreviewCaps) into out_dir in the background;
// {"ok": false, "error"} when one is running or out_dir exists, else null.
nlohmann::json start_preview(EditorState& s, const RunPreview& a);
// Reads the preview's newest stored frame when there is a new one; true when it did.
bool follow_preview(EditorState& s);
// Once the preview run has ended (at once if `wait`): its result line, the last frame shown;
// null while it runs or when there is none.
nlohmann::json finish_preview(EditorState& s, bool wait);
// Where the window's button previews: SCENE.preview beside the scene (NAME.preview here for a
// template), or the first free SCENE.preview_2, _3, ...
std::string preview_dir_for(const std::string& scene_arg);

// A value typed in the panel is the script's `set KEY VALUE`: while typing it is only checked
// (typing_error becomes the message `set` would refuse it with, the scene stays) and null is
// returned; on Enter it is applied as `set` and its result returned. Nothing open: null.
nlohmann::json panel_edit(EditorState& s, const render::PanelChanges& e);

// What the panel shows: every leaf key of the resolved scene, the status and the notes.
render::ScenePanel editor_panel(const EditorState& s);

}  // namespace furrow::cli

namespace furrow::cli {

// ---- window (app/interactive/edit_window.cpp) ---------------------------------------------------
struct EditWindowOptions {
  std::vector<EditStep> script;  // replayed in the window first
  std::string script_path;
  bool exit_after_script = false;
  std::string save_path;         // where Ctrl+S saves (never over an existing file)
  std::string scene_arg;         // the scene file or template, for the preview button's directory
};

// The editor on a display: the same view; drag a body with the left mouse button to move it (an
// invalid position is refused live and shown in the panel), the wheel scrolls the panel, a click
// on a key opens its value for typing (checked as typed like `set`, Enter sets it, Escape
// cancels), "Preview run" runs the scene briefly in the background into preview_dir_for(scene)
// and shows its frames as they are stored, Ctrl+S saves to `save_path`, Esc quits. Each result is
// one JSON line on `out`. Returns 1 when a script action failed, else 0; throws
// std::runtime_error when no window can be opened.
int run_edit_window(EditorState& s, render::SceneView& view, const EditWindowOptions& options, std::ostream& out,
                    std::ostream& err);

}  // namespace furrow::cli
