// The figure of a sweep (sweep.png), chosen from what the sweep varied:
//   drag_lift_vs_depth  the first moving body is a circle whose depth varies: normalized drag and
//                       lift vs |z|/D (paper case 1), with a straight-line fit of the drag
//   plate_width_scaling one moving box whose width varies: initial peak drag and window-mean drag
//                       vs L on log-log axes with fitted power-law exponents (paper case 2, single)
//   pair_separation     two or more moving boxes whose gap varies: mean drag per plate over
//                       rho_d g z L_avg w vs s/L_avg, one curve per L_avg (paper case 2, pairs)
//   collapse_runout     released columns (run.json "collapse") whose aspect ratio varies: runout
//                       (Lf - L0)/L0 vs a on log-log axes with the quasi-2D experiments' linear laws,
//                       and the final deposits' surfaces
//   generic             the first swept key on x, the mean drag and lift of each moving body on y
// Rows that differ in other swept keys become separate curves.
#pragma once
#include <string>
#include <vector>

#include "app/sweep.hpp"
#include "render/plot.hpp"

namespace furrow::sweep {

struct LineFit {
  double slope = 0.0, intercept = 0.0, r2 = 0.0;
  size_t n = 0;
};
// Least squares y = intercept + slope x over the finite pairs.
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);
// y = c x^n by least squares on logs (positive pairs only): slope = n, intercept = ln c.
LineFit fit_power_law(const std::vector<double>& x, const std::vector<double>& y);

struct SweepFigure {
  std::string kind;  // one of the names above
  render::PlotFigure figure;
};

SweepFigure sweep_figure(const std::string& scene_name, const std::vector<Vary>& varies,
                         const std::vector<SweepRow>& rows);

}  // namespace furrow::sweep
