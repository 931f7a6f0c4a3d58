#include "render/x_window.hpp"

#if defined(FURROW_HAVE_GLFW) && defined(FURROW_HAVE_X11)
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

// From glfw3native.h, whose X11 part also pulls in Xrandr headers Debian ships in another package.
extern "C" Display* glfwGetX11Display(void);
extern "C" Window glfwGetX11Window(GLFWwindow* window);

namespace furrow::render {

namespace {
// Bit position of the lowest set bit of a visual's colour mask.
int shift_of(unsigned long mask) {
  int s = 0;
  while (mask && !(mask & 1)) mask >>= 1, ++s;
  return s;
}

XWindow* self(GLFWwindow* w) { return static_cast<XWindow*>(glfwGetWindowUserPointer(w)); }

}  // namespace

XWindow::~XWindow() {
  if (glfw) glfwDestroyWindow(glfw);
  glfwTerminate();
}

void XWindow::present(const RgbImage& img) {
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

RgbImage XWindow::capture() {
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
    if (button != GLFW_MOUSE_BUTTON_LEFT) return;
    XWindow& xw = *self(w);
    if (action == GLFW_PRESS) xw.clicked_left = true, glfwGetCursorPos(w, &xw.press_x, &xw.press_y);
    if (action == GLFW_RELEASE) xw.released_left = true, glfwGetCursorPos(w, &xw.release_x, &xw.release_y);
  });
  glfwSetScrollCallback(xw.glfw, [](GLFWwindow* w, double, double dy) {
    self(w)->wheel += float(dy);
    self(w)->dirty = true;
  });
  glfwSetKeyCallback(xw.glfw, [](GLFWwindow* w, int key, int, int action, int mods) {
    if (action == GLFW_PRESS || action == GLFW_REPEAT)
      self(w)->keys.push_back(key), self(w)->key_mods.push_back(mods), self(w)->dirty = true;
  });
  glfwSetCharCallback(xw.glfw, [](GLFWwindow* w, unsigned c) {
    self(w)->chars.push_back(c);
    self(w)->dirty = true;
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

}  // namespace furrow::render
#endif
