#include "render/imgui_offscreen.hpp"

#include <GL/gl.h>

#include <stdexcept>

#include <imgui.h>
#include <imgui_impl_opengl3.h>

#include "render/gl_context.hpp"

namespace furrow::render {

ImGuiOffscreen::ImGuiOffscreen(int width, int height)
    : gl_(std::make_unique<GlContext>(width, height)), width_(width), height_(height) {
  ImGuiContext* previous = ImGui::GetCurrentContext();
  ctx_ = ImGui::CreateContext();
  ImGui::SetCurrentContext(ctx_);
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // never write imgui.ini into the user's directory
  io.LogFilename = nullptr;
  io.DisplaySize = ImVec2(float(width), float(height));
  // key indices are ImGui's own (a view feeds io.KeysDown by ImGuiKey_*: no window system here)
  for (int k = 0; k < ImGuiKey_COUNT; ++k) io.KeyMap[k] = k;
  ImGui::StyleColorsDark();
  gl_->make_current();
  // GLSL 1.50 is the version of an OpenGL 3.2 core context.
  if (!ImGui_ImplOpenGL3_Init("#version 150")) {
    ImGui::DestroyContext(ctx_);
    throw std::runtime_error("Dear ImGui OpenGL3 backend failed to initialise on OSMesa");
  }
  if (previous) ImGui::SetCurrentContext(previous);
}

ImGuiOffscreen::~ImGuiOffscreen() {
  ImGuiContext* previous = ImGui::GetCurrentContext();
  ImGui::SetCurrentContext(ctx_);
  gl_->make_current();
  ImGui_ImplOpenGL3_Shutdown();
  ImGui::DestroyContext(ctx_);
  if (previous && previous != ctx_) ImGui::SetCurrentContext(previous);
}

RgbImage ImGuiOffscreen::frame(const std::function<void()>& draw, const float clear_rgb[3], float dt_s) {
  ImGuiContext* previous = ImGui::GetCurrentContext();
  ImGui::SetCurrentContext(ctx_);
  gl_->make_current();
  ImGuiIO& io = ImGui::GetIO();
  io.DisplaySize = ImVec2(float(width_), float(height_));
  io.DeltaTime = dt_s > 0 ? dt_s : 1.0f / 60.0f;

  ImGui_ImplOpenGL3_NewFrame();
  ImGui::NewFrame();
  if (draw) draw();
  ImGui::Render();

  glViewport(0, 0, width_, height_);
  glClearColor(clear_rgb[0], clear_rgb[1], clear_rgb[2], 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  glFinish();  // the default framebuffer is our OSMesa buffer: done drawing means done writing

  if (previous && previous != ctx_) ImGui::SetCurrentContext(previous);
  return gl_->read_default_framebuffer();
}

}  // namespace furrow::render
