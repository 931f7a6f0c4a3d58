// Return mapping of the NDPM/DPM point update (paper eqs. 1-6), one material point at a time.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/materials.hpp"
#include "tests/engine/test_scenes.hpp"

using namespace furrow;

namespace {

MaterialParams ndpm() { return MaterialParams::from(test_scenes::glass_beads(0.4), true); }

MaterialParams dpm(double chi) {
  Material m = test_scenes::glass_beads(0.4);
  m.model = MaterialModel::DPM;
  m.chi = chi;
  return MaterialParams::from(m, true);
}

double tau_of(const PointState& s) {
  return std::sqrt(0.5 * (s.sxx * s.sxx + s.syy * s.syy + s.szz * s.szz) + s.sxy * s.sxy);
}

// a dense point compressed to pressure P0 with a chosen deviator
PointState dense_point(const MaterialParams& p, double P0, double phi_d, double mass) {
  PointState s{};
  s.phi_d = phi_d;
  s.volume_m2 = mass / (p.rho_g * phi_d * std::exp(P0 / p.K));
  s.pressure_Pa = P0;
  return s;
}

}  // namespace

TEST(Ndpm, RandomStrainIncrementsStayInsideConeWithNonNegativePressure) {
  const auto p = ndpm();
  NdpmModel model{p};
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  const double mass = 1.0e-3, dt = 1e-5;
  int plastic = 0, open = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    PointState s = dense_point(p, 2000.0 * std::abs(n(rng)), p.phi_c, mass);
    for (int k = 0; k < 20; ++k) {
      const double scale = 5.0;  // velocity gradients up to ~5/s over dt: strains ~ 5e-5 per step
      model.update(dt, scale * n(rng), scale * n(rng), scale * n(rng), scale * n(rng), mass, s);
      const double tau = tau_of(s);
      ASSERT_GE(s.pressure_Pa, 0.0);
      ASSERT_LE(tau, p.mu * s.pressure_Pa * (1.0 + 1e-9) + 1e-12);
      ASSERT_NEAR(s.sxx + s.syy + s.szz, 0.0, 1e-9 * (1.0 + s.pressure_Pa));
      plastic += s.strain_rate_1_s > 0.0;
      open += s.pressure_Pa == 0.0;
    }
  }
  // the random walk must exercise both the cone return and the open state for this test to mean anything
  EXPECT_GT(plastic, 1000);
  EXPECT_GT(open, 100);
}

TEST(Ndpm, OpenMaterialCarriesNoStress) {
  const auto p = ndpm();
  NdpmModel model{p};
  const double mass = 1e-3;
  PointState s = dense_point(p, 500.0, p.phi_c, mass);
  s.sxx = 100.0;
  s.syy = -100.0;
  // expand by 2% in x: phi drops below phi_c
  model.update(1.0, 0.02, 0.0, 0.0, 0.0, mass, s);
  EXPECT_LT(mass / (p.rho_g * s.volume_m2), p.phi_c);
  EXPECT_EQ(s.pressure_Pa, 0.0);
  EXPECT_EQ(tau_of(s), 0.0);
}

TEST(Ndpm, PlasticCorrectionLeavesVolumeUnchanged) {
  const auto p = ndpm();
  NdpmModel model{p};
  const double mass = 1e-3, P0 = 1000.0;
  PointState s = dense_point(p, P0, p.phi_c, mass);
  const double v0 = s.volume_m2;
  // simple shear: traceless L, so the volume is untouched by kinematics as well
  const double g = 0.05;  // strain 5%: far past yield (tau_y / G ~ 2e-4)
  model.update(1.0, 0.0, g, 0.0, 0.0, mass, s);
  EXPECT_GT(s.strain_rate_1_s, 0.0);
  EXPECT_EQ(s.volume_m2, v0);
  EXPECT_NEAR(tau_of(s), p.mu * s.pressure_Pa, 1e-9 * P0);
  EXPECT_NEAR(s.pressure_Pa, P0, 1e-9 * P0);  // no plastic volume change: P untouched by the return
}

TEST(Ndpm, ElasticTrialBelowYieldIsReturnedUnchanged) {
  const auto p = ndpm();
  NdpmModel model{p};
  const double mass = 1e-3, P0 = 1000.0, dt = 1e-6, g = 1.0;
  PointState s = dense_point(p, P0, p.phi_c, mass);
  model.update(dt, 0.0, g, g, 0.0, mass, s);  // symmetric shear: D_xy = g, no spin
  EXPECT_EQ(s.strain_rate_1_s, 0.0);
  EXPECT_NEAR(s.sxy, 2.0 * p.G * g * dt, 1e-9 * p.G * g * dt);
  EXPECT_NEAR(s.pressure_Pa, P0, 1e-9 * P0);
}

