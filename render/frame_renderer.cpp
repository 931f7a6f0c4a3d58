#include "render/frame_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <tuple>
#include <stdexcept>

#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkAxis.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkCoordinate.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkStringArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkImageActor.h>
#include <vtkImageData.h>
#include <vtkImageMapToColors.h>
#include <vtkImageMapper3D.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>

#include "render/colormap.hpp"
#include "render/gl_context.hpp"
#include "render/smooth.hpp"
#include "render/ticks.hpp"

namespace furrow::render {

// ---- field values and ranges --------------------------------------------------------------------
namespace {
const FieldInfo& require_field(const std::string& field) {
  const FieldInfo* info = find_display_field(field);
  if (!info) throw std::invalid_argument("unknown field '" + field + "' (valid fields: " + display_field_names() + ")");
  return *info;
}

// velocity_x -> 0, velocity_y -> 1, anything else -> -1
int velocity_component(const std::string& field) {
  return field == "velocity_x" ? 0 : field == "velocity_y" ? 1 : -1;
}

std::string frame_fields(const FieldFrame& f) {
  std::string s;
  for (const auto& [name, v] : f.scalars) s += (s.empty() ? "" : ", ") + name;
  if (!f.velocity_x.empty()) s += std::string(s.empty() ? "" : ", ") + "velocity";
  return s.empty() ? "none" : s;
}
}  // namespace

const std::vector<FieldInfo>& display_fields() {
  static const std::vector<FieldInfo> fields = [] {
    std::vector<FieldInfo> f = field_registry();
    f.push_back({"velocity_x", "m/s", "Horizontal velocity", false, false, false});
    f.push_back({"velocity_y", "m/s", "Vertical velocity", false, false, false});
    return f;
  }();
  return fields;
}

const FieldInfo* find_display_field(const std::string& name) {
  for (const auto& f : display_fields())
    if (f.name == name) return &f;
  return nullptr;
}

std::string display_field_names() {
  std::string s;
  for (const auto& f : display_fields()) s += (s.empty() ? "" : ", ") + f.name;
  return s;
}

std::vector<float> field_values(const FieldFrame& frame, const std::string& field) {
  const FieldInfo& info = require_field(field);
  const size_t n = size_t(frame.nx) * size_t(frame.ny);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> out(n, nan);
  const bool has_mask = frame.active.size() == n;
  const int component = velocity_component(field);
  if (info.vector || component >= 0) {
    if (frame.velocity_x.size() != n || frame.velocity_y.size() != n)
      throw std::runtime_error("frame at step " + std::to_string(frame.step) + " has no field 'velocity' (it has: " +
                               frame_fields(frame) + ")");
    for (size_t k = 0; k < n; ++k)
      if (!has_mask || frame.active[k])
        out[k] = component == 0 ? frame.velocity_x[k]
                 : component == 1 ? frame.velocity_y[k]
                                  : std::hypot(frame.velocity_x[k], frame.velocity_y[k]);
    return out;
  }
  auto it = frame.scalars.find(field);
  if (it == frame.scalars.end() || it->second.size() != n)
    throw std::runtime_error("frame at step " + std::to_string(frame.step) + " has no field '" + field +
                             "' (it has: " + frame_fields(frame) + ")");
  for (size_t k = 0; k < n; ++k)
    if (!has_mask || frame.active[k]) out[k] = it->second[k];
  return out;
}

RangeAccumulator::RangeAccumulator(const std::string& field) : field_(field), log_(require_field(field).log_scale) {}

void RangeAccumulator::add(const FieldFrame& frame) {
  std::vector<float> vals = field_values(frame, field_);
  // per-frame robust bounds: the 0.5th and 99.5th percentiles of the cells with material
  std::vector<float> finite, positive;
  finite.reserve(vals.size());
  for (float v : vals)
    if (std::isfinite(v)) {
      finite.push_back(v);
      if (v > 0) positive.push_back(v);
    }
  auto percentile = [](std::vector<float>& v, double q) {
    const size_t k = std::min(v.size() - 1, size_t(std::floor(q * double(v.size() - 1) + 0.5)));
    std::nth_element(v.begin(), v.begin() + long(k), v.end());
    return double(v[k]);
  };
  if (!finite.empty()) {
    const double lo = percentile(finite, kTailFraction), hi = percentile(finite, 1.0 - kTailFraction);
    robust_lo_ = any_ ? std::min(robust_lo_, lo) : lo;
    robust_hi_ = any_ ? std::max(robust_hi_, hi) : hi;
  }
  if (!positive.empty()) {
    const double hi = percentile(positive, 1.0 - kTailFraction);
    robust_hi_positive_ = any_positive_ ? std::max(robust_hi_positive_, hi) : hi;
  }
  for (float v : vals) {
    if (!std::isfinite(v)) continue;
    if (!any_) min_ = max_ = v, any_ = true;
    min_ = std::min(min_, double(v));
    max_ = std::max(max_, double(v));
    if (v > 0) {
      if (!any_positive_) min_positive_ = v, any_positive_ = true;
      min_positive_ = std::min(min_positive_, double(v));
    }
  }
}

FieldRange RangeAccumulator::exact_range() const {
  if (!any_) throw std::runtime_error("field '" + field_ + "' has no values in cells with material in the selected frames");
  return {min_, max_, log_};
}

FieldRange RangeAccumulator::range() const {
  if (!any_) throw std::runtime_error("field '" + field_ + "' has no values in cells with material in the selected frames");
  FieldRange r;
  r.log = log_;
  if (log_) {
    if (!any_positive_) {  // nothing flows anywhere: show one decade around 1e-3 of the unit
      r.lo = 1e-4, r.hi = 1e-3;
      return r;
    }
    r.hi = robust_hi_positive_;
    r.lo = std::max(min_positive_, r.hi * 1e-4);
    if (r.lo >= r.hi) r.lo = r.hi / 10.0;
    return r;
  }
  r.lo = robust_lo_, r.hi = robust_hi_;
  // a signed component on a diverging map: zero at the map's neutral centre
  if (velocity_component(field_) >= 0 && r.lo < 0 && r.hi > 0) r.hi = std::max(r.hi, -r.lo), r.lo = -r.hi;
  if (r.hi - r.lo <= 1e-12 * std::max(1.0, std::abs(r.hi))) {
    const double pad = std::abs(r.hi) > 0 ? 0.05 * std::abs(r.hi) : 1.0;
    r.lo -= pad, r.hi += pad;
  }
  return r;
}

std::string default_colormap(const std::string& field, const FieldRange& range) {
  if (!range.log && range.lo < 0 && range.hi > 0) return "coolwarm";
  if (field == "strain_rate" || field == "plastic_strain") return "magma";
  return "viridis";
}

std::string colorbar_title(const std::string& field, bool log_scale) {
  return colorbar_title(field, log_scale, require_field(field).unit);
}

std::string colorbar_title(const std::string& field, bool log_scale, const std::string& display_unit) {
  const FieldInfo& info = require_field(field);
  std::string t = info.label + (info.vector ? " magnitude" : "");
  std::string unit = display_unit == "-" ? "" : display_unit;
  if (log_scale) unit += std::string(unit.empty() ? "" : ", ") + "log scale";
  if (!unit.empty()) t += " (" + unit + ")";
  return t;
}

// ---- renderer -----------------------------------------------------------------------------------
struct FrameRenderer::Pipeline {
  OffscreenWindow window;
  vtkNew<vtkRenderer> field_ren;
  vtkNew<vtkImageData> image;
  vtkNew<vtkFloatArray> values;
  vtkNew<vtkLookupTable> lut;
  vtkNew<vtkImageMapToColors> to_colors;
  vtkNew<vtkImageActor> image_actor;
  vtkNew<vtkPolyData> outlines;
  vtkNew<vtkPolyDataMapper> outline_mapper;
  vtkNew<vtkActor> outline_actor;
  vtkNew<vtkPolyData> overlay;
  vtkNew<vtkPolyDataMapper> overlay_mapper;
  vtkNew<vtkActor> overlay_actor;
  vtkNew<vtkTextActor> overlay_label;
  // colorbar: one quad per colormap entry, tick marks, and a label under each tick
  vtkNew<vtkPolyData> bar, tick_marks;
  vtkNew<vtkPolyDataMapper2D> bar_mapper, tick_mapper;
  vtkNew<vtkActor2D> bar_actor, tick_actor;
  std::vector<vtkSmartPointer<vtkTextActor>> tick_labels;
  vtkNew<vtkTextActor> colorbar_title;
  vtkNew<vtkTextActor> title;
  vtkNew<vtkTextActor> time;
  // side panel
  vtkNew<vtkRenderer> panel_ren;
  vtkNew<vtkContextActor> chart_actor;
  vtkNew<vtkChartXY> chart;
  std::vector<vtkSmartPointer<vtkTable>> line_tables, marker_tables;
  // the movie rows under the force chart (torque, depth against time)
  struct RowPlot {
    size_t row = 0, series = 0;  // indices into ForcePanel::rows and its series
    vtkSmartPointer<vtkTable> line, marker;
  };
  std::vector<vtkSmartPointer<vtkChartXY>> row_charts;
  std::vector<RowPlot> row_plots;

