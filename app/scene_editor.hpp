// The scene editor behind `furrow edit`: an EditorState (the document as edited, always valid),
// edits as small data values (Move{"plate", {0.3, 0.2}}), and one function that applies an action
// and returns its result as JSON. An edit that would make the scene invalid is refused: the
// result has "ok": false and the SceneError text, and the state is unchanged.
#pragma once
#include <nlohmann/json.hpp>

#include <optional>
#include <ostream>
#include <string>
#include <variant>
#include <vector>

#include "engine/scene.hpp"
#include "render/scene_view.hpp"

namespace furrow::cli {

// ---- actions (one per script line) ---------------------------------------------------------------
struct SetKey { std::string assignment; };  // "key.path=value", as --set
struct MoveBody { std::string body; Vec2 start_m{0, 0}; };
struct ResizeBody { std::string body; Vec2 size_m{0, 0}; };
struct SetBed { std::string bed; Vec2 min_m{0, 0}, max_m{0, 0}; };
struct Validate {};
struct Save { std::string path; bool overwrite = false; };
struct EditScreenshot { std::string path; };
using EditAction = std::variant<SetKey, MoveBody, ResizeBody, SetBed, Validate, Save, EditScreenshot>;

// One script line as an action; on a bad line std::nullopt and *error says what was expected
// (blank lines and comments: std::nullopt, empty error).
std::optional<EditAction> parse_edit_line(const std::string& line, std::string* error);

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
};

// A scene file, else a template name. Throws SceneError for an invalid scene, std::runtime_error
// naming the argument when it is neither a file nor a template.
EditorState open_scene_for_edit(const std::string& file_or_template);

// Applies one action; refused edits and saves give {"ok": false, "error": ...}. A screenshot
// needs a view.
nlohmann::json apply_edit(EditorState& s, const EditAction& a, render::SceneView* view);


// A value typed in the panel is the script's `set KEY VALUE`: while typing it is only checked
// (typing_error becomes the message `set` would refuse it with, the scene stays) and null is
// returned; on Enter it is applied as `set` and its result returned. Nothing open: null.
nlohmann::json panel_edit(EditorState& s, const render::PanelChanges& e);

// What the panel shows: every leaf key of the resolved scene, the status and the notes.
render::ScenePanel editor_panel(const EditorState& s);

}  // namespace furrow::cli

namespace furrow::cli {

// ---- window (app/edit_window.cpp) ---------------------------------------------------------------
struct EditWindowOptions {
  std::vector<EditStep> script;  // replayed in the window first
  std::string script_path;
  bool exit_after_script = false;
  std::string save_path;         // where Ctrl+S saves (never over an existing file)
};

// The editor on a display: the same view; drag a body with the left mouse button to move it (an
// invalid position is refused live and shown in the panel), the wheel scrolls the panel, a click
// on a key opens its value for typing (checked as typed like `set`, Enter sets it, Escape
// cancels), Ctrl+S saves to `save_path`, Esc quits. Each result is one JSON line on `out`. Returns 1 when a script action failed, else 0; throws
// std::runtime_error when no window can be opened.
int run_edit_window(EditorState& s, render::SceneView& view, const EditWindowOptions& options, std::ostream& out,
                    std::ostream& err);

}  // namespace furrow::cli
