// A scene drawn to scale for `furrow edit`: the domain with its grid, the beds, the walls and the
// bodies at their start positions on the left, and a Dear ImGui panel on the right listing every
// scene key with its value and the validation status. Everything is one off-screen ImGui frame
// (OSMesa), so the headless editor and its tests need no display.
#pragma once
#include <Eigen/Core>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/scene/scene.hpp"
#include "render/frame_renderer.hpp"
#include "render/image_io.hpp"
#include "app/interactive/inspector.hpp"  // ViewInput

namespace furrow::render {

// What the panel shows besides the scene.
struct ScenePanel {
  std::string title;                                      // scene file or template
  std::vector<std::pair<std::string, std::string>> keys;  // "domain.dx_m", "0.01"
  std::string status;                                     // "valid" or the refused edit's message
  bool valid = true;
  std::vector<std::string> notes;                         // last results
  // the key being typed into (the view's editing_key()) and what `set` would answer to the
  // typed text: "" when it would be accepted
  std::string typing_key, typing_error;
  std::string preview_status;  // "" before any preview
  bool preview_running = false;
};

// What the user did in the panel: a key's value typed (click a key, type, Enter commits, Escape
// cancels) and the preview button.
struct PanelChanges {
  std::string key;         // the key being edited; "" when none
  std::string text;        // the text typed so far
  bool committed = false;  // Enter was pressed in this frame
  bool preview = false;    // "Preview run" was clicked
};

// A stored frame of the editor's preview run, drawn in place of the scene (as movies draw it).
struct PreviewFrame {
  FieldFrame frame;
  std::string field;
  FieldRange range;  // over the frames stored so far: it can only widen
};

// The bed fill colour (RGB), for the screenshot tests.
constexpr unsigned char kBedRgb[3] = {196, 164, 108};

// Where the domain sits in the view: pixel (x, y) of a point in metres (y up in the scene,
// down in the image).
struct SceneLayout {
  double origin_x_px = 0, origin_y_px = 0;  // pixel of the domain's (0, 0) corner (bottom-left)
  double px_per_m = 1;
  Eigen::Vector2d to_px(const Eigen::Vector2d& p_m) const {
    return {origin_x_px + p_m.x() * px_per_m, origin_y_px - p_m.y() * px_per_m};
  }
  Eigen::Vector2d to_m(const Eigen::Vector2d& px) const {
    return {(px.x() - origin_x_px) / px_per_m, (origin_y_px - px.y()) / px_per_m};
  }
};

// The domain fitted, with a margin, into a canvas of the given size.
SceneLayout fit_scene(const Domain& d, int canvas_width, int canvas_height);

class SceneView {
 public:
  SceneView(int width, int height);
  ~SceneView();
  SceneView(const SceneView&) = delete;
  SceneView& operator=(const SceneView&) = delete;

  // With `input` (a window's mouse and keys), the panel scrolls with the wheel and a click on a key
  // opens its value for typing; `edit` then receives the key, the text and whether Enter was
  // pressed. Keys and characters in `input` are pressed in one ImGui frame and released in the next.
  // With `preview`, its field is drawn in place of the scene.
  RgbImage render(const Scene& scene, const ScenePanel& panel, const ViewInput* input = nullptr,
                  PanelChanges* edit = nullptr, const PreviewFrame* preview = nullptr);
  // The key open for typing ("" for none), and closing it (after an accepted edit).
  const std::string& editing_key() const { return editing_key_; }
  void stop_editing() { editing_key_.clear(); }
  // Centre of the panel row of `key` in the last frame (view pixels), if it was drawn.
  std::optional<Eigen::Vector2d> key_row_px(const std::string& key) const;
  int width() const { return width_; }
  int height() const { return height_; }
  int panel_x0() const { return width_ - panel_w_; }
  SceneLayout layout(const Scene& scene) const { return fit_scene(scene.domain, panel_x0(), height_); }

 private:
  int width_, height_, panel_w_;
  // the panel's ImGui calls; true when Enter committed the typed value, *preview when the
  // preview button was clicked
  bool draw_panel(const ScenePanel& p, float x0, float width, float height, bool* preview);
  std::unique_ptr<class ImGuiOffscreen> ui_;
  std::unique_ptr<FrameRenderer> field_;  // the preview's, for its field and range
  std::string field_key_;
  std::string editing_key_;
  std::string buffer_;            // the typed text (ImGui edits a copy with room to grow)
  bool focus_pending_ = false;    // give the text field the keyboard in the next frame
  bool focus_requested_ = false;  // asked for in this frame: it takes it in the next
  std::map<std::string, Eigen::Vector2d> rows_;  // row centres of the last frame
  // per body: its shape (as JSON) and the boundary drawn for it, traced again only when it changes
  std::vector<std::string> boundary_shapes_;
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> boundaries_;
};

}  // namespace furrow::render