  Pipeline(int w, int h) : window(w, h) {}
};

namespace {
constexpr double kPanelFraction = 0.38;  // of the width, when a force panel is shown

int even_floor(double v) { return int(std::floor(v / 2.0)) * 2; }

vtkSmartPointer<vtkTable> make_xy_table(const std::string& x_name, const std::string& y_name) {
  auto t = vtkSmartPointer<vtkTable>::New();
  vtkNew<vtkFloatArray> x, y;
  x->SetName(x_name.c_str());
  y->SetName(y_name.c_str());
  t->AddColumn(x);
  t->AddColumn(y);
  return t;
}

// The "now" dot on a chart's trace, in the trace's colour
void add_now_marker(vtkChartXY* chart, vtkTable* mark_t, const std::array<unsigned char, 3>& c, double font_scale) {
  vtkPlot* mark = chart->AddPlot(vtkChart::POINTS);
  mark->SetInputData(mark_t, 0, 1);
  mark->SetColor(c[0], c[1], c[2], 255);
  mark->SetLegendVisibility(false);
  if (auto* pts = vtkPlotPoints::SafeDownCast(mark)) {
    pts->SetMarkerStyle(vtkPlotPoints::CIRCLE);
    pts->SetMarkerSize(float(std::max(6.0, 12.0 * font_scale)));
  }
}

void set_xy_rows(vtkTable* t, const std::vector<double>& x, const std::vector<double>& y) {
  auto* cx = vtkFloatArray::SafeDownCast(t->GetColumn(0));
  auto* cy = vtkFloatArray::SafeDownCast(t->GetColumn(1));
  cx->SetNumberOfTuples(vtkIdType(x.size()));
  cy->SetNumberOfTuples(vtkIdType(y.size()));
  for (size_t k = 0; k < x.size(); ++k) {
    cx->SetValue(vtkIdType(k), float(x[k]));
    cy->SetValue(vtkIdType(k), float(y[k]));
  }
  t->Modified();
}

// Series samples with t <= time, ending with the point interpolated at `time`.
void series_until(const ForceSeries& s, double time, std::vector<double>& x, std::vector<double>& y) {
  x.clear(), y.clear();
  const size_t n = std::min({s.t_s.size(), s.x.size(), s.y.size()});
  if (n == 0) return;
  size_t k = 0;
  for (; k < n && s.t_s[k] <= time; ++k) x.push_back(s.x[k]), y.push_back(s.y[k]);
  if (k == 0) {
    x.push_back(s.x[0]), y.push_back(s.y[0]);
  }
  if (k <= 1 && n > 0) {
    x.push_back(x.back()), y.push_back(y.back());  // a line needs two points, even at the start
  } else if (k < n) {
    x.push_back(value_at_time(s, s.x, time));
    y.push_back(value_at_time(s, s.y, time));
  }
}

const std::array<unsigned char, 3> kSeriesColors[] = {{31, 92, 180}, {214, 88, 20}, {40, 150, 60}, {150, 50, 160}};
}  // namespace

FrameRenderer::FrameRenderer(const FrameStyle& style) : style_(style) {
  require_field(style.field);
  if (style.width < 16 || style.height < 16)
    throw std::invalid_argument("image size " + std::to_string(style.width) + "x" + std::to_string(style.height) +
                                " is too small (at least 16x16)");
  if (!(style.range.hi > style.range.lo) || !std::isfinite(style.range.lo) || !std::isfinite(style.range.hi))
    throw std::invalid_argument("colour range for '" + style.field + "' must have lo < hi, got [" +
                                std::to_string(style.range.lo) + ", " + std::to_string(style.range.hi) + "]");
  if (style.range.log && !(style.range.lo > 0))
    throw std::invalid_argument("log colour range for '" + style.field + "' needs lo > 0");
  if (style_.colormap.empty()) style_.colormap = default_colormap(style.field, style.range);
  const Colormap& cmap = load_colormap(style_.colormap);

  const int W = style.width, H = style.height;
  p_ = std::make_unique<Pipeline>(W, H);
  Pipeline& p = *p_;
  const double font_scale = style.font_scale > 0 ? style.font_scale : H / 720.0;
  const int fa_w = style.panel ? even_floor(W * (1.0 - kPanelFraction)) : W;

  // colour mapping: NaN marks cells without material
  fill_lookup_table(cmap, p.lut);
  p.lut->SetRange(style.range.lo, style.range.hi);
  if (style.range.log) p.lut->SetScaleToLog10();
  else p.lut->SetScaleToLinear();
  p.lut->SetNanColor(style.empty_rgb[0], style.empty_rgb[1], style.empty_rgb[2], 1.0);
  p.values->SetName(style.field.c_str());
  p.image->GetPointData()->SetScalars(p.values);
  p.to_colors->SetLookupTable(p.lut);
  p.to_colors->SetOutputFormatToRGB();
  p.to_colors->SetInputData(p.image);
  p.image_actor->GetMapper()->SetInputConnection(p.to_colors->GetOutputPort());
  p.image_actor->GetMapper()->BorderOn();  // cells are squares: draw the outer half cells too
  // flat cells show the resolution; smoothed, the texels blend into a continuous image
  if (style.smooth) p.image_actor->InterpolateOn();
  else p.image_actor->InterpolateOff();
  p.field_ren->AddActor(p.image_actor);

  p.outline_mapper->SetInputData(p.outlines);
  p.outline_actor->SetMapper(p.outline_mapper);
  p.outline_actor->GetProperty()->SetColor(style.outline_rgb[0], style.outline_rgb[1], style.outline_rgb[2]);
  p.outline_actor->GetProperty()->SetLineWidth(float(std::max(2.0, 3.0 * font_scale)));
  p.outline_actor->GetProperty()->LightingOff();
  p.field_ren->AddActor(p.outline_actor);

  p.overlay_mapper->SetInputData(p.overlay);
  p.overlay_actor->SetMapper(p.overlay_mapper);
  p.overlay_actor->GetProperty()->SetLineWidth(float(std::max(2.0, 3.0 * font_scale)));
  p.overlay_actor->GetProperty()->LightingOff();
  p.overlay_actor->VisibilityOff();
  p.field_ren->AddActor(p.overlay_actor);
  {
    // dark text on a light box: readable over any colormap, and not the overlay's line colour
    vtkTextProperty* tp = p.overlay_label->GetTextProperty();
    tp->SetFontSize(std::max(10, int(std::lround(18 * font_scale))));
    tp->SetColor(0.05, 0.05, 0.05);
    tp->SetBackgroundColor(1.0, 1.0, 1.0);
    tp->SetBackgroundOpacity(0.85);
    tp->SetFontFamilyToArial();
    tp->SetJustificationToCentered();
    tp->SetVerticalJustificationToCentered();
    p.overlay_label->GetPositionCoordinate()->SetCoordinateSystemToViewport();
    p.overlay_label->VisibilityOff();
    p.field_ren->AddActor2D(p.overlay_label);
  }

  const double text_rgb[3] = {0.05, 0.05, 0.05};
  const int title_px = std::max(10, int(std::lround(22 * font_scale)));
  const int label_px = std::max(8, int(std::lround(16 * font_scale)));

  // layout of the field area (left part): title band, bed, colorbar band
  const int top_band = int(std::lround(0.09 * H));
  const int bottom_band = style.show_colorbar ? int(std::lround(0.17 * H)) : int(std::lround(0.03 * H));
  const int side = int(std::lround(0.025 * W));
  layout_.panel_x0 = style.panel ? fa_w : 0;
  layout_.panel_x1 = style.panel ? W : 0;
  layout_.time_x0 = fa_w / 2, layout_.time_x1 = fa_w - side / 2;
  layout_.time_y0 = 0, layout_.time_y1 = top_band;
  // colorbar band: our own title line, then the bar with its labels below
  const int cb_x0 = int(std::lround(0.15 * fa_w)), cb_x1 = int(std::lround(0.85 * fa_w));
  const int cb_y0 = H - bottom_band + int(std::lround(0.06 * bottom_band));
  const int cb_title_y = H - bottom_band + int(std::lround(0.22 * bottom_band));  // centre line
  const int bar_y0 = H - bottom_band + int(std::lround(0.40 * bottom_band));
  const int cb_y1 = H - int(std::lround(0.04 * bottom_band));
  layout_.colorbar_x0 = cb_x0, layout_.colorbar_x1 = cb_x1;
  layout_.colorbar_y0 = cb_y0, layout_.colorbar_y1 = cb_y1;
  // the bed rectangle itself is fitted per frame (render()), inside this box
  layout_.bed_x0 = side, layout_.bed_x1 = fa_w - side;
  layout_.bed_y0 = top_band, layout_.bed_y1 = H - bottom_band;

  if (style.show_colorbar) {
    // the bar: one quad per colormap entry, so its colours are exactly the table's
    const int bar_y1 = bar_y0 + int(std::lround(0.35 * (cb_y1 - bar_y0)));
    const int tick_len = std::max(3, int(std::lround(6 * font_scale)));
    layout_.colorbar_bar_y0 = bar_y0, layout_.colorbar_bar_y1 = bar_y1;
    vtkNew<vtkPoints> bar_pts;
    vtkNew<vtkCellArray> quads;
    vtkNew<vtkUnsignedCharArray> rgb;
    rgb->SetNumberOfComponents(3);
    const size_t n = cmap.rgb.size();
    for (size_t k = 0; k <= n; ++k) {
      const double x = cb_x0 + (cb_x1 - cb_x0) * double(k) / double(n);
      bar_pts->InsertNextPoint(x, H - bar_y1, 0.0);
      bar_pts->InsertNextPoint(x, H - bar_y0, 0.0);
    }
    for (size_t k = 0; k < n; ++k) {
      const vtkIdType q[4] = {vtkIdType(2 * k), vtkIdType(2 * k + 2), vtkIdType(2 * k + 3), vtkIdType(2 * k + 1)};
      quads->InsertNextCell(4, q);
      const unsigned char c[3] = {(unsigned char)std::lround(255 * cmap.rgb[k][0]),
                                  (unsigned char)std::lround(255 * cmap.rgb[k][1]),
                                  (unsigned char)std::lround(255 * cmap.rgb[k][2])};
      rgb->InsertNextTypedTuple(c);
    }
    p.bar->SetPoints(bar_pts);
    p.bar->SetPolys(quads);
    p.bar->GetCellData()->SetScalars(rgb);
    // ticks at round values (render/ticks.hpp), labelled in a prefixed unit (kPa)
    const int max_ticks = std::clamp((cb_x1 - cb_x0) / (7 * label_px), 3, 6);
    const Ticks ticks = choose_ticks(style.range.lo, style.range.hi, max_ticks, style.range.log,
                                     style.value_title.empty() ? require_field(style.field).unit : "-");
    vtkNew<vtkPoints> tick_pts;
    vtkNew<vtkCellArray> tick_lines;
    for (size_t k = 0; k < ticks.values.size(); ++k) {
      const double x = cb_x0 + (cb_x1 - cb_x0) * range_fraction(ticks.values[k], style.range.lo, style.range.hi, style.range.log);
      const vtkIdType a = tick_pts->InsertNextPoint(x, H - bar_y1, 0.0);
      const vtkIdType b = tick_pts->InsertNextPoint(x, H - bar_y1 - tick_len, 0.0);
      const vtkIdType ab[2] = {a, b};
      tick_lines->InsertNextCell(2, ab);
      auto label = vtkSmartPointer<vtkTextActor>::New();
      label->SetInput(ticks.labels[k].c_str());
      vtkTextProperty* tp = label->GetTextProperty();
      tp->SetFontSize(label_px);
      tp->SetColor(text_rgb);
      tp->SetFontFamilyToArial();
      tp->SetJustificationToCentered();
      tp->SetVerticalJustificationToTop();
      label->GetPositionCoordinate()->SetCoordinateSystemToViewport();
      label->GetPositionCoordinate()->SetValue(x, H - bar_y1 - tick_len - 2);
      p.field_ren->AddActor2D(label);
      p.tick_labels.push_back(label);
      layout_.colorbar_ticks.push_back({x, ticks.values[k], ticks.labels[k]});
    }
    layout_.colorbar_unit = ticks.unit;
    p.tick_marks->SetPoints(tick_pts);
    p.tick_marks->SetLines(tick_lines);
    for (auto [mapper, data, actor] : {std::tuple{p.bar_mapper.Get(), p.bar.Get(), p.bar_actor.Get()},
                                       std::tuple{p.tick_mapper.Get(), p.tick_marks.Get(), p.tick_actor.Get()}}) {
      vtkNew<vtkCoordinate> viewport;
      viewport->SetCoordinateSystemToViewport();
      mapper->SetInputData(data);
      mapper->SetTransformCoordinate(viewport);
      mapper->SetScalarModeToUseCellData();
      mapper->SetColorModeToDirectScalars();
      actor->SetMapper(mapper);
      p.field_ren->AddActor2D(actor);
    }
    p.tick_actor->GetProperty()->SetColor(text_rgb);
    p.tick_actor->GetProperty()->SetLineWidth(float(std::max(1.0, 1.5 * font_scale)));
    const std::string cb_title = style.value_title.empty() ? colorbar_title(style.field, style.range.log, ticks.unit)
                                 : style.value_title + (style.range.log ? " (log scale)" : "");
    p.colorbar_title->SetInput(cb_title.c_str());
    vtkTextProperty* tp = p.colorbar_title->GetTextProperty();
    tp->SetFontSize(title_px - 2);
    tp->SetColor(text_rgb);
    tp->SetFontFamilyToArial();
    tp->SetJustificationToCentered();
    tp->SetVerticalJustificationToCentered();
    p.colorbar_title->GetPositionCoordinate()->SetCoordinateSystemToViewport();
    p.colorbar_title->GetPositionCoordinate()->SetValue(0.5 * (cb_x0 + cb_x1), H - cb_title_y);
    p.field_ren->AddActor2D(p.colorbar_title);
  }
  for (vtkTextActor* t : {p.title.Get(), p.time.Get()}) {
    vtkTextProperty* tp = t->GetTextProperty();
    tp->SetFontSize(title_px);
    tp->SetColor(text_rgb);
    tp->SetFontFamilyToArial();
    tp->SetVerticalJustificationToCentered();
    t->GetPositionCoordinate()->SetCoordinateSystemToViewport();
  }
  p.title->GetTextProperty()->SetJustificationToLeft();
  p.title->GetPositionCoordinate()->SetValue(side, H - top_band / 2);
  p.time->GetTextProperty()->SetJustificationToRight();
  p.time->GetPositionCoordinate()->SetValue(fa_w - side, H - top_band / 2);
  if (style.show_title) p.field_ren->AddActor2D(p.title);
  if (style.show_time) p.field_ren->AddActor2D(p.time);

  p.field_ren->SetBackground(style.background_rgb[0], style.background_rgb[1], style.background_rgb[2]);
  p.field_ren->SetViewport(0.0, 0.0, double(fa_w) / W, 1.0);
  p.field_ren->GetActiveCamera()->ParallelProjectionOn();
  p.window.window()->AddRenderer(p.field_ren);

  if (style.panel) {
    const ForcePanel& fp = *style.panel;
    p.panel_ren->SetViewport(double(fa_w) / W, 0.0, 1.0, 1.0);
    p.panel_ren->SetBackground(style.background_rgb[0], style.background_rgb[1], style.background_rgb[2]);
    p.chart_actor->GetScene()->AddItem(p.chart);
    p.panel_ren->AddActor(p.chart_actor);
    p.window.window()->AddRenderer(p.panel_ren);

    // fill the panel but leave a little air above the chart title
    p.chart->SetLayoutStrategy(vtkChart::FILL_RECT);
    std::vector<size_t> rows;  // the movie rows, each a small chart under the force chart
    for (size_t r = 0; r < fp.rows.size(); ++r)
      if (fp.rows[r].movie && !fp.rows[r].series.empty()) rows.push_back(r);
    const float chart_h = float(H - std::lround(0.03 * H));
    const float force_h = rows.empty() ? chart_h : std::round(0.5f * chart_h);
    const float row_h = rows.empty() ? 0.f : std::floor((chart_h - force_h) / float(rows.size()));
    p.chart->SetSize(vtkRectf(0.f, chart_h - force_h, float(W - fa_w), force_h));
    p.chart->GetTitleProperties()->SetFontSize(title_px - 2);
    p.chart->GetTitleProperties()->SetColor(text_rgb);
    const ForceAxes axes = force_panel_axes(fp);
    std::string title = fp.title;
    // the unit of the force axis, from its label's closing parentheses ("resisting force (N/m)")
    std::string unit;
    if (const size_t open = fp.y_label.rfind('('); open != std::string::npos && fp.y_label.back() == ')')
      unit = " " + fp.y_label.substr(open + 1, fp.y_label.size() - open - 2);
    for (const auto& [what, v] : {std::pair{"peak", axes.clipped_hi}, std::pair{"low", axes.clipped_lo}})
      if (std::isfinite(v)) {
        char note[96];
        std::snprintf(note, sizeof note, "\n(%s %.4g%s off the chart)", what, v, unit.c_str());
        title += note;
      }
    p.chart->SetTitle(title);
    size_t colour = 0;  // a faint raw trace takes the colour of the series drawn over it
    for (size_t s = 0; s < fp.series.size(); ++s) {
      const ForceSeries& ser = fp.series[s];
      std::array<unsigned char, 3> c = kSeriesColors[colour % 4];
      if (ser.faint)
        for (auto& ch : c) ch = (unsigned char)std::lround(0.35 * ch + 0.65 * 255);
      else
        ++colour;
      auto line_t = make_xy_table(fp.x_label, ser.label.empty() ? "body " + std::to_string(s) : ser.label);
      auto mark_t = make_xy_table(fp.x_label, "now");
      vtkPlot* line = p.chart->AddPlot(vtkChart::LINE);
      line->SetInputData(line_t, 0, 1);
      line->SetColor(c[0], c[1], c[2], 255);
      line->SetWidth(float(ser.faint ? std::max(1.0, 1.2 * font_scale) : std::max(1.5, 2.5 * font_scale)));
      line->SetLegendVisibility(!ser.faint);
      p.line_tables.push_back(line_t);
      p.marker_tables.push_back(mark_t);
      if (ser.faint) continue;  // the marker sits on the series drawn over it
      add_now_marker(p.chart, mark_t, c, font_scale);
    }
    vtkAxis* ax = p.chart->GetAxis(vtkAxis::BOTTOM);
    vtkAxis* ay = p.chart->GetAxis(vtkAxis::LEFT);
    ax->SetTitle(fp.x_label);
    ay->SetTitle(fp.y_label);
    ax->SetBehavior(vtkAxis::FIXED);
    ay->SetBehavior(vtkAxis::FIXED);
    ax->SetRange(axes.x_lo, axes.x_hi);
    ay->SetRange(axes.y_lo, axes.y_hi);
    for (vtkAxis* a : {ax, ay}) {
      a->GetTitleProperties()->SetFontSize(label_px);
      a->GetTitleProperties()->SetColor(text_rgb);
      a->GetLabelProperties()->SetFontSize(label_px - 2);
      a->GetLabelProperties()->SetColor(text_rgb);
    }
    p.chart->SetShowLegend(colour > 1);
    if (colour > 1) p.chart->GetLegend()->GetLabelProperties()->SetFontSize(label_px - 2);

    // rows: each body in the colour of its force trace, against time; the chart's own legend names them
    for (size_t k = 0; k < rows.size(); ++k) {
      const MotionRow& row = fp.rows[rows[k]];
      auto chart = vtkSmartPointer<vtkChartXY>::New();
      chart->SetLayoutStrategy(vtkChart::FILL_RECT);
      const float y0 = float(rows.size() - 1 - k) * row_h;
      chart->SetSize(vtkRectf(0.f, y0, float(W - fa_w), row_h));
      layout_.panel_rows.push_back({fa_w, H - int(std::lround(y0 + row_h)), W, H - int(std::lround(y0))});
      for (size_t s = 0; s < row.series.size(); ++s) {
        const ForceSeries& ser = row.series[s];
        size_t c_index = s, n = 0;
        for (const ForceSeries& f : fp.series) {
          if (f.faint) continue;
          if (f.label == ser.label) {
            c_index = n;
            break;
          }
          ++n;
        }
        const std::array<unsigned char, 3> c = kSeriesColors[c_index % 4];
        auto line_t = make_xy_table("time (s)", ser.label.empty() ? "body " + std::to_string(s) : ser.label);
        auto mark_t = make_xy_table("time (s)", "now");
        vtkPlot* line = chart->AddPlot(vtkChart::LINE);
        line->SetInputData(line_t, 0, 1);
        line->SetColor(c[0], c[1], c[2], 255);
        line->SetWidth(float(std::max(1.5, 2.5 * font_scale)));
        add_now_marker(chart, mark_t, c, font_scale);
        p.row_plots.push_back({rows[k], s, line_t, mark_t});
      }
      const ForceAxes a = motion_row_axes(row, row.series.data(), row.series.size());
      vtkAxis* bx = chart->GetAxis(vtkAxis::BOTTOM);
      vtkAxis* by = chart->GetAxis(vtkAxis::LEFT);
      bx->SetTitle("time (s)");
      by->SetTitle(row.y_label);
      bx->SetBehavior(vtkAxis::FIXED);
      by->SetBehavior(vtkAxis::FIXED);
      bx->SetRange(a.x_lo, a.x_hi);
      by->SetRange(a.y_lo, a.y_hi);
      // round ticks of our own: VTK's leave a torque of round-off size (a symmetric impactor:
      // 1e-8 N m/m) with the 0 tick alone
      {
        const Ticks t = choose_ticks(a.y_lo, a.y_hi, 4, false);
        vtkNew<vtkDoubleArray> at;
        vtkNew<vtkStringArray> text;
        for (size_t i = 0; i < t.values.size(); ++i) {
          char buf[32];
          std::snprintf(buf, sizeof buf, "%.3g", t.values[i]);
          at->InsertNextValue(t.values[i]);
          text->InsertNextValue(buf);
        }
        if (t.values.size() >= 2) by->SetCustomTickPositions(at, text);
      }
      for (vtkAxis* ax2 : {bx, by}) {
        ax2->GetTitleProperties()->SetFontSize(label_px);
        ax2->GetTitleProperties()->SetColor(text_rgb);
        ax2->GetLabelProperties()->SetFontSize(label_px - 2);
        ax2->GetLabelProperties()->SetColor(text_rgb);
      }
      chart->SetShowLegend(false);
      p.chart_actor->GetScene()->AddItem(chart);
      p.row_charts.push_back(chart);
    }
  }
}

ForceAxes force_panel_axes(const ForcePanel& fp) { return force_axes(fp.series.data(), fp.series.size()); }

ForceAxes force_axes(const ForceSeries* series, size_t count) {
  ForceAxes a;
  std::vector<double> ys;
  bool any = false;
  for (const ForceSeries* ser = series; ser != series + count; ++ser)
    for (size_t k = 0; k < std::min(ser->x.size(), ser->y.size()); ++k) {
      if (!std::isfinite(ser->x[k]) || !std::isfinite(ser->y[k])) continue;
      if (!any) a.x_lo = a.x_hi = ser->x[k], any = true;
      a.x_lo = std::min(a.x_lo, ser->x[k]), a.x_hi = std::max(a.x_hi, ser->x[k]);
      ys.push_back(ser->y[k]);
    }
  if (!any || a.x_hi <= a.x_lo) a.x_hi = a.x_lo + 1.0;
  if (ys.empty()) return a;
  std::sort(ys.begin(), ys.end());
  const double lo = std::min(ys.front(), 0.0), hi = ys.back();
  double top = hi, bottom = lo;
  // a percentile says something only with a few hundred samples; fewer are all drawn
  if (ys.size() >= 200) {
    const double q_lo = std::min(ys[size_t(0.005 * double(ys.size() - 1))], 0.0);
    const double q_hi = ys[size_t(0.995 * double(ys.size() - 1))];
    const double span = q_hi - q_lo;
    if (span > 0 && hi > q_hi + 0.5 * span) top = q_hi + 0.25 * span, a.clipped_hi = hi;
    if (span > 0 && lo < q_lo - 0.5 * span) bottom = q_lo - 0.25 * span, a.clipped_lo = lo;
  }
  if (top <= bottom) top = bottom + 1.0;
  const double pad = 0.05 * (top - bottom);
  a.y_lo = bottom < 0 ? bottom - pad : bottom;
  a.y_hi = top + pad;
  return a;
}

const std::vector<std::string>& motion_row_keys() {
  static const std::vector<std::string> keys = {"torque", "depth", "speed", "angle"};
  return keys;
}

double value_at_time(const ForceSeries& s, const std::vector<double>& values, double t_s) {
  const size_t n = std::min(s.t_s.size(), values.size());
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  size_t k = 0;
  while (k < n && s.t_s[k] <= t_s) ++k;
  if (k == 0) return values[0];
  if (k == n) return values[n - 1];
  const double w = (t_s - s.t_s[k - 1]) / (s.t_s[k] - s.t_s[k - 1]);  // t_s[k] > t_s >= t_s[k - 1]
  return values[k - 1] + w * (values[k] - values[k - 1]);
}

ForceAxes motion_row_axes(const MotionRow& row, const ForceSeries* series, size_t count) {
  ForceAxes a = force_axes(series, count);
  double largest = 0.0;
  for (const ForceSeries* ser = series; ser != series + count; ++ser)
    for (double y : ser->y)
      if (std::isfinite(y)) largest = std::max(largest, std::abs(y));
  if (row.y_floor > 0.0 && largest <= row.y_floor) a.y_lo = -row.y_floor, a.y_hi = row.y_floor;
  return a;
}

FrameRenderer::~FrameRenderer() = default;

RgbImage FrameRenderer::render(const FieldFrame& frame, const FrameOverlay* overlay) {
  Pipeline& p = *p_;
  const int W = style_.width, H = style_.height;
  if (frame.nx <= 0 || frame.ny <= 0 || !(frame.dx_m > 0))
    throw std::invalid_argument("frame at step " + std::to_string(frame.step) + " has an empty grid (nx " +
                                std::to_string(frame.nx) + ", ny " + std::to_string(frame.ny) + ", dx " +
                                std::to_string(frame.dx_m) + " m)");
  std::vector<float> v = field_values(frame, style_.field);
  if (style_.value_scale != 1.0)
    for (float& x : v) x = float(x * style_.value_scale);
  if (style_.range.log) {
    const float lo = float(style_.range.lo);
    for (float& x : v)
      if (!std::isnan(x) && !(x > lo)) x = lo;  // no flow (rate 0) shows as the bottom colour
  }

  // fit the bed box into the field area, aspect ratio preserved
  const int fa_w = style_.panel ? even_floor(W * (1.0 - kPanelFraction)) : W;
  const int top_band = int(std::lround(0.09 * H));
  const int bottom_band = style_.show_colorbar ? int(std::lround(0.17 * H)) : int(std::lround(0.03 * H));
  const int side = int(std::lround(0.025 * W));
  const double avail_w = fa_w - 2.0 * side, avail_h = double(H - top_band - bottom_band);
  const double bed_w = frame.nx * frame.dx_m, bed_h = frame.ny * frame.dx_m;
  const double ppm = std::min(avail_w / bed_w, avail_h / bed_h) * style_.zoom;
  layout_.px_per_m = ppm;
  layout_.bed_x0 = side + 0.5 * (avail_w - bed_w * ppm);
  layout_.bed_y0 = top_band + 0.5 * (avail_h - bed_h * ppm);
  if (!style_.follow_body.empty()) {
    // the body's position at the field area's centre: it stays put, the bed moves
    const BodyOutline* body = nullptr;
    std::string names;
    for (const auto& b : frame.bodies) {
      if (b.name == style_.follow_body) body = &b;
      names += (names.empty() ? "" : ", ") + b.name;
    }
    if (!body)
      throw std::runtime_error("frame at step " + std::to_string(frame.step) + " has no body '" + style_.follow_body +
                               "' to follow (bodies: " + (names.empty() ? "none" : names) + ")");
    layout_.bed_x0 = side + 0.5 * avail_w - (body->position_m.x() - frame.origin_m.x()) * ppm;
    layout_.bed_y0 = top_band + 0.5 * avail_h + (body->position_m.y() - frame.origin_m.y()) * ppm - bed_h * ppm;
  }
  layout_.bed_x1 = layout_.bed_x0 + bed_w * ppm;
  layout_.bed_y1 = layout_.bed_y0 + bed_h * ppm;
  layout_.bed_origin_m = frame.origin_m;
  // field texture: one image point per cell, or when smoothed per sub-cell of about one and a half
  // pixels (drawn interpolated, so about the image's resolution), at most ~4 M texels
  int sub = 1;
  if (style_.smooth) {
    const double cap = std::sqrt(4.0e6 / (double(frame.nx) * double(frame.ny)));
    sub = std::clamp(int(std::ceil(ppm * frame.dx_m / 1.5)), 2, std::max(2, std::min(16, int(cap))));
  }
  if (sub > 1) v = upsample_within_material(v, frame.nx, frame.ny, sub, style_.range.log);
  const double h = frame.dx_m / sub;
  p.image->SetDimensions(frame.nx * sub, frame.ny * sub, 1);
  p.image->SetSpacing(h, h, 1.0);
  p.image->SetOrigin(frame.origin_m.x() + 0.5 * h, frame.origin_m.y() + 0.5 * h, 0.0);
  p.values->SetNumberOfComponents(1);
  p.values->SetNumberOfTuples(vtkIdType(v.size()));
  std::copy(v.begin(), v.end(), p.values->GetPointer(0));
  p.values->Modified();
  p.image->Modified();
  {
    // only the texels inside the field area: a followed or zoomed bed must not run under the
    // title or the colorbar
    const double tp = h * ppm;  // pixels per texel
    const int mx = frame.nx * sub - 1, my = frame.ny * sub - 1;
    const int i0 = std::clamp(int(std::floor((side - layout_.bed_x0) / tp)), 0, mx);
    const int i1 = std::clamp(int(std::ceil((fa_w - side - layout_.bed_x0) / tp)) - 1, 0, mx);
    const int j0 = std::clamp(int(std::floor((layout_.bed_y1 - (H - bottom_band)) / tp)), 0, my);
    const int j1 = std::clamp(int(std::ceil((layout_.bed_y1 - top_band) / tp)) - 1, 0, my);
    p.image_actor->SetDisplayExtent(i0, i1, j0, j1, 0, 0);
  }

  // camera: world point under the centre of the field viewport; parallel scale = half its height
  const Eigen::Vector2d centre_m(frame.origin_m.x() + (0.5 * fa_w - layout_.bed_x0) / ppm,
                                 frame.origin_m.y() + (layout_.bed_y1 - 0.5 * H) / ppm);
  const double depth = 10.0 * std::max(bed_w, bed_h) + 1.0;
  vtkCamera* cam = p.field_ren->GetActiveCamera();
  cam->SetFocalPoint(centre_m.x(), centre_m.y(), 0.0);
  cam->SetPosition(centre_m.x(), centre_m.y(), depth);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(0.5 * H / ppm);
  cam->SetClippingRange(0.5 * depth, 1.5 * depth);

  // body outlines, just in front of the field
  vtkNew<vtkPoints> pts;
  vtkNew<vtkCellArray> lines;
  const double z = 0.01 * depth;
  for (const BodyOutline& b : frame.bodies) {
    if (b.outline_m.size() < 2) continue;
    std::vector<vtkIdType> ids;
    for (const auto& q : b.outline_m) ids.push_back(pts->InsertNextPoint(q.x(), q.y(), z));
    ids.push_back(ids.front());  // closed loop
    lines->InsertNextCell(vtkIdType(ids.size()), ids.data());
  }
  p.outlines->SetPoints(pts);
  p.outlines->SetLines(lines);
  p.outlines->Modified();

  // overlay: in front of the outlines
  vtkNew<vtkPoints> opts;
  vtkNew<vtkCellArray> olines;
  if (overlay)
    for (const auto& seg : overlay->segments_m) {
      const vtkIdType ab[2] = {opts->InsertNextPoint(seg[0].x(), seg[0].y(), 2 * z),
                               opts->InsertNextPoint(seg[1].x(), seg[1].y(), 2 * z)};
      olines->InsertNextCell(2, ab);
    }
  p.overlay->SetPoints(opts);
  p.overlay->SetLines(olines);
  p.overlay->Modified();
  p.overlay_actor->SetVisibility(overlay && !overlay->segments_m.empty());
  if (overlay) p.overlay_actor->GetProperty()->SetColor(overlay->rgb[0], overlay->rgb[1], overlay->rgb[2]);
  p.overlay_label->SetVisibility(overlay && !overlay->label.empty());
  if (overlay && !overlay->label.empty()) {
    const Eigen::Vector2d at = layout_.to_pixel(overlay->label_m);
    p.overlay_label->SetInput(overlay->label.c_str());
    p.overlay_label->GetPositionCoordinate()->SetValue(at.x(), H - at.y());
  }

  // text
  if (style_.show_title) {
    const std::string t = !style_.title.empty()       ? style_.title
                          : frame.scene_name.empty() ? colorbar_title(style_.field, false)
                                                     : frame.scene_name + ": " + require_field(style_.field).label;
    p.title->SetInput(t.c_str());
  }
  if (style_.show_time) {
    char buf[64];
    if (style_.time_label.empty())
      std::snprintf(buf, sizeof buf, "t = %.*f s", std::clamp(style_.time_decimals, 0, 9), frame.time_s);
    else
      std::snprintf(buf, sizeof buf, "%s = %.2f", style_.time_label.c_str(), frame.time_s * style_.time_scale);
    p.time->SetInput(buf);
  }

  // force panel up to this frame's time
  if (style_.panel) {
    std::vector<double> x, y;
    for (size_t s = 0; s < style_.panel->series.size(); ++s) {
      series_until(style_.panel->series[s], frame.time_s, x, y);
      set_xy_rows(p.line_tables[s], x, y);
      if (x.empty()) {
        set_xy_rows(p.marker_tables[s], {}, {});
      } else {
        set_xy_rows(p.marker_tables[s], {x.back()}, {y.back()});
      }
    }
    p.chart->RecalculateBounds();
    for (const Pipeline::RowPlot& rp : p.row_plots) {
      series_until(style_.panel->rows[rp.row].series[rp.series], frame.time_s, x, y);
      set_xy_rows(rp.line, x, y);
      if (x.empty()) set_xy_rows(rp.marker, {}, {});
      else set_xy_rows(rp.marker, {x.back()}, {y.back()});
    }
    for (auto& c : p.row_charts) c->RecalculateBounds();
  }
  return p.window.capture();
}

}  // namespace furrow::render