TEST(Ndpm, RigidSpinRotatesStressWithoutChangingInvariants) {
  const auto p = ndpm();
  NdpmModel model{p};
  const double mass = 1e-3, P0 = 1000.0;
  PointState s = dense_point(p, P0, p.phi_c, mass);
  s.sxx = 150.0;
  s.syy = -150.0;
  s.szz = 0.0;
  const double tau0 = tau_of(s), omega = 2.0, dt = 1e-5;
  const int steps = int(0.25 * M_PI / omega / dt);  // rotate by 45 degrees
  for (int k = 0; k < steps; ++k) model.update(dt, 0.0, -omega, omega, 0.0, mass, s);
  // after 45 degrees a pure normal deviator becomes pure shear
  EXPECT_NEAR(tau_of(s), tau0, 1e-3 * tau0);
  EXPECT_NEAR(std::abs(s.sxy), 150.0, 0.01 * 150.0);
  EXPECT_NEAR(s.sxx, 0.0, 0.01 * 150.0);
  EXPECT_NEAR(s.pressure_Pa, P0, 1e-6 * P0);
}

TEST(Dpm, ZeroChiMatchesNdpmExactly) {
  const auto pn = ndpm();
  const auto pd = dpm(0.0);
  NdpmModel a{pn};
  DpmModel b{pd};
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 3.0);
  const double mass = 1e-3;
  PointState sa = dense_point(pn, 800.0, pn.phi_c, mass), sb = sa;
  for (int k = 0; k < 500; ++k) {
    const double l00 = n(rng), l01 = n(rng), l10 = n(rng), l11 = n(rng);
    a.update(1e-5, l00, l01, l10, l11, mass, sa);
    b.update(1e-5, l00, l01, l10, l11, mass, sb);
    ASSERT_DOUBLE_EQ(sa.pressure_Pa, sb.pressure_Pa);
    ASSERT_DOUBLE_EQ(sa.sxy, sb.sxy);
    ASSERT_DOUBLE_EQ(sa.volume_m2, sb.volume_m2);
  }
}

// phi_d relaxes toward phi_c under shear from both sides, monotonically; the sign of the
// volumetric response follows phi_d - phi_c.
TEST(Dpm, PhiDRelaxesTowardCriticalFromBothSides) {
  for (double phi0 : {0.55, 0.63}) {
    const auto p = dpm(5.0);
    DpmModel model{p};
    const double mass = 1e-3, dt = 1e-4;
    PointState s = dense_point(p, 2000.0, phi0, mass);
    double prev = std::abs(phi0 - p.phi_c);
    double last_phi = phi0;
    for (int k = 0; k < 400; ++k) {
      // shear while holding volume: the pressure must move with phi_d
      model.update(dt, 0.0, 20.0, 0.0, 0.0, mass, s);
      const double dist = std::abs(s.phi_d - p.phi_c);
      ASSERT_LE(dist, prev + 1e-15) << "phi0 " << phi0 << " step " << k;
      ASSERT_EQ((s.phi_d - p.phi_c) * (phi0 - p.phi_c) >= 0.0, true);  // never overshoots
      prev = dist;
      last_phi = s.phi_d;
    }
    EXPECT_LT(std::abs(last_phi - p.phi_c), std::abs(phi0 - p.phi_c)) << phi0;
    // at fixed volume, dilatant (phi_d falling) material gains pressure; contractant material
    // loses it until it opens and stops evolving
    const double phi = mass / (p.rho_g * s.volume_m2);
    EXPECT_NEAR(s.pressure_Pa, std::max(0.0, p.K * std::log(phi / s.phi_d)), 1e-6 * p.K);
    if (phi0 > p.phi_c) {
      EXPECT_GT(s.pressure_Pa, 2000.0);
      EXPECT_LT(std::abs(last_phi - p.phi_c), 0.5 * std::abs(phi0 - p.phi_c));
    } else {
      EXPECT_LT(s.pressure_Pa, 2000.0);
    }
  }
}

