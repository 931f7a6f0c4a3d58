#include "app/sweep_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>

namespace furrow::sweep {

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  LineFit f;
  double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  for (size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i], syy += y[i] * y[i];
    ++f.n;
  }
  if (f.n < 2) return f;
  const double n = double(f.n);
  const double vxx = sxx - sx * sx / n, vxy = sxy - sx * sy / n, vyy = syy - sy * sy / n;
  if (vxx <= 0.0) return f;
  f.slope = vxy / vxx;
  f.intercept = (sy - f.slope * sx) / n;
  f.r2 = vyy > 0.0 ? vxy * vxy / (vxx * vyy) : 1.0;
  return f;
}

LineFit fit_power_law(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<double> lx, ly;
  for (size_t i = 0; i < std::min(x.size(), y.size()); ++i)
    if (x[i] > 0.0 && y[i] > 0.0 && std::isfinite(x[i]) && std::isfinite(y[i]))
      lx.push_back(std::log(x[i])), ly.push_back(std::log(y[i]));
  return fit_line(lx, ly);
}

namespace {

std::string fmt(const char* f, double v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

const BodyMetrics* find_body(const RunMetrics& m, const std::string& name) {
  for (const auto& b : m.bodies)
    if (b.name == name) return &b;
  return nullptr;
}

using RowValue = std::function<double(const SweepRow&)>;

// Swept keys that change `value` while every other key is held: they drive the x axis and are not
// used to split rows into curves.
std::vector<bool> drivers(const std::vector<Vary>& varies, const std::vector<const SweepRow*>& rows,
                          const std::vector<RowValue>& values) {
  std::vector<bool> d(varies.size(), false);
  for (size_t k = 0; k < varies.size(); ++k)
    for (size_t a = 0; a < rows.size() && !d[k]; ++a)
      for (size_t b = a + 1; b < rows.size() && !d[k]; ++b) {
        bool others_equal = true;
        for (size_t j = 0; j < varies.size(); ++j)
          if (j != k && rows[a]->values[j] != rows[b]->values[j]) others_equal = false;
        if (!others_equal) continue;
        for (const auto& v : values) {
          const double va = v(*rows[a]), vb = v(*rows[b]);
          if (std::isfinite(va) && std::isfinite(vb) && std::abs(va - vb) > 1e-9 * std::max(std::abs(va), std::abs(vb)))
            d[k] = true;
        }
      }
  return d;
}

// Rows grouped into curves by the values of the non-driving keys (plus an optional extra label);
// each curve sorted by x.
struct Curve {
  std::string label;
  std::vector<const SweepRow*> rows;
};

std::vector<Curve> curves(const std::vector<Vary>& varies, const std::vector<const SweepRow*>& rows,
                          const std::vector<bool>& driving, const RowValue& x,
                          const std::function<std::string(const SweepRow&)>& extra = nullptr) {
  std::vector<Curve> out;
  std::map<std::string, size_t> index;
  for (const SweepRow* r : rows) {
    std::string label = extra ? extra(*r) : "";
    for (size_t k = 0; k < varies.size(); ++k)
      if (!driving[k]) label += (label.empty() ? "" : ", ") + varies[k].column + "=" + r->values[k];
    auto it = index.find(label);
    if (it == index.end()) it = index.emplace(label, out.size()).first, out.push_back({label, {}});
    out[it->second].rows.push_back(r);
  }
  for (auto& c : out)
    std::stable_sort(c.rows.begin(), c.rows.end(), [&](const SweepRow* a, const SweepRow* b) { return x(*a) < x(*b); });
  return out;
}

render::PlotSeries series(const std::string& label, const std::vector<const SweepRow*>& rows, const RowValue& x,
                          const RowValue& y, int color) {
  render::PlotSeries s;
  s.label = label;
  s.color = color;
  for (const SweepRow* r : rows) s.x.push_back(x(*r)), s.y.push_back(y(*r));
  return s;
}

bool all_numeric(const std::vector<std::string>& values, std::vector<double>& out) {
  out.clear();
  for (const auto& v : values) {
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(d)) return false;
    out.push_back(d);
  }
  return true;
}

}  // namespace

