// Several fields of one frame side by side (strain rate | pressure | packing fraction), or one
// field of several runs side by side (an under- and an over-compacted bed), as the paper's figures
// and movies show them: each panel a FrameRenderer with its own colour range, colormap, colorbar
// and unit; the force-vs-displacement plot, when given, as one more panel on the right.
#pragma once
#include <memory>
#include <optional>
#include <vector>

#include "render/frame_renderer.hpp"

namespace furrow::render {

struct PanelsStyle {
  int width = 1920, height = 480;  // the whole image
  // One per field, left to right; their width, height, panel and show_time are set here (the
  // time stamp only on the first panel).
  std::vector<FrameStyle> fields;
  std::optional<ForcePanel> forces;
};

class PanelsRenderer {
 public:
  // Throws std::invalid_argument when no field is given, the panels would be under 16 px wide, or
  // a FrameStyle is invalid (see FrameRenderer).
  explicit PanelsRenderer(const PanelsStyle& style);
  ~PanelsRenderer();
  PanelsRenderer(const PanelsRenderer&) = delete;
  PanelsRenderer& operator=(const PanelsRenderer&) = delete;

  RgbImage render(const FieldFrame& frame);
  // Side-by-side runs: panel k draws frames[k] (one per panel); the force plot follows frames[0]'s
  // time. Throws std::invalid_argument when the count differs from the panels'.
  RgbImage render(const std::vector<const FieldFrame*>& frames);
  size_t field_count() const { return fields_.size(); }
  // Left edge of field panel k in the image, and its layout (pixels within the panel).
  int panel_x0(size_t k) const { return int(k) * panel_w_; }
  int panel_width() const { return panel_w_; }
  const FrameLayout& layout(size_t k) const { return fields_[k]->layout(); }

 private:
  PanelsStyle style_;
  int panel_w_ = 0;
  std::vector<std::unique_ptr<FrameRenderer>> fields_;
  std::unique_ptr<FrameRenderer> forces_;  // drawn at its own width, only its plot is kept
};

}  // namespace furrow::render
