// `furrow edit` in a window: the off-screen SceneView shown through render/x_window.
#include <stdexcept>

#include "app/scene_editor.hpp"
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
  auto show = [&] { xw.present(view.render(s.scene, editor_panel(s))); };
  auto print = [&](const nlohmann::json& r) { out << r.dump() << "\n" << std::flush; };
  show();
  const int status = render::replay_script(
      o.script, o.script_path, "furrow edit",
      [&](const EditStep& step) {
        nlohmann::json r = apply_edit(s, step.action, &view);
        show();
        return r;
      },
      out, err);
  if (o.exit_after_script) return status;

  int dragging = -1;       // body index under the mouse since the press
  Vec2 grab(0, 0);         // mouse minus body start, kept over the drag
  nlohmann::json last;     // the drag's latest move, printed on release
  while (!glfwWindowShouldClose(xw.glfw)) {
    glfwWaitEventsTimeout(0.5);
    if (!xw.dirty) continue;
    xw.dirty = false;
    for (size_t k = 0; k < xw.keys.size(); ++k) {
      if (xw.keys[k] == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(xw.glfw, GLFW_TRUE);
      if (xw.keys[k] == GLFW_KEY_S && (xw.key_mods[k] & GLFW_MOD_CONTROL)) print(apply_edit(s, Save{o.save_path, false}, &view));
    }
    xw.keys.clear(), xw.key_mods.clear();
    double mx = 0, my = 0;
    glfwGetCursorPos(xw.glfw, &mx, &my);
    const bool down = glfwGetMouseButton(xw.glfw, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    const Vec2 p = view.layout(s.scene).to_m({mx, my});
    if (xw.clicked_left && down && dragging < 0 && mx < view.panel_x0()) {
      dragging = body_under(s.scene, p);
      if (dragging >= 0) grab = p - s.scene.bodies[size_t(dragging)].start_m;
    }
    xw.clicked_left = false;
    // every position is validated as the mouse moves: an invalid one is refused (the panel says
    // why) and the body stays at the last valid one
    if (dragging >= 0 && down) last = apply_edit(s, MoveBody{std::to_string(dragging), snapped(p - grab)}, &view);
    if (dragging >= 0 && !down) {
      if (!last.is_null()) print(last);
      dragging = -1, last = nullptr;
    }
    // the panel scrolls with the wheel over it
    render::ViewInput in;
    in.mouse_x = float(mx), in.mouse_y = float(my), in.wheel = xw.wheel, xw.wheel = 0;
    xw.present(view.render(s.scene, editor_panel(s), &in));
  }
  return status;
}

#else

int run_edit_window(EditorState&, render::SceneView&, const EditWindowOptions&, std::ostream&, std::ostream&) {
  throw std::runtime_error("this furrow was built without GLFW/X11, so it has no window; use --headless --script FILE");
}

#endif

}  // namespace furrow::cli