SweepFigure sweep_figure(const std::string& scene_name, const std::vector<Vary>& varies,
                         const std::vector<SweepRow>& all_rows) {
  SweepFigure out;
  render::PlotFigure& fig = out.figure;
  fig.width = 1400;
  fig.height = 720;
  std::vector<const SweepRow*> rows;
  for (const auto& r : all_rows)
    if (r.ok) rows.push_back(&r);

  // the first moving body, and the moving boxes, as the first good run has them
  std::string lead;
  size_t moving_boxes = 0;
  bool lead_circle = false;
  if (!rows.empty())
    for (const auto& b : rows[0]->metrics.bodies) {
      if (!b.moving) continue;
      if (lead.empty()) lead = b.name, lead_circle = b.kind == "circle";
      moving_boxes += b.kind == "box";
    }
  auto body_value = [&](double BodyMetrics::*field) -> RowValue {
    return [field, lead](const SweepRow& r) {
      const BodyMetrics* b = find_body(r.metrics, lead);
      return b ? b->*field : NAN;
    };
  };
  auto varies_over_rows = [&](const RowValue& v) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const SweepRow* r : rows)
      if (std::isfinite(v(*r))) lo = std::min(lo, v(*r)), hi = std::max(hi, v(*r));
    return hi > lo && hi - lo > 1e-9 * std::max(std::abs(lo), std::abs(hi));
  };

  const RowValue depth = body_value(&BodyMetrics::depth_m), size = body_value(&BodyMetrics::size_m);
  const RowValue gap = [](const SweepRow& r) { return r.metrics.gap_m; };
  const RowValue L_avg = [](const SweepRow& r) { return r.metrics.L_avg_m; };

  const RowValue aspect = [](const SweepRow& r) { return r.metrics.aspect_ratio; };
  bool all_collapse = !rows.empty();
  for (const SweepRow* r : rows) all_collapse = all_collapse && r->metrics.collapse;

  if (all_collapse && varies_over_rows(aspect)) {
    // ---- released columns: runout vs aspect ratio against the experiments' laws ----
    out.kind = "collapse_runout";
    fig.title = scene_name + ": column collapse, runout vs aspect ratio";
    const RowValue runout = [](const SweepRow& r) { return r.metrics.runout_relative; };
    const auto cs = curves(varies, rows, drivers(varies, rows, {aspect}), aspect);
    render::PlotPanel a, b;
    a.title = "runout";
    a.x_label = "a = H0 / L0";
    a.y_label = "(Lf - L0) / L0";
    a.log_x = a.log_y = true;
    a.legend_top = false;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const SweepRow* r : rows) lo = std::min(lo, aspect(*r)), hi = std::max(hi, aspect(*r));
    // quasi-2D channel experiments in their linear regime (a up to about 2-3)
    for (auto [label, k] : {std::pair{"1.2 a (Lube et al. 2005)", 1.2}, std::pair{"1.8 a (Lajeunesse et al. 2005)", 1.8}}) {
      render::PlotSeries law;
      law.label = label;
      law.dashed = true;
      law.markers = false;
      law.color = 4 + int(k > 1.5);  // the simulation curves take 0..3
      for (double x : {lo, hi}) law.x.push_back(x), law.y.push_back(k * x);
      a.series.push_back(law);
    }
    for (size_t c = 0; c < cs.size(); ++c) {
      a.series.push_back(series(cs[c].label.empty() ? "simulation" : cs[c].label, cs[c].rows, aspect, runout, int(c)));
      const LineFit f = fit_power_law(a.series.back().x, a.series.back().y);
      if (f.n >= 2 && c < 4)
        a.notes.push_back((cs.size() > 1 ? "[" + std::to_string(c + 1) + "] " : std::string()) + "runout = " +
                          fmt("%.3g", std::exp(f.intercept)) + " a^" + fmt("%.2f", f.slope));
    }
    for (const SweepRow* r : rows)
      if (!r->metrics.settled) {
        a.notes.push_back("not settled at the end: " + r->dir);
        break;
      }
    // the final surfaces of the first curve, one per a
    b.title = "final deposit" + (cs.empty() || cs[0].label.empty() ? std::string() : " (" + cs[0].label + ")");
    b.x_label = "x / L0 (from the back wall)";
    b.y_label = "h / L0";
    b.y_from_zero = true;
    b.legend_top = true;
    if (!cs.empty())
      for (size_t i = 0; i < cs[0].rows.size(); ++i) {
        const RunMetrics& m = cs[0].rows[i]->metrics;
        render::PlotSeries p;
        p.label = "a = " + fmt("%.3g", m.aspect_ratio);
        p.markers = false;
        p.color = int(i);
        p.x = m.surface_x_over_L0;
        p.y = m.surface_height_over_L0;
        b.series.push_back(p);
      }
    fig.panels = {a, b};
  } else if (!lead.empty() && lead_circle && varies_over_rows(depth)) {
    // ---- paper case 1: drag and lift vs |z|/D ----
    out.kind = "drag_lift_vs_depth";
    fig.title = scene_name + ": drag and lift on " + lead + " vs depth";
    const RowValue x = [&](const SweepRow& r) { return depth(r) / size(r); };
    const RowValue drag = body_value(&BodyMetrics::mean_drag_N_per_m), lift = body_value(&BodyMetrics::mean_lift_N_per_m);
    const RowValue F0 = body_value(&BodyMetrics::F0_N_per_m);
    const auto cs = curves(varies, rows, drivers(varies, rows, {x}), x);
    render::PlotPanel a, b;
    a.title = "drag (against the motion)";
    b.title = "lift (motion direction turned +90 deg)";
    a.x_label = b.x_label = "|z| / D (centre depth over diameter)";
    a.y_label = "F_drag / (pi (D/2)^2 rho_d g w)";
    b.y_label = "F_lift / (pi (D/2)^2 rho_d g w)";
    a.y_from_zero = b.y_from_zero = true;
    for (size_t c = 0; c < cs.size(); ++c) {
      const std::string label = cs[c].label.empty() ? lead : cs[c].label;
      a.series.push_back(series(label, cs[c].rows, x, [&](const SweepRow& r) { return drag(r) / F0(r); }, int(c)));
      b.series.push_back(series(label, cs[c].rows, x, [&](const SweepRow& r) { return lift(r) / F0(r); }, int(c)));
      const LineFit f = fit_line(a.series.back().x, a.series.back().y);
      if (f.n >= 2 && c < 4)
        a.notes.push_back((cs.size() > 1 ? "[" + std::to_string(c + 1) + "] " : std::string()) + "drag = " +
                          fmt("%.3g", f.intercept) + " + " + fmt("%.3g", f.slope) + " |z|/D, R^2 = " + fmt("%.4f", f.r2));
    }
    if (!rows.empty()) {
      const SweepRow& r = *rows[0];
      b.notes.push_back("rho_d = " + fmt("%.4g", r.metrics.rho_d_kg_m3) + " kg/m^3, g = " + fmt("%.3g", r.metrics.g_m_s2) +
                        " m/s^2, w = 1 m");
      b.notes.push_back("D = " + fmt("%.4g", size(r) * 1e3) + " mm; window mean, t = " + fmt("%.3g", r.metrics.window_from_s) +
                        ".." + fmt("%.3g", r.metrics.window_to_s) + " s");
    }
    fig.panels = {a, b};
  } else if (!lead.empty() && moving_boxes == 1 && varies_over_rows(size)) {
    // ---- paper case 2, single plates: peak and mean drag vs L ----
    out.kind = "plate_width_scaling";
    fig.title = scene_name + ": drag on " + lead + " vs plate width";
    // the initial peak where every run has one; else the drag at the start of penetration, which is
    // what the peak measures (the force that starts the flow) when the drag never gives afterwards
    bool all_peaks = true;
    for (const SweepRow* r : rows) all_peaks = all_peaks && std::isfinite(body_value(&BodyMetrics::peak_drag_N_per_m)(*r));
    const RowValue peak = body_value(all_peaks ? &BodyMetrics::peak_drag_N_per_m : &BodyMetrics::onset_drag_N_per_m);
    const RowValue mean = body_value(&BodyMetrics::mean_drag_N_per_m);
    const auto cs = curves(varies, rows, drivers(varies, rows, {size}), size);
    render::PlotPanel a, b;
    a.title = all_peaks ? "initial peak drag" : "drag at the start of penetration (no peak: z -> 0 of F(z))";
    b.title = "mean drag over the averaging window";
    a.x_label = b.x_label = "plate width L (m)";
    a.y_label = all_peaks ? "F_peak (N/m)" : "F(z -> 0) (N/m)";
    b.y_label = "F_avg (N/m)";
    a.log_x = a.log_y = b.log_x = b.log_y = true;
    for (size_t c = 0; c < cs.size(); ++c) {
      const std::string label = cs[c].label.empty() ? "simulation" : cs[c].label;
      for (auto [panel, value, expect] : {std::tuple{&a, peak, 2.0}, std::tuple{&b, mean, 1.0}}) {
        auto s = series(label, cs[c].rows, size, value, int(c));
        s.line = false;
        const LineFit f = fit_power_law(s.x, s.y);
        panel->series.push_back(s);
        if (f.n >= 2) {
          render::PlotSeries fit;
          fit.label = cs.size() == 1 ? "fit F = c L^n" : "";
          fit.color = int(c);
          fit.dashed = true;
          fit.markers = false;
          const double lo = *std::min_element(s.x.begin(), s.x.end()), hi = *std::max_element(s.x.begin(), s.x.end());
          for (int i = 0; i <= 20; ++i) {
            const double L = lo * std::pow(hi / lo, i / 20.0);
            fit.x.push_back(L);
            fit.y.push_back(std::exp(f.intercept) * std::pow(L, f.slope));
          }
          panel->series.push_back(fit);
          if (c < 4)
            panel->notes.push_back((cs.size() > 1 ? "[" + std::to_string(c + 1) + "] " : std::string()) + "n = " +
                                   fmt("%.3f", f.slope) + " (paper: " + fmt("%.0f", expect) + "), R^2 = " + fmt("%.4f", f.r2));
        }
      }
    }
    if (!rows.empty())
      b.notes.push_back("window: plate bottom " + fmt("%.3g", rows[0]->metrics.z_m * 1e3) + " mm deep at its middle");
    fig.panels = {a, b};
  } else if (moving_boxes >= 2 && varies_over_rows(gap)) {
    // ---- paper case 2, pairs: per-plate drag / (rho_d g z L_avg w) vs s / L_avg ----
    out.kind = "pair_separation";
    fig.title = scene_name + ": plate pairs, drag vs separation";
    const RowValue x = [&](const SweepRow& r) { return gap(r) / L_avg(r); };
    const RowValue y = [&](const SweepRow& r) {
      size_t n = 0;
      for (const auto& b : r.metrics.bodies) n += b.moving && b.kind == "box";
      return r.metrics.total_mean_drag_N_per_m / double(std::max<size_t>(n, 1)) / r.metrics.total_F0_N_per_m;
    };
    auto d = drivers(varies, rows, {x});
    const auto dL = drivers(varies, rows, {L_avg});
    for (size_t k = 0; k < d.size(); ++k) d[k] = d[k] || dL[k];
    const auto cs = curves(varies, rows, d, x, [&](const SweepRow& r) { return "L_avg = " + fmt("%.4g", L_avg(r)) + " m"; });
    render::PlotPanel a;
    a.title = "mean drag per plate over the averaging window";
    a.x_label = "s / L_avg (inner-edge gap over mean plate width)";
    a.y_label = "F / (rho_d g z L_avg w)";
    a.y_from_zero = true;
    for (size_t c = 0; c < cs.size(); ++c) {
      a.series.push_back(series(cs[c].label, cs[c].rows, x, y, int(c)));
      const auto& s = a.series.back();
      size_t best = 0;
      for (size_t i = 1; i < s.y.size(); ++i)
        if (s.y[i] > s.y[best]) best = i;
      if (!s.y.empty() && c < 6)
        a.notes.push_back(cs[c].label + ": max " + fmt("%.3g", s.y[best]) + " at s/L = " + fmt("%.3g", s.x[best]));
    }
    if (!rows.empty())
      a.notes.push_back("z = " + fmt("%.3g", rows[0]->metrics.z_m * 1e3) + " mm (plate bottoms, window middle)");
    fig.panels = {a};
  } else {
    // ---- anything else: first swept key on x, mean drag and lift on y ----
    out.kind = "generic";
    fig.title = scene_name + ": mean forces vs " + (varies.empty() ? std::string("run") : varies[0].column);
    std::vector<std::string> firsts;
    for (const SweepRow* r : rows) firsts.push_back(r->values.empty() ? "" : r->values[0]);
    std::vector<double> xs;
    const bool numeric = all_numeric(firsts, xs);
    std::map<const SweepRow*, double> xmap;
    for (size_t i = 0; i < rows.size(); ++i) xmap[rows[i]] = numeric ? xs[i] : double(i);
    const RowValue x = [xmap](const SweepRow& r) { return xmap.at(&r); };
    std::vector<bool> d(varies.size(), false);
    if (!d.empty()) d[0] = true;
    const auto cs = curves(varies, rows, d, x);
    render::PlotPanel a;
    a.x_label = varies.empty() ? "run" : varies[0].column + (numeric ? "" : " (run index)");
    a.y_label = "mean force over the averaging window (N/m)";
    a.title = "mean drag and lift";
    std::vector<std::string> names;
    if (!rows.empty())
      for (const auto& b : rows[0]->metrics.bodies)
        if (b.moving || lead.empty()) names.push_back(b.name);
    int color = 0;
    for (const auto& c : cs)
      for (const auto& name : names)
        for (auto [what, field] : {std::pair{"drag", &BodyMetrics::mean_drag_N_per_m},
                                   std::pair{"lift", &BodyMetrics::mean_lift_N_per_m}}) {
          if (a.series.size() >= 12) break;
          const RowValue y = [name, field = field](const SweepRow& r) {
            const BodyMetrics* b = find_body(r.metrics, name);
            return b ? b->*field : NAN;
          };
          auto s = series(name + " " + what + (c.label.empty() ? "" : " (" + c.label + ")"), c.rows, x, y, color++);
          s.dashed = std::string(what) == "lift";
          a.series.push_back(s);
        }
    fig.panels = {a};
    fig.width = 1000;
  }
  return out;
}

}  // namespace furrow::sweep
