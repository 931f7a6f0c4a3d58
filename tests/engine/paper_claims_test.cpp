// Each paper-claim measure (paper_claims.hpp) on constructed traces: it passes one that has the
// claim and fails one that does not, on the depths, widths and separations the claim tests use.
// Without these, a claim test could pass whatever the solver did.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/engine/paper_claims.hpp"

namespace furrow::paper {
namespace {

const std::vector<double> kCylinderDepthsD = {2.5, 5.0, 10.0, 15.0};  // PaperCase1's |z|/D

std::vector<double> of(const std::vector<double>& z, double (*f)(double)) {
  std::vector<double> out;
  for (double d : z) out.push_back(f(d));
  return out;
}

// Case 1, drag linear in depth: any straight line passes (through the origin or not); sqrt(z) and
// z^1.5 fail on the same four depths, where both reach R^2 0.987 / 0.990 in a straight-line fit
// (the check this measure replaced: R^2 >= 0.97).
TEST(PaperClaimMeasures, LinearInDepthRejectsSqrtAndThreeHalvesPowers) {
  const auto& z = kCylinderDepthsD;
  EXPECT_TRUE(linear_in_depth(z, of(z, [](double d) { return 17.7 * d; }), 0.15));
  EXPECT_TRUE(linear_in_depth(z, of(z, [](double d) { return 17.7 * d - 27.7; }), 0.15));
  EXPECT_TRUE(linear_in_depth(z, of(z, [](double d) { return 30.0 + 5.0 * d; }), 0.15));
  const auto root = of(z, [](double d) { return std::sqrt(d); });
  const auto three_halves = of(z, [](double d) { return std::pow(d, 1.5); });
  EXPECT_GE(fit_line(z, root).r2, 0.97);  // what the old check accepted
  EXPECT_GE(fit_line(z, three_halves).r2, 0.97);
  EXPECT_FALSE(linear_in_depth(z, root, 0.15)) << secant_slope_ratio(z, root);
  EXPECT_FALSE(linear_in_depth(z, three_halves, 0.15)) << secant_slope_ratio(z, three_halves);
  // the bounds: z^0.85 and z^1.15 on these depths
  EXPECT_NEAR(power_law_slope_ratio(z, 1.0), 1.0, 1e-12);
  EXPECT_LT(power_law_slope_ratio(z, 0.85), 0.95);
  EXPECT_GT(power_law_slope_ratio(z, 1.15), 1.05);
}

// Case 1, lift levels off: a lift that plateaus passes; one growing linearly, one growing with the
// drag (lift = drag / 4, drag 25.95 / 54.49 / 138.2 / 245.6 F0) and one growing +38% from 10 to
// 15 D while the drag grows +78% (what the old check, |lift change| < drag change / 2, passed) fail.
TEST(PaperClaimMeasures, LevellingOffRejectsALiftGrowingWithTheDrag) {
  const auto& z = kCylinderDepthsD;
  const std::vector<double> drag = {25.95, 54.49, 138.2, 245.6};
  const std::vector<double> plateau = {7.1, 9.9, 37.6, 40.0};
  EXPECT_LT(levelling_ratio(z, plateau), 0.5);
  const std::vector<double> linear = {2.5, 5.0, 10.0, 15.0};
  EXPECT_NEAR(levelling_ratio(z, linear), 1.0, 1e-12);
  std::vector<double> with_drag;
  for (double d : drag) with_drag.push_back(d / 4.0);
  EXPECT_GT(levelling_ratio(z, with_drag), 1.0);
  const std::vector<double> plus38 = {7.1, 9.9, 37.6, 1.38 * 37.6};
  const double old_measure = (plus38[3] / plus38[2] - 1.0) / (drag[3] / drag[2] - 1.0);
  EXPECT_LT(old_measure, 0.5);  // the old check passed it
  EXPECT_GE(levelling_ratio(z, plus38), 0.5);
  // a lift that never grew has not levelled off from anything
  EXPECT_TRUE(std::isnan(levelling_ratio(z, {5.0, 5.0, 5.0, 5.0})));
}

// Case 2, onset force ~ L^2: samples every 0.1 mm of z over 0..L/2 for L = 0.04 / 0.06 / 0.08 m,
// the window 5-20 mm. The bearing-capacity line F = rho_d g L (N_q z + N_gamma L / 2) gives
// exponents 2 and 1; F = c z L (no onset force), which gave exactly 2.000 with the mean over
// z in [L/8, L/2] (the measure this one replaced), has no onset exponent; F = c z L^2 + d L (the
// scalings swapped) fails both.
TEST(PaperClaimMeasures, OnsetScalingRejectsATraceWithoutAnOnsetForce) {
  const std::vector<double> widths = {0.04, 0.06, 0.08};
  const double rho_g = 1512.0 * 9.81;
  auto traces = [&](double (*F)(double z, double L, double rho_g)) {
    std::vector<std::vector<double>> z(widths.size()), f(widths.size());
    for (size_t i = 0; i < widths.size(); ++i)
      for (double d = 0.0; d <= 0.5 * widths[i] + 1e-12; d += 1e-4) z[i].push_back(d), f[i].push_back(F(d, widths[i], rho_g));
    return std::make_pair(z, f);
  };
  auto scaling = [&](double (*F)(double, double, double)) {
    const auto [z, f] = traces(F);
    return onset_scaling(widths, z, f, 0.005, 0.02);
  };
  const OnsetScaling bearing = scaling([](double z, double L, double rg) { return rg * L * (20.0 * z + 3.5 * L); });
  EXPECT_NEAR(bearing.onset_exponent, 2.0, 1e-9);
  EXPECT_NEAR(bearing.slope_exponent, 1.0, 1e-9);
  // what the old measure read on F = c z L: the mean over [L/8, L/2] ~ L^2
  std::vector<double> old_onset;
  for (double L : widths) old_onset.push_back(rho_g * 20.0 * L * (0.5 * (0.125 + 0.5) * L));
  EXPECT_NEAR(fit_power_law(widths, old_onset).slope, 2.0, 1e-9);
  const OnsetScaling no_onset = scaling([](double z, double L, double rg) { return rg * 20.0 * z * L; });
  EXPECT_FALSE(std::abs(no_onset.onset_exponent - 2.0) <= 0.3) << no_onset.onset_exponent;
  const OnsetScaling swapped = scaling([](double z, double L, double rg) { return rg * (400.0 * z * L * L + 0.05 * L); });
  EXPECT_FALSE(std::abs(swapped.onset_exponent - 2.0) <= 0.3) << swapped.onset_exponent;
  EXPECT_FALSE(std::abs(swapped.slope_exponent - 1.0) <= 0.15) << swapped.slope_exponent;
}

// Case 2, pair peak: samples at s/L 0, 0.3, 0.6, 1, 1.5, inf. A peak with lower values on both
// sides passes; a curve still rising at s/L 1.5, or one whose largest value is at s = 0, fails.
TEST(PaperClaimMeasures, InteriorPeakNeedsLowerValuesPastIt) {
  size_t k = 0;
  EXPECT_TRUE(interior_peak({10.4, 12.5, 12.6, 11.8, 11.0, 10.2}, 0.05, &k));
  EXPECT_EQ(k, 2u);
  EXPECT_FALSE(interior_peak({10.4, 11.0, 11.6, 12.2, 12.6, 10.2}, 0.05, &k));  // still rising at 1.5
  EXPECT_EQ(k, 4u);
  EXPECT_FALSE(interior_peak({12.6, 12.5, 12.0, 11.8, 11.0, 10.2}, 0.05));  // falls from s = 0
  EXPECT_FALSE(interior_peak({10.4, 10.6, 10.7, 10.5, 10.4, 10.2}, 0.05));  // within 5%: no peak
  // the four samples the test had until 2026-12-05 (s/L 0, 0.3, 0.6, inf) cannot show it
  EXPECT_FALSE(interior_peak({10.41, 12.53, 12.64, 10.16}, 0.05));
}

// Case 4, the wedge's apex approaches pi/2 - atan(mu_c) = 62.1 deg from the initial friction's
// 74.4 deg: within a third of the way (4.1 deg) of it. The old bound, 62.1 +- 8 deg, passed a zone
// stuck near its starting 74.4 deg in the truncated early form (70 deg).
TEST(PaperClaimMeasures, WedgeApproachRejectsAZoneThatDidNotSharpen) {
  EXPECT_TRUE(approaches(61.8, 62.1, 74.4));
  EXPECT_TRUE(approaches(65.9, 62.1, 74.4));
  EXPECT_FALSE(approaches(74.4, 62.1, 74.4));
  EXPECT_FALSE(approaches(68.3, 62.1, 74.4));  // halfway
  EXPECT_FALSE(approaches(57.0, 62.1, 74.4));  // past it by more than the tolerance
  EXPECT_LE(std::abs(69.9 - 62.1), 8.0);       // what the old bound accepted
  EXPECT_FALSE(approaches(69.9, 62.1, 74.4));
}

}  // namespace
}  // namespace furrow::paper
