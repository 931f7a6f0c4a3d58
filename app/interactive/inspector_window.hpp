// The inspector in a window on a display (GLFW + X11). Every image is the off-screen
// InspectorView's (OSMesa + VTK + ImGui), shown with XPutImage: the window has no GL context,
// because Mesa's OSMesa library, linked first for VTK, owns the process's gl* symbols.
// Mouse and keys drive the same actions as a script:
//   panel: field and frame pickers;  click on the field: probe there;
//   Left/Right: previous/next frame;  W: wedge overlay on/off;  S: screenshot (inspect.png, inspect_2.png, ... in the current
//   folder);  Esc or Q: quit.
// Each result is printed as one JSON line, as in headless mode.
#pragma once
#include <ostream>
#include <string>
#include <vector>

#include "app/interactive/inspector.hpp"

namespace furrow::render {

struct WindowOptions {
  std::vector<ScriptStep> script;  // replayed in the window first (screenshots read the window back)
  std::string script_path;         // for error messages
  bool exit_after_script = false;
};

// Whether this build can open a window at all (GLFW and X11 found at configure time).
bool inspector_window_available();
// Why no window can open here ("this furrow was built without GLFW/X11 ...", "no display ..."),
// or "" when one can; for the inspector and the editor alike.
std::string window_unavailable_reason();

// Runs until the window closes; returns the exit status (1 when a script line fails, after
// printing the error naming the script, line and cause to `err`). Throws std::runtime_error when
// no window can be opened (no display, or a build without GLFW/X11).
int run_inspector_window(InspectorState& s, InspectorView& view, const WindowOptions& options, std::ostream& out,
                         std::ostream& err);

}  // namespace furrow::render
