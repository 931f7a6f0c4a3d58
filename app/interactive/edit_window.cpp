// `furrow edit` in a window: the off-screen SceneView shown through render/x_window.
#include <stdexcept>

#include "app/interactive/scene_editor.hpp"
#include "engine/bodies.hpp"
#include "render/script.hpp"
#include "render/x_window.hpp"  // last: X11 macros

namespace furrow::cli {

#if defined(FURROW_HAVE_GLFW) && defined(FURROW_HAVE_X11)

namespace {
// A dragged position to 0.1 mm: the mouse is no more precise, and the saved scene stays readable.
Vec2 snapped(const Vec2& p_m) { return (p_m * 1e4).array().round().matrix() / 1e4; }

// The index of the topmost body (drawn last) holding the point, or -1.
int body_under(const Scene& scene, const Vec2& p_m) {
  for (int k = int(scene.bodies.size()) - 1; k >= 0; --k)
    if (shape_sdf(scene.bodies[size_t(k)].shape, p_m - scene.bodies[size_t(k)].start_m) <= 0) return k;
  return -1;
}
}  // namespace

int run_edit_window(EditorState& s, render::SceneView& view, const EditWindowOptions& o, std::ostream& out,
                    std::ostream& err) {
  render::XWindow xw;
  render::open_window(xw, view.width(), view.height(), "furrow edit " + s.source);
  auto frame = [&]() -> const render::PreviewFrame* { return s.preview_frame ? &*s.preview_frame : nullptr; };
  auto show = [&] { xw.present(view.render(s.scene, editor_panel(s), nullptr, nullptr, frame())); };
  auto print = [&](const nlohmann::json& r) { out << r.dump() << "\n" << std::flush; };
  show();
  const int status = render::replay_script(
      o.script, o.script_path, "furrow edit",
      [&](const EditStep& step) {
        nlohmann::json r;
        if (auto* p = std::get_if<RunPreview>(&step.action)) {
          // in the window the preview's frames appear as they are stored
          r = start_preview(s, *p);
          while (r.is_null()) {
            if (follow_preview(s)) show();
            glfwWaitEventsTimeout(0.05);
            r = finish_preview(s, false);
          }
        } else {
          r = apply_edit(s, step.action, &view);
        }
        show();
        return r;
      },
      out, err);
  if (o.exit_after_script) return status;

  int dragging = -1;       // body index under the mouse since the press
  Vec2 grab(0, 0);         // mouse minus body start, kept over the drag
  nlohmann::json last;     // the drag's latest move, printed on release
  while (!glfwWindowShouldClose(xw.glfw)) {
    // while a preview runs, look for its new frames a few times a second
    glfwWaitEventsTimeout(s.preview ? 0.1 : 0.5);
    if (follow_preview(s)) xw.dirty = true;
    const nlohmann::json ended = finish_preview(s, false);
    if (!ended.is_null()) print(ended), xw.dirty = true;
    if (!xw.dirty) continue;
    xw.dirty = false;
    render::ViewInput in;
    for (size_t k = 0; k < xw.keys.size(); ++k) {
      const int key = xw.keys[k];
      const bool ctrl = xw.key_mods[k] & GLFW_MOD_CONTROL;
      // Escape cancels a value being typed, else quits
      if (key == GLFW_KEY_ESCAPE && view.editing_key().empty()) glfwSetWindowShouldClose(xw.glfw, GLFW_TRUE);
      if (key == GLFW_KEY_S && ctrl) print(apply_edit(s, Save{o.save_path, false}, &view));
      const std::pair<int, render::ViewKey> text_keys[] = {
          {GLFW_KEY_ENTER, render::ViewKey::Enter},       {GLFW_KEY_KP_ENTER, render::ViewKey::Enter},
          {GLFW_KEY_ESCAPE, render::ViewKey::Escape},     {GLFW_KEY_BACKSPACE, render::ViewKey::Backspace},
          {GLFW_KEY_DELETE, render::ViewKey::Delete},     {GLFW_KEY_LEFT, render::ViewKey::Left},
          {GLFW_KEY_RIGHT, render::ViewKey::Right},       {GLFW_KEY_HOME, render::ViewKey::Home},
          {GLFW_KEY_END, render::ViewKey::End},           {GLFW_KEY_TAB, render::ViewKey::Tab}};
      for (const auto& [glfw_key, view_key] : text_keys)
        if (key == glfw_key) in.keys.push_back(view_key);
      in.ctrl = in.ctrl || ctrl;
    }
    in.chars = xw.chars;
    xw.keys.clear(), xw.key_mods.clear(), xw.chars.clear();
    double mx = 0, my = 0;
    glfwGetCursorPos(xw.glfw, &mx, &my);
    const bool down = glfwGetMouseButton(xw.glfw, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    const Vec2 p = view.layout(s.scene).to_m({mx, my});
    // a drag starts where the button went down and ends where it came up, whatever else the
    // frame saw in between
    if (xw.clicked_left && dragging < 0 && xw.press_x < view.panel_x0()) {
      const Vec2 at = view.layout(s.scene).to_m({xw.press_x, xw.press_y});
      dragging = body_under(s.scene, at);
      if (dragging >= 0) grab = at - s.scene.bodies[size_t(dragging)].start_m;
    }
    in.clicked_left = xw.clicked_left && mx >= view.panel_x0();
    xw.clicked_left = false;
    // every position is validated as the mouse moves: an invalid one is refused (the panel says
    // why) and the body stays at the last valid one
    if (dragging >= 0 && down) last = apply_edit(s, MoveBody{std::to_string(dragging), snapped(p - grab)}, &view);
    if (dragging >= 0 && !down) {
      if (xw.released_left) {
        const Vec2 at = view.layout(s.scene).to_m({xw.release_x, xw.release_y});
        last = apply_edit(s, MoveBody{std::to_string(dragging), snapped(at - grab)}, &view);
      }
      if (!last.is_null()) print(last);
      dragging = -1, last = nullptr;
    }
    xw.released_left = false;
    // the panel: wheel scrolling, a clicked key's value typed (checked as typed, set on Enter),
    // the preview button
    in.mouse_x = float(mx), in.mouse_y = float(my), in.wheel = xw.wheel, xw.wheel = 0;
    in.mouse_down[0] = down;
    render::PanelChanges changes;
    const std::string typed_before = s.typing_key + "=" + s.typing_error;
    xw.present(view.render(s.scene, editor_panel(s), &in, &changes, frame()));
    const nlohmann::json set = panel_edit(s, changes);
    if (!set.is_null()) {
      print(set);
      if (set["ok"] == true) view.stop_editing(), s.typing_key.clear(), s.typing_error.clear();
    }
    if (changes.preview) {
      const nlohmann::json r = start_preview(s, RunPreview{preview_dir_for(o.scene_arg), 0.2});
      if (!r.is_null()) print(r);
    }
    // the panel shows what was just checked or set, and the preview's first frames
    if (!set.is_null() || changes.preview || typed_before != s.typing_key + "=" + s.typing_error) xw.dirty = true;
  }
  return status;
}

#else

int run_edit_window(EditorState&, render::SceneView&, const EditWindowOptions&, std::ostream&, std::ostream&) {
  throw std::runtime_error("this furrow was built without GLFW/X11, so it has no window; use --headless --script FILE");
}

#endif

}  // namespace furrow::cli
