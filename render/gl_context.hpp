// Off-screen OpenGL without a display: an OSMesa core-profile context on a buffer we own, and a
// VTK render window that draws into it. All the Debian-specific workarounds live in
// gl_context.cpp and nowhere else.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <vtkSmartPointer.h>

#include "render/image_io.hpp"

class vtkGenericOpenGLRenderWindow;

namespace furrow::render {

// An OSMesa OpenGL 3.2 core context with its own RGBA colour buffer. Not copyable; one per thread
// of drawing. Throws std::runtime_error if Mesa refuses the context.
class GlContext {
 public:
  GlContext(int width, int height);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  void make_current();
  // Reallocates the buffer and makes the context current on it.
  void resize(int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }
  // The default framebuffer: RGBA, bottom row first (GL order).
  const uint8_t* rgba() const { return buffer_.data(); }
  // The default framebuffer as RgbImage (flipped to top row first).
  RgbImage read_default_framebuffer() const;

 private:
  void* ctx_ = nullptr;  // OSMesaContext
  int width_ = 0, height_ = 0;
  std::vector<uint8_t> buffer_;
};

// A vtkGenericOpenGLRenderWindow bound to its own GlContext. Add renderers to window(), call
// capture() to render and read the pixels back.
class OffscreenWindow {
 public:
  OffscreenWindow(int width, int height);
  ~OffscreenWindow();
  OffscreenWindow(const OffscreenWindow&) = delete;
  OffscreenWindow& operator=(const OffscreenWindow&) = delete;

  vtkGenericOpenGLRenderWindow* window();
  int width() const { return gl_.width(); }
  int height() const { return gl_.height(); }
  // Renders the window and returns its pixels (RGB, top row first).
  RgbImage capture();

 private:
  GlContext gl_;
  vtkSmartPointer<vtkGenericOpenGLRenderWindow> window_;
};

}  // namespace furrow::render
