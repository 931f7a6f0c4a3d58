#include "app/interactive/scene_view.hpp"

#include <imgui.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/Geometry>

#include "engine/bodies.hpp"
#include "engine/scene/scene_io.hpp"
#include "render/imgui_offscreen.hpp"

namespace furrow::render {

SceneLayout fit_scene(const Domain& d, int canvas_width, int canvas_height) {
  const double margin = 24;
  SceneLayout l;
  l.px_per_m = std::min((canvas_width - 2 * margin) / d.width_m, (canvas_height - 2 * margin) / d.height_m);
  l.origin_x_px = 0.5 * (canvas_width - d.width_m * l.px_per_m);
  l.origin_y_px = 0.5 * (canvas_height + d.height_m * l.px_per_m);
  return l;
}

namespace {
ImVec2 px(const SceneLayout& l, const Vec2& p_m) {
  const Eigen::Vector2d q = l.to_px(p_m);
  return ImVec2(float(q.x()), float(q.y()));
}

ImU32 wall_colour(Wall::Kind k) {
  switch (k) {
    case Wall::Kind::Slip: return IM_COL32(60, 110, 200, 255);
    case Wall::Kind::Friction: return IM_COL32(200, 120, 40, 255);
    case Wall::Kind::Sticky: return IM_COL32(180, 40, 40, 255);
    case Wall::Kind::Open: return IM_COL32(0, 0, 0, 0);
  }
  return IM_COL32(0, 0, 0, 255);
}

// Domain, grid, beds, walls and bodies on the background draw list (canvas pixels).
void draw_scene(ImDrawList* dl, const Scene& s, const std::vector<std::vector<std::vector<Vec2>>>& boundaries,
                const SceneLayout& l, float canvas_w, float canvas_h) {
  dl->AddRectFilled(ImVec2(0, 0), ImVec2(canvas_w, canvas_h), IM_COL32(40, 44, 52, 255));
  const Vec2 size(s.domain.width_m, s.domain.height_m);
  const ImVec2 lo = px(l, Vec2(0, size.y())), hi = px(l, Vec2(size.x(), 0));
  dl->AddRectFilled(lo, hi, IM_COL32(250, 250, 250, 255));
  // grid lines every cell, or every k cells when cells would be closer than 6 px
  const double dx = s.domain.dx_m;
  const int every = std::max(1, int(std::ceil(6.0 / (dx * l.px_per_m))));
  for (int i = 0; i * dx <= size.x() + 1e-12; i += every)
    dl->AddLine(px(l, Vec2(i * dx, 0)), px(l, Vec2(i * dx, size.y())), IM_COL32(215, 215, 215, 255));
  for (int j = 0; j * dx <= size.y() + 1e-12; j += every)
    dl->AddLine(px(l, Vec2(0, j * dx)), px(l, Vec2(size.x(), j * dx)), IM_COL32(215, 215, 215, 255));
  for (const Bed& b : s.beds)
    dl->AddRectFilled(px(l, Vec2(b.min_m.x(), b.max_m.y())), px(l, Vec2(b.max_m.x(), b.min_m.y())),
                      IM_COL32(kBedRgb[0], kBedRgb[1], kBedRgb[2], 255));
  const struct { const Wall* w; Vec2 a, b; } walls[] = {{&s.walls.left, {0, 0}, {0, size.y()}},
                                                       {&s.walls.right, {size.x(), 0}, size},
                                                       {&s.walls.bottom, {0, 0}, {size.x(), 0}},
                                                       {&s.walls.top, {0, size.y()}, size}};
  for (const auto& w : walls)
    if (w.w->kind != Wall::Kind::Open) dl->AddLine(px(l, w.a), px(l, w.b), wall_colour(w.w->kind), 4.0f);
  for (size_t k = 0; k < s.bodies.size(); ++k) {
    const Body& b = s.bodies[k];
    // at its start angle, turned about its origin as the solver turns it
    const Eigen::Rotation2Dd turn(b.start_angle_rad);
    auto screen = [&](const std::vector<Vec2>& loop) {
      std::vector<ImVec2> pts;
      for (const Vec2& q : loop) pts.push_back(px(l, turn * q + b.start_m));
      return pts;
    };
    // every part is convex (circle, box, convex polygon), so each part fills as one polygon; the
    // line is the body's boundary (a union's inner edges are not drawn)
    for (const auto& loop : shape_outline(b.shape)) {
      const auto pts = screen(loop);
      dl->AddConvexPolyFilled(pts.data(), int(pts.size()), IM_COL32(90, 96, 110, 255));
    }
    for (const auto& loop : boundaries[k]) {
      const auto pts = screen(loop);
      dl->AddPolyline(pts.data(), int(pts.size()), IM_COL32(20, 20, 20, 255), ImDrawFlags_Closed, 1.5f);
    }
    const ImVec2 c = px(l, b.start_m);
    dl->AddText(ImVec2(c.x + 4, c.y + 4), IM_COL32(200, 0, 0, 255), b.name.c_str());
  }
}

}  // namespace

SceneView::SceneView(int width, int height)
    : width_(width), height_(height), panel_w_(std::clamp(width * 2 / 5, 200, 520)) {
  if (width - panel_w_ < 64 || height < 64)
    throw std::invalid_argument("editor view " + std::to_string(width) + "x" + std::to_string(height) +
                                " is too small (at least " + std::to_string(panel_w_ + 64) + "x64)");
}

SceneView::~SceneView() = default;

std::optional<Eigen::Vector2d> SceneView::key_row_px(const std::string& key) const {
  const auto it = rows_.find(key);
  if (it == rows_.end()) return std::nullopt;
  return it->second;
}

bool SceneView::draw_panel(const ScenePanel& p, float x0, float width, float height, bool* preview) {
  bool committed = false;
  rows_.clear();
  ImGui::SetNextWindowPos(ImVec2(x0, 0));
  ImGui::SetNextWindowSize(ImVec2(width, height));
  ImGui::Begin("Scene", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  ImGui::TextUnformatted(p.title.c_str());
  const ImVec4 colour = p.valid ? ImVec4(0.4f, 0.9f, 0.4f, 1) : ImVec4(1.0f, 0.45f, 0.4f, 1);
  ImGui::PushStyleColor(ImGuiCol_Text, colour);
  ImGui::TextWrapped("%s", p.status.c_str());
  ImGui::PopStyleColor();
  for (const auto& n : p.notes) ImGui::TextWrapped("%s", n.c_str());
  if (p.preview_running) ImGui::BeginDisabled();
  if (ImGui::Button("Preview run")) *preview = true;
  if (p.preview_running) ImGui::EndDisabled();
  if (!p.preview_status.empty()) {
    ImGui::SameLine();
    ImGui::TextWrapped("%s", p.preview_status.c_str());
  }
  ImGui::Separator();
  if (ImGui::BeginTable("keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
    for (const auto& [k, v] : p.keys) {
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      const bool editing = k == editing_key_;
      // a click anywhere on the row opens its value for typing, starting from the current value
      if (ImGui::Selectable(k.c_str(), editing, ImGuiSelectableFlags_SpanAllColumns | ImGuiSelectableFlags_AllowItemOverlap) &&
          !editing) {
        editing_key_ = k, buffer_ = v, focus_pending_ = true;
      }
      const ImVec2 r0 = ImGui::GetItemRectMin(), r1 = ImGui::GetItemRectMax();
      if (ImGui::IsItemVisible()) rows_[k] = Eigen::Vector2d(0.5 * (r0.x + r1.x), 0.5 * (r0.y + r1.y));
      ImGui::TableSetColumnIndex(1);
      if (k != editing_key_) {
        ImGui::TextUnformatted(v.c_str());
        continue;
      }
      std::vector<char> buf(std::max<size_t>(1024, buffer_.size() + 256), '\0');
      std::copy(buffer_.begin(), buffer_.end(), buf.begin());
      if (focus_pending_) ImGui::SetKeyboardFocusHere(), focus_pending_ = false, focus_requested_ = true;
      ImGui::SetNextItemWidth(-FLT_MIN);
      if (ImGui::InputText("##value", buf.data(), buf.size(),
                           ImGuiInputTextFlags_EnterReturnsTrue | ImGuiInputTextFlags_AutoSelectAll)) {
        committed = true;
        focus_pending_ = true;  // a refused value stays open for correcting
      }
      buffer_ = buf.data();
      // what `set` would answer, as the user types
      if (p.typing_key == k) {
        const bool ok = p.typing_error.empty();
        ImGui::PushStyleColor(ImGuiCol_Text, ok ? ImVec4(0.4f, 0.9f, 0.4f, 1) : ImVec4(1.0f, 0.45f, 0.4f, 1));
        ImGui::TextWrapped("%s", ok ? "valid: Enter sets it, Escape cancels" : p.typing_error.c_str());
        ImGui::PopStyleColor();
      }
    }
    ImGui::EndTable();
  }
  ImGui::End();
  return committed;
}

namespace {
int imgui_key(ViewKey k) {
  switch (k) {
    case ViewKey::Enter: return ImGuiKey_Enter;
    case ViewKey::Escape: return ImGuiKey_Escape;
    case ViewKey::Backspace: return ImGuiKey_Backspace;
    case ViewKey::Delete: return ImGuiKey_Delete;
    case ViewKey::Left: return ImGuiKey_LeftArrow;
    case ViewKey::Right: return ImGuiKey_RightArrow;
    case ViewKey::Home: return ImGuiKey_Home;
    case ViewKey::End: return ImGuiKey_End;
    case ViewKey::Tab: return ImGuiKey_Tab;
  }
  return ImGuiKey_Tab;
}
}  // namespace

RgbImage SceneView::render(const Scene& scene, const ScenePanel& panel, const ViewInput* input, PanelChanges* edit,
                           const PreviewFrame* preview) {
  const bool first = !ui_;
  if (first) ui_ = std::make_unique<ImGuiOffscreen>(width_, height_);
  const SceneLayout l = layout(scene);
  // a union's boundary takes ~10 ms to trace: again only for a body whose shape changed
  const nlohmann::json bodies = scene_to_json(scene)["bodies"];
  boundary_shapes_.resize(scene.bodies.size()), boundaries_.resize(scene.bodies.size());
  for (size_t k = 0; k < scene.bodies.size(); ++k) {
    std::string shape = bodies[k]["shape"].dump();
    if (shape == boundary_shapes_[k]) continue;
    boundary_shapes_[k] = std::move(shape);
    boundaries_[k] = shape_boundary(scene.bodies[k].shape);
  }
  bool committed = false, preview_clicked = false;
  auto draw = [&] {
    draw_scene(ImGui::GetBackgroundDrawList(), scene, boundaries_, l, float(panel_x0()), float(height_));
    committed |= draw_panel(panel, float(panel_x0()), float(panel_w_), float(height_), &preview_clicked);
  };
  const float clear[3] = {0.16f, 0.17f, 0.2f};
  if (first) ui_->frame(draw, clear);  // the first frame lays the windows out
  // ImGui sees a press as a change between frames: presses go down in one frame and up in the next
  const bool press = input && (input->clicked_left || !input->keys.empty() || !input->chars.empty());
  auto set_input = [&](bool pressed) {
    ImGuiContext* previous = ImGui::GetCurrentContext();
    ImGui::SetCurrentContext(ui_->context());
    ImGuiIO& io = ImGui::GetIO();
    const bool over_panel = input->mouse_x >= panel_x0();
    io.MousePos = ImVec2(input->mouse_x, input->mouse_y);
    for (int b = 0; b < 3; ++b) io.MouseDown[b] = input->mouse_down[b] && over_panel;
    if (pressed && input->clicked_left && over_panel) io.MouseDown[0] = true;
    io.MouseWheel = pressed || !press ? input->wheel : 0.0f;
    io.KeyCtrl = pressed && input->ctrl;
    for (ViewKey k : input->keys) io.KeysDown[imgui_key(k)] = pressed;
    if (pressed)
      for (unsigned c : input->chars) io.AddInputCharacter(c);
    ImGui::SetCurrentContext(previous);
  };
  if (input && std::find(input->keys.begin(), input->keys.end(), ViewKey::Escape) != input->keys.end())
    editing_key_.clear();
  if (input) set_input(true);
  RgbImage img = ui_->frame(draw, clear);
  if (press) {
    set_input(false);
    img = ui_->frame(draw, clear);
  }
  // a text field asked for the keyboard takes it in the next frame, and a key typed in that
  // frame would be lost: draw the frames that settle it now
  for (int k = 0; k < 2 && (focus_pending_ || focus_requested_); ++k) {
    focus_requested_ = false;
    img = ui_->frame(draw, clear);
  }
  if (edit) {
    edit->key = editing_key_;
    edit->text = editing_key_.empty() ? "" : buffer_;
    edit->committed = committed && !editing_key_.empty();
    edit->preview = preview_clicked;
  }
  if (preview) {
    // the preview's field over the canvas; a new renderer when its field or range changed
    char key[160];
    std::snprintf(key, sizeof key, "%s %.9g %.9g %d", preview->field.c_str(), preview->range.lo, preview->range.hi,
                  int(preview->range.log));
    if (!field_ || field_key_ != key) {
      FrameStyle style;
      style.field = preview->field;
      style.range = preview->range;
      style.width = panel_x0() / 2 * 2, style.height = height_ / 2 * 2;
      field_ = std::make_unique<FrameRenderer>(style);
      field_key_ = key;
    }
    img.blit(field_->render(preview->frame), 0, 0);
  }
  return img;
}

}  // namespace furrow::render
