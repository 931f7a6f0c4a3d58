// One field of a FieldFrame drawn as an image: the field as a colour-mapped texture (cells without
// material in a neutral grey, so the free surface shows), a colorbar titled with label and unit
// from field_registry(), a time stamp, body outlines, and optionally a side panel plotting force
// against displacement up to the frame's time. Off-screen (OSMesa), no display needed.
#pragma once
#include <Eigen/Core>
#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/fields.hpp"
#include "render/image_io.hpp"

namespace furrow::render {

// Colour range of a field, fixed by the caller for a whole movie (never per frame).
struct FieldRange {
  double lo = 0.0, hi = 1.0;
  bool log = false;  // log10 mapping (strain rate); then 0 < lo < hi
};

// What can be drawn: every stored field of field_registry(), plus the velocity's components
// velocity_x and velocity_y (signed, read from the stored `velocity`).
const std::vector<FieldInfo>& display_fields();
const FieldInfo* find_display_field(const std::string& name);
std::string display_field_names();  // "velocity, velocity_x, ..." for messages

// The values drawn for `field` (a display field): the scalar as stored, |v| for velocity, or one
// component. Inactive cells are NaN. Throws std::invalid_argument for an unknown field and
// std::runtime_error if the frame does not hold it (naming the ones it has).
std::vector<float> field_values(const FieldFrame& frame, const std::string& field);

// Accumulates the range of a field over frames (active cells only).
class RangeAccumulator {
 public:
  explicit RangeAccumulator(const std::string& field);
  void add(const FieldFrame& frame);
  // Robust to a few extreme cells (a pressure spike under a plate's edge would otherwise turn the
  // whole bed into the bottom colour): in each frame take the 0.5th and 99.5th percentiles of the
  // cells with material; the range runs from the lowest to the highest of those over all frames.
  // Cells beyond it show in the end colours. Linear fields are widened if flat. Log fields
  // (field_registry().log_scale): hi from the positive values as above, lo = max(smallest positive
  // value, hi / 10^4), so static regions (rate 0) do not stretch the scale over empty decades.
  // Throws if no active value was seen.
  FieldRange range() const;
  // Plain min and max over the cells with material.
  FieldRange exact_range() const;
  static constexpr double kTailFraction = 0.005;

