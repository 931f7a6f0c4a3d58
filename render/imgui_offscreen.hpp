// Dear ImGui drawn into an OSMesa buffer: the inspector's UI without a display (and what the
// smoke test checks). No platform backend: display size and frame time are set by hand.
#pragma once
#include <functional>
#include <memory>

#include "render/image_io.hpp"

struct ImGuiContext;

namespace furrow::render {

class GlContext;

class ImGuiOffscreen {
 public:
  ImGuiOffscreen(int width, int height);
  ~ImGuiOffscreen();
  ImGuiOffscreen(const ImGuiOffscreen&) = delete;
  ImGuiOffscreen& operator=(const ImGuiOffscreen&) = delete;

  // Runs one ImGui frame in which `draw` issues the ImGui calls, renders it over `clear_rgb`
  // (0..1) and returns the pixels (top row first).
  RgbImage frame(const std::function<void()>& draw, const float clear_rgb[3], float dt_s = 1.0f / 60.0f);

  ImGuiContext* context() { return ctx_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  std::unique_ptr<GlContext> gl_;
  ImGuiContext* ctx_ = nullptr;
  int width_ = 0, height_ = 0;
};

}  // namespace furrow::render
