// (9) A long quiet run: a small bed started in geostatic equilibrium, 1e5 steps with nothing
// acting on it but gravity. Round-off and the discrete equilibrium's misfit may ring it, but
// nothing may accumulate: no surface drift, no creeping plastic strain, no energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tests/stability/stability_check.hpp"
#include "tests/stability/stability_scenes.hpp"

using namespace furrow;
using namespace furrow::stability;

namespace {

// Height of the highest point in each particle column (points are seeded at column centres
// (k + 1/2) h, h = dx / ppc, and a bed at rest keeps them there to far below h / 2).
std::vector<double> surface_m(const Particles& p, double h_m, int columns) {
  std::vector<double> top(size_t(columns), -1.0);
  for (size_t i = 0; i < p.size(); ++i) {
    const int k = std::clamp(int(std::floor(p.x[i] / h_m)), 0, columns - 1);
    top[size_t(k)] = std::max(top[size_t(k)], p.y[i]);
  }
  return top;
}

double max_of(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

}  // namespace

TEST(QuietBed, HundredThousandStepsAtRest) {
  constexpr int64_t kSteps = 100000;
  const double w_m = 0.04, h_m = 0.02, dx_m = 0.0025;
  Scene s = bed(w_m, h_m, 0.01, dx_m, 1e6);
  s.solver.max_steps = int(kSteps);
  s.outputs.fields = {"plastic_strain"};  // the solver keeps plastic strain only when a field needs it
  Simulation sim(s);
  ASSERT_EQ(sim.particles().plastic_strain.size(), sim.particles().size());

  // Bounds from the material. M = K + 4G/3 is the constrained (oedometric) modulus.
  const Material& mat = s.materials[0];
  const MaterialParams mp = MaterialParams::from(mat, true);
  const double M_Pa = mp.K + 4.0 * mp.G / 3.0, rho_d = mat.grain_density_kg_m3 * s.beds[0].packing_fraction;
  // Settlement of the whole bed from stress-free to its weight: sum of rho_d g z / M over the depth.
  // The geostatic start already carries it; what is left is the misfit between the continuum
  // equilibrium and the discrete one, a fraction of it, and with no damping the surface rings
  // about the discrete equilibrium by at most that misfit again: 2x the settlement bounds it.
  const double settlement_m = rho_d * kG * h_m * h_m / (2.0 * M_Pa);
  const double drift_bound_m = 2.0 * settlement_m;
  // The largest elastic strain the bed's own weight causes (at the floor). Plastic flow in a bed
  // at rest can only come from the same misfit; more than that strain anywhere is plastic creep.
  const double plastic_bound = rho_d * kG * h_m / M_Pa;
  ASSERT_LT(drift_bound_m, 0.01 * dx_m);  // the bound is far below a cell: a real test of rest

  const int ppc = s.solver.particles_per_cell_1d, columns = int(std::lround(w_m / dx_m)) * ppc;
  const double col_m = dx_m / ppc;
  const std::vector<double> top0 = surface_m(sim.particles(), col_m, columns);
  Checker check(sim);
  double drift_m = 0.0, plastic_half = 0.0;
  const RunResult r = run_checked(sim, check, 100, [&](const Simulation& m) {
    if (m.step_count() % 100) return;
    const std::vector<double> top = surface_m(m.particles(), col_m, columns);
    for (size_t k = 0; k < top.size(); ++k) drift_m = std::max(drift_m, std::abs(top[k] - top0[k]));
    if (m.step_count() == kSteps / 2) plastic_half = max_of(m.particles().plastic_strain);
  });
  print_summary("quiet bed", sim, check, r);
  const double plastic_end = max_of(sim.particles().plastic_strain);
  std::printf("[stability] quiet bed: surface drift %.3g m (bound %.3g m, settlement %.3g m), max plastic strain "
              "%.3g at half time, %.3g at the end (bound %.3g)\n",
              drift_m, drift_bound_m, settlement_m, plastic_half, plastic_end, plastic_bound);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(sim.step_count(), kSteps);
  EXPECT_LT(drift_m, drift_bound_m);
  EXPECT_LT(plastic_end, plastic_bound);
}
