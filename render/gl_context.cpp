// Headless OpenGL for Debian's X-only VTK 9.1 (render/README.md): OSMesa core context + GLX stand-ins that
// GLEW binds to + a generic VTK render window on the current context.
#include "render/gl_context.hpp"

#include <GL/osmesa.h>
#include <dlfcn.h>

#include <cstring>
#include <stdexcept>

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>
// Including one header of each module that has factory overrides makes this translation unit carry
// VTK's autoinit registrations (CMake's vtk_module_autoinit defines the hooks for furrow_render
// sources). Every program that draws links this file, so test and app executables get them too;
// without them vtkRenderer::New() silently draws nothing.
#include <vtkRenderingContext2DModule.h>
#include <vtkRenderingCoreModule.h>
#include <vtkRenderingOpenGL2Module.h>

// ---- GLX stand-ins ------------------------------------------------------------------------------
// Debian's VTK GLEW is the GLX build: it fetches every GL entry point, even glGetString, through
// glXGetProcAddressARB and queries GLX versions on init. The executable exports these (ENABLE_EXPORTS)
// so they interpose on libGLX. While an OSMesa context is current they answer for Mesa; otherwise
// (a real GLFW window on a display) they forward to the real GLX so windowed use keeps working.
namespace {
using GlProc = void (*)();

void* next_symbol(const char* name) { return dlsym(RTLD_NEXT, name); }

bool osmesa_current() { return OSMesaGetCurrentContext() != nullptr; }

// GLEW only checks that a display exists; Mesa never dereferences it.
void* dummy_current_display() {
  static int dummy = 0;
  return &dummy;
}
}  // namespace

extern "C" {
__attribute__((visibility("default"))) GlProc glXGetProcAddressARB(const unsigned char* name) {
  if (!osmesa_current()) {
    using Fn = GlProc (*)(const unsigned char*);
    if (auto real = reinterpret_cast<Fn>(next_symbol("glXGetProcAddressARB"))) return real(name);
  }
  const char* n = reinterpret_cast<const char*>(name);
  if (std::strcmp(n, "glXGetCurrentDisplay") == 0) return reinterpret_cast<GlProc>(&dummy_current_display);
  return reinterpret_cast<GlProc>(OSMesaGetProcAddress(n));
}

__attribute__((visibility("default"))) int glXQueryVersion(void* display, int* major, int* minor) {
  if (!osmesa_current()) {
    using Fn = int (*)(void*, int*, int*);
    if (auto real = reinterpret_cast<Fn>(next_symbol("glXQueryVersion"))) return real(display, major, minor);
  }
  if (major) *major = 1;
  if (minor) *minor = 4;
  return 1;
}

__attribute__((visibility("default"))) const char* glXGetClientString(void* display, int name) {
  if (!osmesa_current()) {
    using Fn = const char* (*)(void*, int);
    if (auto real = reinterpret_cast<Fn>(next_symbol("glXGetClientString"))) return real(display, name);
  }
  return "";
}
}  // extern "C"

namespace furrow::render {

// ---- GlContext ----------------------------------------------------------------------------------
GlContext::GlContext(int width, int height) {
  if (width <= 0 || height <= 0)
    throw std::runtime_error("GL context size must be positive, got " + std::to_string(width) + "x" +
                             std::to_string(height));
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 8,
                         OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                         OSMESA_CONTEXT_MINOR_VERSION, 2, 0};
  ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!ctx_) throw std::runtime_error("OSMesa refused an OpenGL 3.2 core-profile context");
  resize(width, height);
}

GlContext::~GlContext() {
  if (ctx_) OSMesaDestroyContext(static_cast<OSMesaContext>(ctx_));
}

void GlContext::make_current() {
  if (!OSMesaMakeCurrent(static_cast<OSMesaContext>(ctx_), buffer_.data(), GL_UNSIGNED_BYTE, width_, height_))
    throw std::runtime_error("OSMesaMakeCurrent failed for a " + std::to_string(width_) + "x" +
                             std::to_string(height_) + " buffer");
}

void GlContext::resize(int width, int height) {
  width_ = width;
  height_ = height;
  buffer_.assign(size_t(width) * size_t(height) * 4, 0);
  make_current();
}

RgbImage GlContext::read_default_framebuffer() const {
  RgbImage img(width_, height_);
  for (int y = 0; y < height_; ++y) {
    const uint8_t* src = &buffer_[size_t(height_ - 1 - y) * size_t(width_) * 4];
    uint8_t* dst = img.at(0, y);
    for (int x = 0; x < width_; ++x) {
      dst[3 * x + 0] = src[4 * x + 0];
      dst[3 * x + 1] = src[4 * x + 1];
      dst[3 * x + 2] = src[4 * x + 2];
    }
  }
  return img;
}

// ---- OffscreenWindow ----------------------------------------------------------------------------
namespace {
// VTK asks the host to make its context current before drawing; with several windows alive the
// OSMesa current context must follow.
void on_make_current(vtkObject*, unsigned long, void* client, void*) {
  static_cast<GlContext*>(client)->make_current();
}
}  // namespace

OffscreenWindow::OffscreenWindow(int width, int height) : gl_(width, height) {
  window_ = vtkSmartPointer<vtkGenericOpenGLRenderWindow>::New();
  auto cb = vtkSmartPointer<vtkCallbackCommand>::New();
  cb->SetCallback(&on_make_current);
  cb->SetClientData(&gl_);
  window_->AddObserver(vtkCommand::WindowMakeCurrentEvent, cb);
  window_->SetSize(width, height);
  window_->SetMultiSamples(0);  // deterministic pixels; llvmpipe MSAA costs time
  window_->SetIsCurrent(true);
  window_->SetIsDirect(true);
  window_->SetSupportsOpenGL(true);
  window_->SetMapped(true);
  window_->InitializeFromCurrentContext();
}

OffscreenWindow::~OffscreenWindow() {
  gl_.make_current();
  window_->Finalize();
  window_ = nullptr;
}

vtkGenericOpenGLRenderWindow* OffscreenWindow::window() { return window_.Get(); }

RgbImage OffscreenWindow::capture() {
  gl_.make_current();
  auto grab = vtkSmartPointer<vtkWindowToImageFilter>::New();
  grab->SetInput(window_);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();  // renders, then reads the buffer just drawn
  grab->Update();
  vtkImageData* data = grab->GetOutput();
  int dims[3];
  data->GetDimensions(dims);
  auto* scalars = vtkUnsignedCharArray::SafeDownCast(data->GetPointData()->GetScalars());
  if (!scalars || scalars->GetNumberOfComponents() != 3 || dims[0] != width() || dims[1] != height())
    throw std::runtime_error("reading back the off-screen VTK window failed");
  RgbImage img(dims[0], dims[1]);
  const uint8_t* src = scalars->GetPointer(0);
  const size_t row = size_t(dims[0]) * 3;
  for (int y = 0; y < dims[1]; ++y)  // VTK images are bottom row first
    std::memcpy(img.at(0, y), src + size_t(dims[1] - 1 - y) * row, row);
  return img;
}

}  // namespace furrow::render
