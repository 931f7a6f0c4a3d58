#include "render/plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTable.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include "render/gl_context.hpp"

namespace furrow::render {

namespace {

// Colour-blind-safe palette (Okabe-Ito, without yellow/black).
constexpr std::array<std::array<unsigned char, 3>, 6> kPalette = {
    {{0, 114, 178}, {213, 94, 0}, {0, 158, 115}, {204, 121, 167}, {86, 180, 233}, {230, 159, 0}}};

bool usable(double x, bool log) { return std::isfinite(x) && (!log || x > 0.0); }

// Padded [lo, hi] of the usable values; log axes pad by a factor, linear by a fraction.
std::array<double, 2> axis_range(const std::vector<double>& v, bool log, bool from_zero) {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (double x : v) lo = std::min(lo, x), hi = std::max(hi, x);
  if (lo > hi) return log ? std::array<double, 2>{1.0, 10.0} : std::array<double, 2>{0.0, 1.0};
  if (log) {
    if (hi <= lo * 1.0001) lo /= 2.0, hi *= 2.0;
    const double f = std::pow(hi / lo, 0.06);
    return {lo / f, hi * f};
  }
  if (from_zero) lo = std::min(lo, 0.0), hi = std::max(hi, 0.0);
  if (hi - lo <= 1e-12 * std::max(1.0, std::abs(hi))) {
    const double d = std::max(std::abs(hi) * 0.1, 1e-9);
    lo -= d, hi += d;
  }
  const double pad = 0.06 * (hi - lo);
  return {(from_zero && lo >= 0.0) ? lo : lo - pad, (from_zero && hi <= 0.0) ? hi : hi + pad};
}

struct PanelPipeline {
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkContextActor> actor;
  vtkNew<vtkChartXY> chart;
  std::vector<vtkSmartPointer<vtkTable>> tables;
  vtkNew<vtkTextActor> notes;
  struct Label {
    double x, y;
    std::string text;
    int color;
  };
  std::vector<Label> labels;
  std::array<double, 2> xr{}, yr{};
  bool log_x = false, log_y = false;
  std::vector<vtkSmartPointer<vtkTextActor>> label_actors;
};

}  // namespace

RgbImage render_figure(const PlotFigure& fig) {
  if (fig.panels.empty()) throw std::invalid_argument("plot: a figure needs at least one panel");
  if (fig.width < 64 || fig.height < 64)
    throw std::invalid_argument("plot: figure size " + std::to_string(fig.width) + "x" + std::to_string(fig.height) +
                                " is below 64 px");
  const int W = fig.width, H = fig.height;
  const double scale = std::min(W / 1280.0, H / 720.0);  // fonts and lines follow the figure size
  const int title_px = std::max(10, int(std::lround(22 * scale)));
  const int label_px = std::max(9, int(std::lround(17 * scale)));
  const int tick_px = std::max(8, int(std::lround(15 * scale)));
  const double title_band = fig.title.empty() ? 0.0 : std::min(0.1, 2.2 * title_px / double(H));

  OffscreenWindow window(W, H);
  vtkNew<vtkRenderer> title_ren;
  vtkNew<vtkTextActor> title;
  if (!fig.title.empty()) {
    title_ren->SetViewport(0.0, 1.0 - title_band, 1.0, 1.0);
    title_ren->SetBackground(1, 1, 1);
    title->SetInput(fig.title.c_str());
    vtkTextProperty* tp = title->GetTextProperty();
    tp->SetFontSize(title_px);
    tp->SetColor(0.1, 0.1, 0.1);
    tp->SetBold(true);
    tp->SetJustificationToCentered();
    tp->SetVerticalJustificationToCentered();
    title->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    title->GetPositionCoordinate()->SetValue(0.5, 0.5);
    title_ren->AddActor2D(title);
    window.window()->AddRenderer(title_ren);
  }

  const size_t n = fig.panels.size();
  std::vector<std::unique_ptr<PanelPipeline>> pipes;
  for (size_t k = 0; k < n; ++k) {
    const PlotPanel& panel = fig.panels[k];
    auto pp = std::make_unique<PanelPipeline>();
    PanelPipeline& p = *pp;
    p.renderer->SetViewport(double(k) / n, 0.0, double(k + 1) / n, 1.0 - title_band);
    p.renderer->SetBackground(1, 1, 1);
    p.actor->GetScene()->AddItem(p.chart);
    p.renderer->AddActor(p.actor);
    window.window()->AddRenderer(p.renderer);

    vtkChartXY* chart = p.chart;
    chart->SetTitle(panel.title);
    chart->GetTitleProperties()->SetFontSize(label_px);
    chart->GetTitleProperties()->SetColor(0.1, 0.1, 0.1);
    chart->GetTitleProperties()->SetBold(true);

    std::vector<double> xs, ys;
    int legend_entries = 0;
    for (size_t s = 0; s < panel.series.size(); ++s) {
      const PlotSeries& ser = panel.series[s];
      auto t = vtkSmartPointer<vtkTable>::New();
      vtkNew<vtkDoubleArray> cx, cy;
      cx->SetName(panel.x_label.empty() ? "x" : panel.x_label.c_str());
      // vtkTable needs distinct column names; the legend shows the y column's name
      const std::string yname = ser.label.empty() ? " " + std::string(s + 1, ' ') : ser.label;
      cy->SetName(yname.c_str());
      for (size_t i = 0; i < std::min(ser.x.size(), ser.y.size()); ++i) {
        if (!usable(ser.x[i], panel.log_x) || !usable(ser.y[i], panel.log_y)) continue;
        cx->InsertNextValue(ser.x[i]);
        cy->InsertNextValue(ser.y[i]);
        xs.push_back(ser.x[i]);
        ys.push_back(ser.y[i]);
        if (i < ser.point_labels.size() && !ser.point_labels[i].empty())
          p.labels.push_back({ser.x[i], ser.y[i], ser.point_labels[i], ser.color >= 0 ? ser.color : int(s)});
      }
      t->AddColumn(cx);
      t->AddColumn(cy);
      p.tables.push_back(t);
      if (cx->GetNumberOfTuples() == 0) continue;
      const auto& c = kPalette[size_t(ser.color >= 0 ? ser.color : int(s)) % kPalette.size()];
      if (ser.line && cx->GetNumberOfTuples() >= 2) {  // VTK cannot draw a line through one point
        vtkPlot* line = chart->AddPlot(vtkChart::LINE);
        line->SetInputData(t, 0, 1);
        line->SetColor(c[0], c[1], c[2], 255);
        line->SetWidth(float(std::max(1.5, 2.5 * scale)));
        if (ser.dashed) line->GetPen()->SetLineType(vtkPen::DASH_LINE);
        if (auto* pts = vtkPlotPoints::SafeDownCast(line)) {
          pts->SetMarkerStyle(ser.markers ? vtkPlotPoints::CIRCLE : vtkPlotPoints::NONE);
          pts->SetMarkerSize(float(std::max(5.0, 9.0 * scale)));
        }
        line->SetLegendVisibility(!ser.label.empty());
      } else if (ser.markers || ser.line) {
        vtkPlot* pts = chart->AddPlot(vtkChart::POINTS);
        pts->SetInputData(t, 0, 1);
        pts->SetColor(c[0], c[1], c[2], 255);
        if (auto* pp2 = vtkPlotPoints::SafeDownCast(pts)) {
          pp2->SetMarkerStyle(vtkPlotPoints::CIRCLE);
          pp2->SetMarkerSize(float(std::max(6.0, 10.0 * scale)));
        }
        pts->SetLegendVisibility(!ser.label.empty());
      }
      legend_entries += ser.label.empty() ? 0 : 1;
    }

    vtkAxis* ax = chart->GetAxis(vtkAxis::BOTTOM);
    vtkAxis* ay = chart->GetAxis(vtkAxis::LEFT);
    const auto xr = axis_range(xs, panel.log_x, false);
    const auto yr = axis_range(ys, panel.log_y, panel.y_from_zero);
    p.xr = xr, p.yr = yr, p.log_x = panel.log_x, p.log_y = panel.log_y;
    ax->SetLogScale(panel.log_x);
    ay->SetLogScale(panel.log_y);
    ax->SetBehavior(vtkAxis::FIXED);
    ay->SetBehavior(vtkAxis::FIXED);
    ax->SetUnscaledRange(xr[0], xr[1]);
    ay->SetUnscaledRange(yr[0], yr[1]);
    ax->SetTitle(panel.x_label);
    ay->SetTitle(panel.y_label);
    for (vtkAxis* a : {ax, ay}) {
      a->GetTitleProperties()->SetFontSize(label_px);
      a->GetTitleProperties()->SetColor(0.1, 0.1, 0.1);
      a->GetLabelProperties()->SetFontSize(tick_px);
      a->GetLabelProperties()->SetColor(0.15, 0.15, 0.15);
      a->GetGridPen()->SetColor(225, 225, 225, 255);
    }
    chart->SetShowLegend(legend_entries > 0);
    if (legend_entries > 0) {
      chart->GetLegend()->GetLabelProperties()->SetFontSize(tick_px);
      chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
      chart->GetLegend()->SetVerticalAlignment(panel.legend_top ? vtkChartLegend::TOP : vtkChartLegend::BOTTOM);
    }

    if (!panel.notes.empty()) {
      std::string text;
      for (const auto& line : panel.notes) text += (text.empty() ? "" : "\n") + line;
      p.notes->SetInput(text.c_str());
      vtkTextProperty* tp = p.notes->GetTextProperty();
      tp->SetFontSize(tick_px);
      tp->SetColor(0.1, 0.1, 0.1);
      tp->SetFontFamilyToCourier();
      tp->SetJustificationToLeft();
      tp->SetVerticalJustificationToTop();
      tp->SetBackgroundColor(1, 1, 1);
      tp->SetBackgroundOpacity(0.85);
      p.notes->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
      // inside the plot area, in the corner (top left, top right, bottom left; the legend sits
      // bottom right) that the data crowd least
      auto frac = [](double v, const std::array<double, 2>& r, bool log) {
        return log ? std::log(v / r[0]) / std::log(r[1] / r[0]) : (v - r[0]) / (r[1] - r[0]);
      };
      int crowd[3] = {0, 0, 0};
      for (size_t i = 0; i < xs.size(); ++i) {
        const double fx = frac(xs[i], xr, panel.log_x), fy = frac(ys[i], yr, panel.log_y);
        crowd[0] += fx < 0.6 && fy > 0.6;
        crowd[1] += fx > 0.4 && fy > 0.6;
        crowd[2] += fx < 0.6 && fy < 0.4;
      }
      if (panel.legend_top && legend_entries > 0) crowd[1] += int(xs.size()) + 1;  // the legend is there
      const int best = int(std::min_element(crowd, crowd + 3) - crowd);
      if (best == 1) tp->SetJustificationToRight();
      if (best == 2) tp->SetVerticalJustificationToBottom();
      const double nx = best == 1 ? 0.96 : 0.14, ny = best == 2 ? 0.16 : 0.90;
      p.notes->GetPositionCoordinate()->SetValue(nx, ny);
      p.renderer->AddActor2D(p.notes);
    }
    pipes.push_back(std::move(pp));
  }

  // point labels go where the chart put its plot area, known only after a first render
  bool any_labels = false;
  for (const auto& p : pipes) any_labels = any_labels || !p->labels.empty();
  if (any_labels) {
    window.window()->Render();
    for (auto& p : pipes) {
      int lo[2], hi[2];
      p->chart->GetPoint1(lo);
      p->chart->GetPoint2(hi);
      auto frac = [](double v, const std::array<double, 2>& r, bool log) {
        return log ? std::log(v / r[0]) / std::log(r[1] / r[0]) : (v - r[0]) / (r[1] - r[0]);
      };
      for (const auto& l : p->labels) {
        auto a = vtkSmartPointer<vtkTextActor>::New();
        a->SetInput(l.text.c_str());
        vtkTextProperty* tp = a->GetTextProperty();
        tp->SetFontSize(tick_px);
        const auto& c = kPalette[size_t(l.color) % kPalette.size()];
        tp->SetColor(c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
        // near the right edge the text goes to the left of its point so it stays inside the plot
        const double fx = frac(l.x, p->xr, p->log_x);
        if (fx > 0.85) tp->SetJustificationToRight();
        else tp->SetJustificationToLeft();
        tp->SetVerticalJustificationToBottom();
        a->GetPositionCoordinate()->SetCoordinateSystemToViewport();
        const double px = lo[0] + fx * (hi[0] - lo[0]) + (fx > 0.85 ? -6.0 : 6.0) * scale;
        const double py = lo[1] + frac(l.y, p->yr, p->log_y) * (hi[1] - lo[1]) + 4.0 * scale;
        a->GetPositionCoordinate()->SetValue(px, py);
        p->renderer->AddActor2D(a);
        p->label_actors.push_back(a);
      }
    }
  }
  return window.capture();
}

void write_figure_png(const PlotFigure& figure, const std::string& path, bool overwrite) {
  write_png(render_figure(figure), path, overwrite);
}

}  // namespace furrow::render