TEST(Dpm, OpeningBelowPhiMinResetsState) {
  const auto p = dpm(5.0);
  DpmModel model{p};
  const double mass = 1e-3;
  PointState s = dense_point(p, 0.0, 0.58, mass);
  // expand the area by 40%: phi = 0.58 / 1.4 ~ 0.41 < phi_min
  model.update(1.0, 0.4, 0.0, 0.0, 0.0, mass, s);
  EXPECT_EQ(s.phi_d, p.phi_min);
  EXPECT_EQ(s.pressure_Pa, 0.0);
  // a small opening keeps phi_d: the material will reconsolidate at its current state
  PointState t = dense_point(p, 0.0, 0.58, mass);
  model.update(1.0, 0.05, 0.0, 0.0, 0.0, mass, t);
  EXPECT_EQ(t.phi_d, 0.58);
}

// ---- mu(I) (effects.rate_dependence) ------------------------------------------------------------

namespace {

MaterialParams mu_i(MaterialModel model) {
  Material m = test_scenes::glass_beads(0.38);
  m.model = model;
  m.chi = model == MaterialModel::DPM ? 2.0 : 0.0;
  m.mu_2 = 0.64;  // Jop, Forterre & Pouliquen (2006), glass beads
  m.inertial_I0 = 0.279;
  m.grain_diameter_m = 0.53e-3;
  return MaterialParams::from(m, true);
}

double mu_of_I(const MaterialParams& p, double mu_s, double I) { return mu_s + p.dmu / (1.0 + p.I0 / I); }

}  // namespace

// Steady simple shear at fixed volume (a homogeneous layer): once the elastic strain stops
// changing, the plastic rate equals the imposed rate, so tau/P must be mu(I) of the imposed I.
TEST(RateDependence, SteadySimpleShearGivesMuOfI) {
  const auto p = mu_i(MaterialModel::NDPM);
  PlasticityModel<false, true> model{p};
  const double P0 = 1000.0, mass = 1e-3;
  for (double I : {0.01, 0.1, 1.0}) {
    const double gdot = I * std::sqrt(P0 / p.rho_g) / p.d_m;  // imposed engineering shear rate dvx/dy
    const double dt = 1e-4 / gdot;                             // 1e-4 strain per step
    PointState s = dense_point(p, P0, p.phi_c, mass);
    for (int i = 0; i < 20000; ++i) model.update(dt, 0.0, gdot, 0.0, 0.0, mass, s);
    const double ratio = tau_of(s) / s.pressure_Pa;
    EXPECT_NEAR(s.pressure_Pa, P0, 1e-9 * P0) << "fixed volume keeps the pressure";
    EXPECT_NEAR(ratio, mu_of_I(p, 0.38, I), 0.02 * mu_of_I(p, 0.38, I)) << "I = " << I;
    EXPECT_NEAR(s.strain_rate_1_s, gdot, 0.02 * gdot) << "steady: plastic rate = imposed rate";
  }
}

