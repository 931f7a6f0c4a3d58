// The measures the paper-claim tests apply to their force numbers, as pure functions, so that
// paper_claims_test.cpp can show each one failing on a constructed trace that lacks the claim
// (a claim test that passes whatever the solver does would assert nothing).
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

namespace furrow::paper {

struct Fit {
  double slope = 0.0, intercept = 0.0, r2 = 0.0;
};

inline Fit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = double(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  for (size_t i = 0; i < x.size(); ++i)
    sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i], syy += y[i] * y[i];
  const double vxx = sxx - sx * sx / n, vxy = sxy - sx * sy / n, vyy = syy - sy * sy / n;
  Fit f;
  f.slope = vxy / vxx;
  f.intercept = (sy - f.slope * sx) / n;
  f.r2 = vxy * vxy / (vxx * vyy);
  return f;
}

// F = c L^n: slope of log F against log L. NaN when a value is not positive (no power law).
inline Fit fit_power_law(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<double> lx, ly;
  for (size_t i = 0; i < x.size(); ++i) {
    if (!(x[i] > 0.0) || !(y[i] > 0.0)) return {std::nan(""), std::nan(""), std::nan("")};
    lx.push_back(std::log(x[i])), ly.push_back(std::log(y[i]));
  }
  return fit_line(lx, ly);
}

// ---- linear in depth (case 1's drag) -------------------------------------------------------------
// The slope between the two deepest samples over the slope between the two shallowest: 1 for any
// straight line, whatever its offset (a line through the origin, or one starting below a surface
// layer); below 1 for a force that levels off (sqrt z), above for one that steepens (z^1.5). A
// log-log exponent would not do: F = b (z - z0), straight, reads above 1 for z0 > 0.
inline double secant_slope_ratio(const std::vector<double>& z, const std::vector<double>& F) {
  const size_t n = z.size();
  if (n < 3) return std::nan("");
  return ((F[n - 1] - F[n - 2]) / (z[n - 1] - z[n - 2])) / ((F[1] - F[0]) / (z[1] - z[0]));
}

// What `secant_slope_ratio` reads for F = z^exponent on the same depths: the bounds of "linear
// within an exponent of 1 +- tolerance".
inline double power_law_slope_ratio(const std::vector<double>& z, double exponent) {
  std::vector<double> F;
  for (double d : z) F.push_back(std::pow(d, exponent));
  return secant_slope_ratio(z, F);
}

// F(z) is linear in z as far as a power law of exponent 1 +- tolerance would be.
inline bool linear_in_depth(const std::vector<double>& z, const std::vector<double>& F, double exponent_tolerance) {
  const double r = secant_slope_ratio(z, F);
  return r >= power_law_slope_ratio(z, 1.0 - exponent_tolerance) && r <= power_law_slope_ratio(z, 1.0 + exponent_tolerance);
}

// ---- levelling off (case 1's lift) ---------------------------------------------------------------
// The growth per unit depth over the deepest interval over the steepest growth per unit depth of
// the intervals before it: near 0 for a force that has levelled off, 1 for one still growing
// linearly, above 1 for one growing as a steepening drag does.
inline double levelling_ratio(const std::vector<double>& z, const std::vector<double>& F) {
  const size_t n = z.size();
  if (n < 3) return std::nan("");
  double steepest = -INFINITY;
  for (size_t i = 0; i + 2 < n; ++i) steepest = std::max(steepest, (F[i + 1] - F[i]) / (z[i + 1] - z[i]));
  if (!(steepest > 0.0)) return std::nan("");  // it never grew: nothing levelled off
  return ((F[n - 1] - F[n - 2]) / (z[n - 1] - z[n - 2])) / steepest;
}

// ---- onset force ~ L^2 (case 2) ------------------------------------------------------------------
// Near the surface F = a + b z (a: the force that starts the flow, b z: the growth with depth; for
// the bearing-capacity line F = rho_d g L (N_q z + N_gamma L / 2), a ~ L^2 and b ~ L). Fitted per
// width over one window of absolute depth, the exponents of a and b against L. F = c z L (no
// onset force) has a = 0: its a exponent is NaN.
struct OnsetScaling {
  std::vector<double> onset_N_per_m, slope_N_per_m2;  // a and b per width
  double onset_exponent = 0.0, slope_exponent = 0.0;
};
// traces[i]: (z_m, F_N_per_m) samples of width widths_m[i]
inline OnsetScaling onset_scaling(const std::vector<double>& widths_m, const std::vector<std::vector<double>>& z_m,
                                  const std::vector<std::vector<double>>& F_N_per_m, double from_m, double to_m) {
  OnsetScaling s;
  for (size_t i = 0; i < widths_m.size(); ++i) {
    std::vector<double> zs, Fs;
    for (size_t k = 0; k < z_m[i].size(); ++k)
      if (z_m[i][k] >= from_m && z_m[i][k] <= to_m) zs.push_back(z_m[i][k]), Fs.push_back(F_N_per_m[i][k]);
    const Fit line = fit_line(zs, Fs);
    s.onset_N_per_m.push_back(line.intercept);
    s.slope_N_per_m2.push_back(line.slope);
  }
  s.onset_exponent = fit_power_law(widths_m, s.onset_N_per_m).slope;
  s.slope_exponent = fit_power_law(widths_m, s.slope_N_per_m2).slope;
  return s;
}

// ---- an interior maximum (case 2's pair) ---------------------------------------------------------
// values[i] at increasing separations, the last standing for s -> infinity: the maximum lies at
// an interior sample with at least one finite separation past it (so a curve still rising at the
// largest finite separation fails), and stands at least `margin` (relative) above the first and
// the last samples.
inline bool interior_peak(const std::vector<double>& values, double margin, size_t* peak_index = nullptr) {
  if (values.size() < 3) return false;
  const size_t k = size_t(std::max_element(values.begin(), values.end()) - values.begin());
  if (peak_index) *peak_index = k;
  if (k == 0 || k + 1 >= values.size()) return false;
  if (k + 2 >= values.size()) return false;  // no finite separation past the peak
  return values[k] >= (1.0 + margin) * values.front() && values[k] >= (1.0 + margin) * values.back();
}

// ---- approaching an angle (case 4's wedge) -------------------------------------------------------
// A measured angle has approached `target` from `start` when it lies within a third of the way
// between them of the target: a zone stuck at its starting angle, or gone only halfway, fails.
inline bool approaches(double measured_deg, double target_deg, double start_deg) {
  return std::abs(measured_deg - target_deg) <= std::abs(start_deg - target_deg) / 3.0;
}

}  // namespace furrow::paper