 private:
  std::string field_;
  bool log_ = false;
  double min_ = 0, max_ = 0, min_positive_ = 0;
  double robust_lo_ = 0, robust_hi_ = 0, robust_hi_positive_ = 0;
  bool any_ = false, any_positive_ = false;
};

// Colormap used when the caller names none: diverging (coolwarm) for a range spanning zero,
// magma for strain rate and plastic strain, viridis for the rest.
std::string default_colormap(const std::string& field, const FieldRange& range);

// Force against displacement of one body, sampled at times t_s (ascending).
struct ForceSeries {
  std::string label;  // body name
  bool faint = false;  // drawn light and thin behind the next series (its raw trace), no legend
  std::vector<double> t_s, x, y;  // x, y in the panel's display units
};

// One quantity of the bodies that turn or are free against time (x = t_s): torque, depth, ...
struct MotionRow {
  std::string key;      // "torque", "depth", "speed", "angle"
  std::string y_label;  // with its unit, e.g. "torque (N m/m)"
  bool movie = false;   // drawn as a row under the force chart; the rest only in the inspector
  std::vector<ForceSeries> series;  // labels are body names, as in the force chart
  // values that all stay within +-y_floor are drawn over +-y_floor: a symmetric body's torque of
  // round-off size (1e-8 N m/m) then reads as zero rather than as signal at full scale
  double y_floor = 0.0;
};

struct ForcePanel {
  std::string title = "Force on bodies";
  std::string x_label = "displacement (mm)";
  std::string y_label = "resisting force (N/m)";
  std::vector<ForceSeries> series;
  // Empty unless a body turns or is free (render/force_series.hpp); without a `movie` row the
  // panel is the force chart alone, as it was before these rows existed.
  std::vector<MotionRow> rows;
};

// The panel's axes, fixed over the whole series so the plot does not jump between frames. The
// force axis fits the trace, not a start-up impulse: a body started at full speed inside a bed
// pushes 6x its steady drag for a step (cylinder_drag: 114 against 19 N/m), which left the trace
// in the bottom sixth of the panel. When the largest (smallest) values stand more than half the
// trace's span beyond its 99.5th (0.5th) percentile, the axis stops a quarter span past that
// percentile and `clipped_hi` (`clipped_lo`) holds the value off the chart (NaN otherwise).
struct ForceAxes {
  double x_lo = 0, x_hi = 1, y_lo = 0, y_hi = 1;
  double clipped_hi = std::numeric_limits<double>::quiet_NaN(), clipped_lo = std::numeric_limits<double>::quiet_NaN();
};
ForceAxes force_panel_axes(const ForcePanel& panel);
ForceAxes force_axes(const ForceSeries* series, size_t count);  // the same over `count` series
// a motion row's axes over `count` of its series: force_axes, widened to the row's y_floor
ForceAxes motion_row_axes(const MotionRow& row, const ForceSeries* series, size_t count);
// The motion rows' keys in the order a panel lists them.
const std::vector<std::string>& motion_row_keys();
// `values` (a series' x or y) at time t_s, linear between the samples around it, the end values
// outside them; NaN for an empty series.
double value_at_time(const ForceSeries& s, const std::vector<double>& values, double t_s);

struct FrameStyle {
  int width = 1280, height = 720;  // even sizes for movies
  std::string field;               // registry name
  FieldRange range;
  std::string colormap;            // empty: default_colormap(field, range)
  bool show_colorbar = true;
  bool show_title = true;
  bool show_time = true;
  int time_decimals = 3;
  double font_scale = 0.0;  // text size relative to a 720-pixel-high image; 0: height / 720
  std::optional<ForcePanel> panel;  // side panel (right ~38% of the image)
  // Dimensionless display (furrow render --normalize): values drawn as value * value_scale under
  // the colorbar title value_title (e.g. "Vertical velocity / v"), time as time_s * time_scale
  // after time_label ("t v/L = 1.25"). Empty: the field's own label and unit, "t = ... s".
  // `range` is in the drawn (scaled) values.
  double value_scale = 1.0;
  std::string value_title;
  double time_scale = 1.0;
  std::string time_label;
  std::string title;  // replaces "<scene>: <field label>" (side-by-side runs carry their label)
  // Follow a body (--frame-of): each frame is centred on this body's position, so the body stays
  // still in the image and the bed moves past it; `zoom` multiplies the whole-bed scale.
  std::string follow_body;
  double zoom = 1.0;
  // Display only: blend values between cell centres inside the material at about the image's
  // resolution (render/smooth.hpp), the surface within half a cell of the cells with material.
  // false draws each cell as one flat colour (the resolution visible).
  bool smooth = true;
  std::array<float, 3> empty_rgb{0.82f, 0.82f, 0.82f};     // cells with no material
  std::array<float, 3> outline_rgb{0.0f, 0.9f, 1.0f};      // body outlines (cyan: in no colormap)
  std::array<float, 3> background_rgb{1.0f, 1.0f, 1.0f};
};

// Where things landed in the last image, in pixels with the top-left corner as origin.
struct FrameLayout {
  double bed_x0 = 0, bed_y0 = 0, bed_x1 = 0, bed_y1 = 0;  // the bed box (field texture) edges
  double px_per_m = 0;
  Eigen::Vector2d bed_origin_m{0, 0};                  // world point at (bed_x0, bed_y1)
  int colorbar_x0 = 0, colorbar_y0 = 0, colorbar_x1 = 0, colorbar_y1 = 0;  // title, bar and labels
  int colorbar_bar_y0 = 0, colorbar_bar_y1 = 0;                              // the coloured bar itself
  struct Tick {
    double x_px = 0;  // centre of the tick mark and its label
    double value = 0; // SI
    std::string label;
  };
  std::vector<Tick> colorbar_ticks;  // empty without a colorbar
  std::string colorbar_unit;         // unit the labels read in, e.g. "kPa"
  int time_x0 = 0, time_y0 = 0, time_x1 = 0, time_y1 = 0;  // box the time stamp is drawn in
  int panel_x0 = 0, panel_x1 = 0;                          // 0, 0 when there is no panel
  // The charts of the panel's movie rows under the force chart (x0, y0, x1, y1), top to bottom.
  std::vector<std::array<int, 4>> panel_rows;
  // Pixel (x right, y down) of a world point.
  Eigen::Vector2d to_pixel(const Eigen::Vector2d& p_m) const {
    return {bed_x0 + (p_m.x() - bed_origin_m.x()) * px_per_m, bed_y1 - (p_m.y() - bed_origin_m.y()) * px_per_m};
  }
};

// Marks drawn over the field in world coordinates (the inspector's wedge): line segments in one
// colour, and a text label centred on a point. Magenta, like no colormap and unlike the outlines.
struct FrameOverlay {
  std::vector<std::array<Eigen::Vector2d, 2>> segments_m;
  std::string label;                 // UTF-8; "" for none
  Eigen::Vector2d label_m{0, 0};     // the label's centre
  std::array<float, 3> rgb{1.0f, 0.0f, 1.0f};
};

// Keeps its VTK pipeline between frames, so a movie pays set-up once. Not thread-safe.
class FrameRenderer {
 public:
  // Throws std::invalid_argument for an unknown field (listing the valid ones), a bad size or
  // range, or an unknown colormap.
  explicit FrameRenderer(const FrameStyle& style);
  ~FrameRenderer();
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  RgbImage render(const FieldFrame& frame, const FrameOverlay* overlay = nullptr);
  const FrameLayout& layout() const { return layout_; }
  const FrameStyle& style() const { return style_; }

 private:
  struct Pipeline;
  FrameStyle style_;
  FrameLayout layout_;
  std::unique_ptr<Pipeline> p_;
};

// Colorbar title: "Pressure (Pa)", "Velocity magnitude (m/s)", "Packing fraction" (unit "-");
// with a display unit (the ticks' prefixed one): "Pressure (kPa)".
std::string colorbar_title(const std::string& field, bool log_scale);
std::string colorbar_title(const std::string& field, bool log_scale, const std::string& display_unit);

}  // namespace furrow::render
