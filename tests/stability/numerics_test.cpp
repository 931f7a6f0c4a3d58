// The solver's numerical settings at the edges of what the schema accepts: one particle per cell,
// and the time step at the CFL limit (solver.cfl = 1, the largest value scenes/README.md allows),
// each under a plate pushed into a bed, with both contact methods and all three kernels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "tests/stability/stability_check.hpp"
#include "tests/stability/stability_scenes.hpp"

using namespace furrow;
using namespace furrow::stability;

namespace {

// A 40 x 10 mm plate starting 5 mm above a 0.15 x 0.05 m bed, pushed 25 mm in at 0.3 m/s.
Scene plate_scene(ContactMethod contact, ShapeFunction kernel) {
  const double dx_m = 0.005, bed_h_m = 0.05;
  Scene s = bed(0.15, bed_h_m, 0.03, dx_m, 1.0);
  s.solver.contact = contact;
  s.solver.shape_function = kernel;
  s.solver.end_displacement_m = 0.005 + 0.025;
  s.bodies.push_back(box("plate", Vec2(0.04, 0.01), Vec2(0.075, bed_h_m + 0.005 + 0.005), Vec2(0.0, -0.3)));
  return s;
}

// The plate pushed: at least the weight of the material column under it at the final depth.
double min_push_N_per_m() { return 2520.0 * 0.6 * kG * 0.04 * 0.025; }

}  // namespace

// ----------------------------------------------------------------------------- (7) one per cell
// particles_per_cell_1d = 1: a cell holds one point, so a node can be reached by a single point
// with a small weight, and particle contact sees points a whole cell across.
class OnePerCell : public ::testing::TestWithParam<ContactMethod> {};

TEST_P(OnePerCell, PlateIntoBed) {
  Scene s = plate_scene(GetParam(), ShapeFunction::Quadratic);
  s.solver.particles_per_cell_1d = 1;
  Simulation sim(s);
  Checker check(sim);
  double f_max = 0.0;
  const RunResult r = run_checked(sim, check, 1, [&](const Simulation& m) {
    f_max = std::max(f_max, m.bodies()[0].force_N_per_m.y());
  });
  print_summary((std::string("one per cell, ") + contact_name(GetParam())).c_str(), sim, check, r);
  ASSERT_TRUE(r.ok);
  EXPECT_GT(f_max, min_push_N_per_m());
}

INSTANTIATE_TEST_SUITE_P(Contact, OnePerCell, ::testing::Values(ContactMethod::Node, ContactMethod::Particle, ContactMethod::CellFraction),
                         [](const auto& info) { return std::string(contact_name(info.param)); });

// ----------------------------------------------------------------------------- (8) CFL limit
// cfl = 1: dt = dx / (c + v_body), the largest step the schema accepts. The solver's c is the
// P-wave speed at the initial density (denser material is slower), so this is the edge the
// time-step estimate claims to be stable at.
class CflLimit : public ::testing::TestWithParam<std::tuple<ShapeFunction, ContactMethod>> {};

TEST_P(CflLimit, PlateIntoBedAtCflOne) {
  const auto [kernel, contact] = GetParam();
  Scene s = plate_scene(contact, kernel);
  s.solver.cfl = 1.0;
  Simulation sim(s);
  Checker check(sim);
  double f_max = 0.0;
  const RunResult r = run_checked(sim, check, 1, [&](const Simulation& m) {
    f_max = std::max(f_max, m.bodies()[0].force_N_per_m.y());
  });
  print_summary((std::string("cfl 1, ") + shape_name(kernel) + ", " + contact_name(contact)).c_str(), sim, check, r);
  ASSERT_TRUE(r.ok);
  EXPECT_GT(f_max, min_push_N_per_m());
}

INSTANTIATE_TEST_SUITE_P(KernelsAndContact, CflLimit,
                         ::testing::Combine(::testing::Values(ShapeFunction::Linear, ShapeFunction::Quadratic,
                                                              ShapeFunction::Cubic),
                                            ::testing::Values(ContactMethod::Node, ContactMethod::Particle, ContactMethod::CellFraction)),
                         [](const auto& info) {
                           return std::string(shape_name(std::get<0>(info.param))) + "_" +
                                  contact_name(std::get<1>(info.param));
                         });

// A bed released stress-free at cfl = 1 settles under its own weight: the elastic wave that
// crosses it is the stiffest thing the time step must resolve. Settled: over each tenth of the run
// after the first, the stress carries the bed's weight on average (weight_carried_fraction: 1, up
// to the grid's floor excess; a bed that stayed stress-free reads 0), and the ringing does not grow
// (the last tenth's mean kinetic energy at most the first tenth's). It does not die out: FLIP 0.99
// barely damps it. Measured (0.5 s, mean KE of the last tenth over the first, weight carried):
// linear 0.89 (flat from the second tenth on, 28% of the largest KE), quadratic 0.57, cubic 0.17;
// weight 0.987-1.012, 1.003-1.030, 1.028-1.033 (2026-12-05).
TEST(CflLimit, StressFreeBedSettlesAtCflOne) {
  const double end_s = 0.5, dx_m = 0.005;
  for (ShapeFunction kernel : {ShapeFunction::Linear, ShapeFunction::Quadratic, ShapeFunction::Cubic}) {
    Scene s = bed(0.1, 0.05, 0.02, dx_m, end_s);
    s.beds[0].geostatic = false;
    s.solver.cfl = 1.0;
    s.solver.shape_function = kernel;
    Simulation sim(s);
    Checker check(sim);
    double ke_sum[10] = {}, carried_sum[10] = {};
    int n[10] = {};
    const RunResult r = run_checked(sim, check, 1, [&](const Simulation& m) {
      const int k = std::min(9, int(10.0 * m.time_s() / end_s));
      ke_sum[k] += m.kinetic_energy(), carried_sum[k] += weight_carried_fraction(m.particles(), kG), ++n[k];
    });
    print_summary((std::string("cfl 1 settling, ") + shape_name(kernel)).c_str(), sim, check, r);
    EXPECT_TRUE(r.ok) << shape_name(kernel);
    const double excess = floor_reaction_excess_bound(sim.particles(), dx_m);
    for (int k = 1; k < 10; ++k) {
      const double carried = carried_sum[k] / n[k];
      EXPECT_GT(carried, 0.97) << shape_name(kernel) << ", tenth " << k;
      EXPECT_LT(carried, 1.0 + excess) << shape_name(kernel) << ", tenth " << k;
    }
    const double ke_first = ke_sum[0] / n[0], ke_last = ke_sum[9] / n[9];
    std::printf("cfl 1 settling, %s: mean KE last tenth / first %.3g (%.3g of the largest); weight carried %.4f "
                "(1 up to +%.2f on the grid)\n",
                shape_name(kernel), ke_last / ke_first, ke_last / check.max_kinetic_energy_J(), carried_sum[9] / n[9],
                excess);
    EXPECT_LE(ke_last, ke_first) << shape_name(kernel);
  }
}
