#include "app/interactive/inspector_window.hpp"

#include <cstdlib>
#include <stdexcept>

#include "render/image_io.hpp"

#include "render/x_window.hpp"  // last: X11 macros

namespace furrow::render {

std::string window_unavailable_reason() {
  if (!inspector_window_available()) return "this furrow was built without GLFW/X11 and has no window";
  const char* display = std::getenv("DISPLAY");
  if (!(display && *display)) return "no display (DISPLAY is not set) for the window";
  return "";
}

#if defined(FURROW_HAVE_GLFW) && defined(FURROW_HAVE_X11)

bool inspector_window_available() { return true; }

int run_inspector_window(InspectorState& s, InspectorView& view, const WindowOptions& options, std::ostream& out,
                         std::ostream& err) {
  XWindow xw;
  open_window(xw, view.width(), view.height(), "furrow inspect " + s.run_dir);
  auto print = [&](nlohmann::json r) { out << r.dump() << "\n" << std::flush; };
  // a screenshot in a window is what the display shows, read back
  auto screenshot = [&](const std::string& path) {
    xw.present(view.render(s));
    return write_screenshot(s, path, xw.capture(), view);
  };

  xw.present(view.render(s));
  for (const auto& step : options.script) {
    try {
      nlohmann::json r;
      if (auto* shot = std::get_if<Screenshot>(&step.action)) r = screenshot(shot->path);
      else r = apply_action(s, step.action, &view);
      r["line"] = step.line;
      print(r);
    } catch (const std::exception& e) {
      err << options.script_path << ":" << step.line << ": " << e.what() << "\n";
      return 1;
    }
    xw.present(view.render(s));
  }
  if (options.exit_after_script) return 0;

  while (!glfwWindowShouldClose(xw.glfw)) {
    glfwWaitEventsTimeout(0.5);
    if (!xw.dirty) continue;
    xw.dirty = false;
    std::vector<InspectAction> actions;
    for (int key : xw.keys) {
      if (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q) glfwSetWindowShouldClose(xw.glfw, GLFW_TRUE);
      if (key == GLFW_KEY_RIGHT && s.current + 1 < s.frame_numbers.size())
        actions.push_back(GoToFrame{s.frame_numbers[s.current + 1]});
      if (key == GLFW_KEY_LEFT && s.current > 0) actions.push_back(GoToFrame{s.frame_numbers[s.current - 1]});
      if (key == GLFW_KEY_S) actions.push_back(Screenshot{next_free_path("inspect.png")});
      if (key == GLFW_KEY_W && s.wedge_analysis) actions.push_back(ShowWedge{!s.show_wedge});
    }
    xw.keys.clear(), xw.key_mods.clear();
    ViewInput in;
    double mx = 0, my = 0;
    glfwGetCursorPos(xw.glfw, &mx, &my);
    in.mouse_x = float(mx), in.mouse_y = float(my);
    for (int b = 0; b < 3; ++b) in.mouse_down[b] = glfwGetMouseButton(xw.glfw, b) == GLFW_PRESS;
    in.wheel = xw.wheel, xw.wheel = 0;
    // a click on the bed probes the point under it
    if (xw.clicked_left && mx < view.panel_x0()) {
      const FrameLayout& L = view.frame_layout();
      if (mx >= L.bed_x0 && mx <= L.bed_x1 && my >= L.bed_y0 && my <= L.bed_y1)
        actions.push_back(Probe{{L.bed_origin_m.x() + (mx - L.bed_x0) / L.px_per_m,
                                 L.bed_origin_m.y() + (L.bed_y1 - my) / L.px_per_m}});
    }
    xw.clicked_left = false;
    xw.present(view.render(s, &in, &actions));
    for (const auto& a : actions) {
      try {
        print(std::get_if<Screenshot>(&a) ? screenshot(std::get<Screenshot>(a).path) : apply_action(s, a, &view));
      } catch (const std::exception& e) {
        err << "furrow inspect: " << e.what() << "\n";  // shown, and the window stays open
      }
    }
    if (!actions.empty()) {
      xw.present(view.render(s));
      xw.dirty = true;  // one more frame so the panel settles after the change
    }
  }
  return 0;
}

#else

bool inspector_window_available() { return false; }

int run_inspector_window(InspectorState&, InspectorView&, const WindowOptions&, std::ostream&, std::ostream&) {
  throw std::runtime_error("this furrow was built without GLFW/X11, so it has no window; use --headless --script FILE");
}

#endif

}  // namespace furrow::render
