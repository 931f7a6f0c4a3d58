// The granular model where it is hardest to integrate: over-compacted DPM plowed into shear bands
// (friction softening with strain), and material at the apex of the yield cone (zero pressure, so
// zero strength) at a free surface at rest and on a collapsing slope. The shipped templates, run
// coarse and short.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "tests/stability/stability_check.hpp"
#include "tests/stability/stability_scenes.hpp"

using namespace furrow;
using namespace furrow::stability;

// ----------------------------------------------------------------------------- (4) DPM plowing
// scenes/plowing.json (phi_i 0.63 > phi_c 0.60, chi 5) at dx 8 mm, the bed cut to 0.4 m and the
// plate run 0.1 m at 0.2 m/s. Shearing dilates the dense bed toward phi_c and softens its friction
// from 0.55 toward 0.40: the strain-softening that localises into shear bands.
class DpmPlowing : public ::testing::TestWithParam<ContactMethod> {};

TEST_P(DpmPlowing, OvercompactedBedShearBands) {
  const Scene s = from_template("plowing", {"domain.dx_m=0.008", "domain.width_m=0.4", "beds.0.max_m=[0.4,0.12]",
                                            "solver.end_displacement_m=0.1",
                                            "bodies.plate.motion.velocity_m_s=[0.2,0]",
                                            std::string("solver.contact=") + contact_name(GetParam())});
  Simulation sim(s);
  ASSERT_FALSE(sim.particles().phi_d.empty());
  ASSERT_FALSE(sim.particles().plastic_strain.empty());  // the template stores strain_rate
  Checker check(sim);
  double drag_max = 0.0;
  const RunResult r = run_checked(sim, check, 1, [&](const Simulation& m) {
    drag_max = std::max(drag_max, -m.bodies()[0].force_N_per_m.x());
  });
  print_summary((std::string("dpm plowing, ") + contact_name(GetParam())).c_str(), sim, check, r);
  ASSERT_TRUE(r.ok);
  EXPECT_GE(sim.lead_body_travel_m(), 0.1);
  // the bed softened where it sheared: some points dilated at least halfway to phi_c, and their
  // plastic strain is of order one (a band), not the elastic 1e-4
  const auto& p = sim.particles();
  EXPECT_LT(*std::min_element(p.phi_d.begin(), p.phi_d.end()), 0.615);
  EXPECT_GT(*std::max_element(p.plastic_strain.begin(), p.plastic_strain.end()), 0.1);
  for (double phi_d : p.phi_d) ASSERT_TRUE(phi_d >= 0.45 && phi_d <= 0.63) << phi_d;  // [phi_min, phi_i]
  // passive earth pressure order: rho_d g d^2 / 2 times a Rankine factor > 1 on the 5 cm face
  EXPECT_GT(drag_max, 0.5 * 2520.0 * 0.63 * kG * 0.05 * 0.05);
}

INSTANTIATE_TEST_SUITE_P(Contact, DpmPlowing, ::testing::Values(ContactMethod::Node, ContactMethod::Particle),
                         [](const auto& info) { return std::string(contact_name(info.param)); });

// ----------------------------------------------------------------------------- (5) yield apex
// scenes/hydrostatic_bed.json at dx 10 mm with the paper's linear kernel: the top row of points
// carries almost no pressure, so any shear there is plastic; at rest nothing may move.
TEST(YieldApex, FreeSurfaceAtRestStaysAtRest) {
  const Scene s = from_template("hydrostatic_bed", {"domain.dx_m=0.01", "solver.shape_function=\"linear\""});
  Simulation sim(s);
  Checker check(sim);
  double v_max = 0.0;
  const RunResult r = run_checked(sim, check, 1, [&](const Simulation& m) { v_max = std::max(v_max, m.stats().max_speed_m_s); });
  print_summary("free surface at rest", sim, check, r);
  ASSERT_TRUE(r.ok);
  // at rest: far below the speed a point falling one cell would reach, sqrt(2 g dx)
  EXPECT_LT(v_max, 0.01 * std::sqrt(2.0 * kG * s.domain.dx_m));
}

// scenes/column_collapse.json at dx 8 mm with the cubic kernel: a 0.1 m column against the left
// wall slumps into a heap. Its surface goes through the apex everywhere: it shears at zero
// pressure, opens and re-compacts.
TEST(YieldApex, CollapsingColumn) {
  const Scene s = from_template("column_collapse", {"domain.dx_m=0.008", "solver.shape_function=\"cubic\""});
  Simulation sim(s);
  Checker check(sim);
  const RunResult r = run_checked(sim, check);
  print_summary("column collapse", sim, check, r);
  ASSERT_TRUE(r.ok);
  // it collapsed: the front ran out well past the initial 0.1 m width
  const auto& p = sim.particles();
  EXPECT_GT(*std::max_element(p.x.begin(), p.x.end()), 0.15);
}