// The implicit return at its extremes: P -> 0 and I -> infinity, P large and I -> 0. The friction
// stays between mu_s and mu_2, the stress finite, and the static limit is the rate-independent law.
TEST(RateDependence, ReturnIsBoundedAtExtremeRatesAndPressures) {
  const auto p = mu_i(MaterialModel::NDPM);
  PlasticityModel<false, true> rate{p};
  PlasticityModel<false, false> plain{p};
  const double mass = 1e-3, mu_s = 0.38, mu_2 = 0.64;
  int flowing = 0;
  for (double P0 : {1e-9, 1e-3, 1.0, 1e3, 1e6})
    for (double gdot : {1e-6, 1.0, 1e3, 1e8}) {
      PointState s = dense_point(p, P0, p.phi_c, mass);
      for (int i = 0; i < 50; ++i) rate.update(1e-5, 0.0, gdot, 0.0, 0.0, mass, s);
      const double r = tau_of(s) / s.pressure_Pa;
      ASSERT_TRUE(std::isfinite(r)) << P0 << " " << gdot;
      EXPECT_LE(r, mu_2 * (1.0 + 1e-9)) << "P " << P0 << " rate " << gdot;
      // a point that flows sits on the yield surface, never under mu_s (an elastic one may)
      if (s.strain_rate_1_s > 0.0) {
        EXPECT_GE(r, mu_s * (1.0 - 1e-9)) << "P " << P0 << " rate " << gdot;
        ++flowing;
      }
    }
  EXPECT_GE(flowing, 8) << "the extremes must make points flow for the lower bound to be tested";
  // both bounds reached: steady shear (1e-3 strain a step, one unit of strain) at I from 1e-7 to
  // 1e4 at P 1 kPa reads mu(I) within 0.1% of it, from mu_s (mu(1e-7) - mu_s = 9e-8) to mu_2
  // (mu_2 - mu(1e4) = 7e-6)
  const double P0 = 1e3;
  std::vector<double> ratios;
  for (double I : {1e-7, 1e-3, 1.0, 1e4}) {
    const double gdot = I * std::sqrt(P0 / p.rho_g) / p.d_m, dt = 1e-3 / gdot;
    PointState s = dense_point(p, P0, p.phi_c, mass);
    for (int i = 0; i < 1000; ++i) rate.update(dt, 0.0, gdot, 0.0, 0.0, mass, s);
    ratios.push_back(tau_of(s) / s.pressure_Pa);
    EXPECT_GT(s.strain_rate_1_s, 0.0) << "I " << I;
    EXPECT_NEAR(ratios.back(), mu_of_I(p, mu_s, I), 1e-3 * mu_of_I(p, mu_s, I)) << "I " << I;
  }
  EXPECT_NEAR(ratios.front(), mu_s, 1e-3 * mu_s);
  EXPECT_NEAR(ratios.back(), mu_2, 1e-3 * mu_2);
  // vanishing rate: identical to the rate-independent return at mu_s within round-off
  PointState a = dense_point(p, 1e3, p.phi_c, mass), b = a;
  for (int i = 0; i < 2000; ++i) {
    rate.update(1e-5, 0.0, 1e-3, 0.0, 0.0, mass, a);
    plain.update(1e-5, 0.0, 1e-3, 0.0, 0.0, mass, b);
  }
  EXPECT_NEAR(tau_of(a), tau_of(b), 1e-6 * tau_of(b));
  // with mu_2 = mu_s the effect is the rate-independent law exactly (to round-off)
  Material m = test_scenes::glass_beads(0.38);
  m.mu_2 = 0.38;
  const auto same = MaterialParams::from(m, true);
  PlasticityModel<false, true> flat{same};
  PlasticityModel<false, false> flat_plain{same};
  PointState c = dense_point(same, 1e3, same.phi_c, mass), d = c;
  for (int i = 0; i < 2000; ++i) {
    flat.update(1e-5, 0.3, 50.0, -20.0, -0.2, mass, c);
    flat_plain.update(1e-5, 0.3, 50.0, -20.0, -0.2, mass, d);
  }
  EXPECT_NEAR(tau_of(c), tau_of(d), 1e-9 * tau_of(d));
  EXPECT_NEAR(c.pressure_Pa, d.pressure_Pa, 1e-9 * d.pressure_Pa);
}

// DPM: the rate part adds to the state-dependent static friction mu_c + (phi_d - phi_c) chi.
TEST(RateDependence, DpmAddsTheRatePartToTheStateFriction) {
  const auto p = mu_i(MaterialModel::DPM);
  PlasticityModel<true, true> model{p};
  const double P0 = 1000.0, mass = 1e-3, I = 0.3;
  const double gdot = I * std::sqrt(P0 / p.rho_g) / p.d_m, dt = 1e-4 / gdot;
  PointState s = dense_point(p, P0, p.phi_c, mass);  // at phi_c: phi_d stays at phi_c under shear
  for (int i = 0; i < 20000; ++i) model.update(dt, 0.0, gdot, 0.0, 0.0, mass, s);
  EXPECT_NEAR(s.phi_d, p.phi_c, 1e-12);
  EXPECT_NEAR(tau_of(s) / s.pressure_Pa, mu_of_I(p, p.friction(s.phi_d), I), 0.02 * mu_of_I(p, 0.38, I));
}

// The pressure's log of phi / phi_d: the series used near 1 agrees with the library log to round-off
// (a few units in the last place) on both sides of 1, through all its reach and past the switch to
// std::log.
TEST(LogNearOne, MatchesTheLibraryLogToRoundOff) {
  double worst = 0.0;
  for (double x = 1e-14; x < 2.0 * kLogSeriesReach; x *= 1.001)
    for (double q : {1.0 + x, 1.0 - x}) {
      const double ref = std::log(q), got = log_near_one(q);
      worst = std::max(worst, std::abs(got - ref) / std::abs(ref));
    }
  std::printf("largest relative difference from std::log: %.2g\n", worst);
  EXPECT_LT(worst, 4.0 * std::numeric_limits<double>::epsilon());
  EXPECT_EQ(log_near_one(1.0), 0.0);
  EXPECT_DOUBLE_EQ(log_near_one(0.5), std::log(0.5));
}
