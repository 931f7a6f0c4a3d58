// A GLFW window on an X11 display that shows off-screen images (the inspector's and the editor's):
// no GL context on the window, because Mesa's OSMesa library, linked first for VTK, owns
// the process's gl* symbols; pixels go through XPutImage. Include last: X11 defines None, Bool...
#pragma once
#if defined(FURROW_HAVE_GLFW) && defined(FURROW_HAVE_X11)
#include <string>
#include <vector>

#include "render/image_io.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>

namespace furrow::render {

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
  std::vector<int> key_mods;  // GLFW_MOD_* of each key in `keys`
  std::vector<unsigned> chars;  // text typed (Unicode code points)
  bool clicked_left = false;
  bool released_left = false;
  // where the cursor was at the last left press and release: a frame can see a press, the moves
  // and the release at once, and the cursor's position then is only the last of them
  double press_x = 0, press_y = 0, release_x = 0, release_y = 0;

  XWindow() = default;
  XWindow(const XWindow&) = delete;
  XWindow& operator=(const XWindow&) = delete;
  ~XWindow();
  void present(const RgbImage& img);
  // What the window shows, read back from the X server.
  RgbImage capture();
};

// Opens `xw` (width x height, not resizable) and waits until it is on screen. Throws naming the
// display when there is none or no window can be made.
void open_window(XWindow& xw, int width, int height, const std::string& title);

}  // namespace furrow::render
#endif
