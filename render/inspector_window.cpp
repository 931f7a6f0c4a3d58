#include "render/inspector_window.hpp"

#include <cstdlib>
#include <stdexcept>

#include "render/image_io.hpp"

#if defined(FURROW_HAVE_GLFW) && defined(FURROW_HAVE_X11)
// X11 headers define None, Bool, Status...: included last, after everything else.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>
// From glfw3native.h, whose X11 part also pulls in Xrandr headers Debian ships in another package.
extern "C" Display* glfwGetX11Display(void);
extern "C" Window glfwGetX11Window(GLFWwindow* window);
#endif

namespace furrow::render {

#if defined(FURROW_HAVE_GLFW) && defined(FURROW_HAVE_X11)

bool inspector_window_available() { return true; }

namespace {
// Bit position of the lowest set bit of a visual's colour mask.
int shift_of(unsigned long mask) {
  int s = 0;
  while (mask && !(mask & 1)) mask >>= 1, ++s;
  return s;
}

struct XWindow {
  GLFWwindow* glfw = nullptr;
  Display* dpy = nullptr;
  Window win = 0;
  Visual* visual = nullptr;
  int depth = 0;
  int width = 0, height = 0;
  // what the callbacks saw since the last frame
  bool dirty = true;
  float wheel = 0;
  std::vector<int> keys;
  bool clicked_left = false;

  ~XWindow() {
    if (glfw) glfwDestroyWindow(glfw);
    glfwTerminate();
  }

  void present(const RgbImage& img) {
    const unsigned long rm = visual->red_mask, gm = visual->green_mask, bm = visual->blue_mask;
    const int rs = shift_of(rm), gs = shift_of(gm), bs = shift_of(bm);
    std::vector<uint32_t> px(size_t(img.width) * size_t(img.height));
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const uint8_t* p = img.at(x, y);
        px[size_t(y) * size_t(img.width) + size_t(x)] =
            uint32_t(((unsigned long)p[0] << rs) & rm) | uint32_t(((unsigned long)p[1] << gs) & gm) |
            uint32_t(((unsigned long)p[2] << bs) & bm);
      }
    XImage* xi = XCreateImage(dpy, visual, unsigned(depth), ZPixmap, 0, reinterpret_cast<char*>(px.data()),
                              unsigned(img.width), unsigned(img.height), 32, 0);
    if (!xi) throw std::runtime_error("XCreateImage failed");
    XPutImage(dpy, win, DefaultGC(dpy, DefaultScreen(dpy)), xi, 0, 0, 0, 0, unsigned(img.width), unsigned(img.height));
    xi->data = nullptr;  // ours, not Xlib's to free
    XDestroyImage(xi);
    XSync(dpy, False);
  }

  // What the window shows, read back from the X server.
  RgbImage capture() {
    XSync(dpy, False);
    // Xlib's default handler would exit the process on an error (e.g. a window not viewable)
    static int x_error = 0;
    x_error = 0;
    auto* previous = XSetErrorHandler([](Display*, XErrorEvent* e) { return x_error = e->error_code, 0; });
    XImage* xi = XGetImage(dpy, win, 0, 0, unsigned(width), unsigned(height), AllPlanes, ZPixmap);
    XSync(dpy, False);
    XSetErrorHandler(previous);
    if (!xi || x_error) {
      if (xi) XDestroyImage(xi);
      throw std::runtime_error("reading the window back (XGetImage) failed, X error " + std::to_string(x_error));
    }
    const unsigned long rm = visual->red_mask, gm = visual->green_mask, bm = visual->blue_mask;
    const int rs = shift_of(rm), gs = shift_of(gm), bs = shift_of(bm);
    RgbImage img(width, height);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const unsigned long v = XGetPixel(xi, x, y);
        uint8_t* p = img.at(x, y);
        p[0] = uint8_t((v & rm) >> rs), p[1] = uint8_t((v & gm) >> gs), p[2] = uint8_t((v & bm) >> bs);
      }
    XDestroyImage(xi);
    return img;
  }
};

XWindow* self(GLFWwindow* w) { return static_cast<XWindow*>(glfwGetWindowUserPointer(w)); }

void open_window(XWindow& xw, int width, int height, const std::string& title) {
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display) throw std::runtime_error("no display (DISPLAY is not set); use --headless --script FILE");
  if (!glfwInit()) throw std::runtime_error(std::string("cannot open a window on display '") + display + "'");
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);  // pixels go through XPutImage
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  xw.glfw = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!xw.glfw) throw std::runtime_error(std::string("cannot create a window on display '") + display + "'");
  xw.width = width, xw.height = height;
  xw.dpy = glfwGetX11Display();
  xw.win = glfwGetX11Window(xw.glfw);
  XWindowAttributes wa;
  XGetWindowAttributes(xw.dpy, xw.win, &wa);
  xw.visual = wa.visual, xw.depth = wa.depth;
  if (xw.depth < 24 || xw.visual->c_class != TrueColor)
    throw std::runtime_error("the display needs a 24-bit TrueColor visual, it has depth " + std::to_string(xw.depth));
  glfwSetWindowUserPointer(xw.glfw, &xw);
  glfwSetCursorPosCallback(xw.glfw, [](GLFWwindow* w, double, double) { self(w)->dirty = true; });
  glfwSetMouseButtonCallback(xw.glfw, [](GLFWwindow* w, int button, int action, int) {
    self(w)->dirty = true;
    if (button == GLFW_MOUSE_BUTTON_LEFT && action == GLFW_PRESS) self(w)->clicked_left = true;
  });
  glfwSetScrollCallback(xw.glfw, [](GLFWwindow* w, double, double dy) {
    self(w)->wheel += float(dy);
    self(w)->dirty = true;
  });
  glfwSetKeyCallback(xw.glfw, [](GLFWwindow* w, int key, int, int action, int) {
    if (action == GLFW_PRESS || action == GLFW_REPEAT) self(w)->keys.push_back(key), self(w)->dirty = true;
  });
  glfwSetWindowRefreshCallback(xw.glfw, [](GLFWwindow* w) { self(w)->dirty = true; });
  // pixels put before the window is on screen are lost: wait (up to 2 s) until it is viewable
  for (int k = 0; k < 200; ++k) {
    XGetWindowAttributes(xw.dpy, xw.win, &wa);
    if (wa.map_state == IsViewable) return;
    glfwWaitEventsTimeout(0.01);
  }
  throw std::runtime_error("the window did not appear on display '" + std::string(display) + "'");
}
}  // namespace

int run_inspector_window(InspectorState& s, InspectorView& view, const WindowOptions& options, std::ostream& out,
                         std::ostream& err) {
  XWindow xw;
  open_window(xw, view.width(), view.height(), "furrow inspect " + s.run_dir);
  auto print = [&](nlohmann::json r) { out << r.dump() << "\n" << std::flush; };
  // a screenshot in a window is what the display shows, read back
  auto screenshot = [&](const std::string& path) {
    xw.present(view.render(s));
    return write_screenshot(s, path, xw.capture(), view.panel_x0());
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
    }
    xw.keys.clear();
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
