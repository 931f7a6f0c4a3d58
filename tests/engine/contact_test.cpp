// Body contact free of grid artifacts: the force on an intruder fluctuates only where the flow
// does, not each time a face crosses a node line (issue 11). Templates at their preview dx.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "engine/analysis.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"
#include "tests/engine/test_scenes.hpp"

using namespace furrow;

namespace {

struct Trace {
  std::vector<double> travel_m, drag_N_per_m;
  double dx_m = 0.0;
};

// Runs a template until its lead body has travelled `travel_m` (the template's own end if <= 0).
// `shift_cells` moves the bodies sideways by that fraction of a cell (off the node lines).
Trace run_template(const std::string& name, double travel_m, ContactMethod contact, double shift_cells = 0.0) {
  Scene s = load_scene((std::filesystem::path(FURROW_SOURCE_DIR) / "scenes" / (name + ".json")).string());
  s.solver.contact = contact;
  for (auto& b : s.bodies) b.start_m.x() += shift_cells * s.domain.dx_m;
  if (travel_m > 0.0) s.solver.end_displacement_m = travel_m;
  s.outputs.fields.clear();
  Simulation sim(s);
  Trace t;
  t.dx_m = s.domain.dx_m;
  while (!sim.finished()) {
    sim.step();
    const BodyState& b = sim.bodies()[0];
    t.travel_m.push_back(sim.lead_body_travel_m());
    t.drag_N_per_m.push_back(-b.force_N_per_m.dot(b.velocity_m_s.normalized()));
  }
  return t;
}

void report(const char* what, const ForceSmoothness& f) {
  std::printf("%s: mean %.1f N/m, peak/one-cell mean %.3f at %.1f mm, RMS about it %.2f%%, cell-period component %.2f%%, "
              "largest single-step tick %.2f%%\n",
              what, f.mean_N_per_m, f.peak_ratio, 1e3 * f.peak_at_m, 100 * f.rms_relative,
              100 * f.cell_amplitude_relative, 100 * f.tick_max_relative);
}

// plate_intrusion at its preview dx over its averaging window (45..85 mm of travel)
ForceSmoothness plate_intrusion_smoothness(ContactMethod contact, double shift_cells = 0.0) {
  const Trace t = run_template("plate_intrusion", 0.0855, contact, shift_cells);
  const ForceSmoothness f = force_smoothness(t.travel_m, t.drag_N_per_m, t.dx_m, 0.045, 0.085);
  char what[96];
  std::snprintf(what, sizeof what, "plate_intrusion, %s, shifted %.2f cell", contact_method_name(contact), shift_cells);
  report(what, f);
  return f;
}

// loose_intrusion (plate 2 mm above the bed at the start) from three cells of penetration
ForceSmoothness loose_intrusion_smoothness(ContactMethod contact, double travel_m) {
  const Trace t = run_template("loose_intrusion", travel_m, contact);
  const double gap = 0.002, dx = t.dx_m;
  const ForceSmoothness f = force_smoothness(t.travel_m, t.drag_N_per_m, dx, gap + 3 * dx, t.travel_m.back() - 0.5 * dx);
  report((std::string("loose_intrusion, ") + contact_method_name(contact)).c_str(), f);
  return f;
}

}  // namespace

// plate_intrusion (dx 10 mm) over its averaging window (45..85 mm of travel). Node contact gave
// peak 1.46x, RMS 8.9%, cell component 7.8%; particle contact 1.12x, 3.4%, 1.7%. What remains in
// the RMS is not at the cell period: the largest components have periods of 8, 5.7 and 20 mm
// of travel (2.4%, 1.3%, 1.6%), the bed's elastic response at E 5 MPa, so the 2% RMS
// target is not met and the bound here is 4%.
TEST(ContactSmoothness, PlateIntrusionForceHasNoCellComb) {
  const ForceSmoothness f = plate_intrusion_smoothness(ContactMethod::Particle);
  EXPECT_LE(f.peak_ratio, 1.15);
  EXPECT_LE(f.cell_amplitude_relative, 0.02);
  EXPECT_LE(f.rms_relative, 0.04);
}

// loose_intrusion (plate 2 mm above the bed at the start). The first cells of penetration are
// the impact on loose, stress-free material (at dx 2.5 mm, the preview until 2026-12-03: particle
// rows struck one by one, peak 1.42x the one-cell mean at 2.9 mm depth, 1.2x at 5 mm; node contact
// 7.8x); from three cells on no step rises above 1.2x its one-cell mean (dx 2.5 mm: 1.07x over the
// whole run, node contact 3.8x at 10 mm depth, 2.2x late; dx 2 mm, 35 mm: 1.106x, RMS 1.88%). The
// test stops at 35 mm of travel to save time.
TEST(ContactSmoothness, LooseIntrusionHasNoSpikes) {
  const ForceSmoothness f = loose_intrusion_smoothness(ContactMethod::Particle, 0.035);  // 33 of its 60 mm
  EXPECT_LE(f.peak_ratio, 1.2);
  EXPECT_LE(f.cell_amplitude_relative, 0.02);
}

// Cell-fraction contact on the same two templates. plate_intrusion (its plate's sides lie on node
// lines): 1.038x, RMS 1.45%, cell component 0.68%, largest single-step tick 0.65% (node 1.46x,
// 8.9%, 7.8%); half a cell off the node lines: 1.027x, 1.13%, 1.00%, 0.71%. Until 2026-12-04
// G2P's safety net took a point's approach out of its velocity as it put it back on the plate's
// face, which put single-step ticks of up to 16.8% on the force and a 1.133x peak; the tick bound
// (2%) is what that fix holds. The mass-gradient normal this method used before met the peak
// (1.13x) but not the rest half a cell sideways (2.15%, 2.0%); its first form, a ramp, met the
// first case (1.12x, 2.4%, 2.05%) but not the second (1.09x, 5.3%, 5.9%), which is why the test
// runs both. loose_intrusion: 1.054x, RMS 1.97%, tick 0.12% over 23 mm at its 2 mm preview.
TEST(ContactSmoothness, CellFractionPlateIntrusionHasNoCellComb) {
  for (double shift_cells : {0.0, 0.5}) {
    const ForceSmoothness f = plate_intrusion_smoothness(ContactMethod::CellFraction, shift_cells);
    EXPECT_LE(f.peak_ratio, 1.05) << "shifted " << shift_cells << " cell";
    EXPECT_LE(f.cell_amplitude_relative, 0.02) << "shifted " << shift_cells << " cell";
    EXPECT_LE(f.rms_relative, 0.02) << "shifted " << shift_cells << " cell";
    EXPECT_LE(f.tick_max_relative, 0.02) << "shifted " << shift_cells << " cell";
  }
}

TEST(ContactSmoothness, CellFractionLooseIntrusionHasNoSpikes) {
  const ForceSmoothness f = loose_intrusion_smoothness(ContactMethod::CellFraction, 0.025);  // 23 of its 60 mm
  EXPECT_LE(f.peak_ratio, 1.2);
  EXPECT_LE(f.cell_amplitude_relative, 0.02);
  EXPECT_LE(f.tick_max_relative, 0.02);
}

// Onset: a 0.04 m plate descending at 0.1 m/s from 2 cells (10 mm) above a bed, dx 5 mm. Until
// its face is within a quarter cell of the material's surface it feels less than 1% of its force
// after one cell of penetration (measured: exactly 0 of 189 N/m with particle contact, 0 of 137
// with cell_fraction, which starts a fifth of a cell out); node contact feels the bed early
// (40 N/m, 37% of its 109 N/m at one cell). Node's early force is printed, not asserted: it is the
// artifact particle and cell-fraction contact remove, and a fix of node contact must not fail a test.
TEST(ContactOnset, ParticleAndCellFractionContactStartWhenTheSurfacesMeet) {
  const double dx = 0.005, gap = 2 * dx, bed_top = 0.1;
  for (ContactMethod method : {ContactMethod::Particle, ContactMethod::CellFraction, ContactMethod::Node}) {
    Scene s = test_scenes::bed_scene(0.2, bed_top, 0.03, dx, 10.0);
    s.solver.contact = method;
    s.solver.end_displacement_m = gap + 1.2 * dx;
    s.bodies.push_back(test_scenes::plate(0.04, 0.01, 0.1, bed_top + gap, Vec2(0.0, -0.1)));
    Simulation sim(s);
    std::vector<double> depth, force;
    while (!sim.finished()) {
      sim.step();
      depth.push_back(sim.lead_body_travel_m() - gap);
      force.push_back(sim.bodies()[0].force_N_per_m.y());
    }
    double before = 0.0, at_one_cell = 0.0;
    int n = 0;
    for (size_t k = 0; k < depth.size(); ++k) {
      if (depth[k] < -0.25 * dx) before = std::max(before, std::abs(force[k]));
      if (depth[k] >= 0.9 * dx && depth[k] <= 1.1 * dx) at_one_cell += force[k], ++n;
    }
    at_one_cell /= std::max(n, 1);
    std::printf("%s contact: force at one cell %.1f N/m, largest before the surfaces meet %.3f N/m\n",
                contact_method_name(method), at_one_cell, before);
    ASSERT_GT(at_one_cell, 0.0);
    if (method != ContactMethod::Node) {
      EXPECT_LT(before, 0.01 * at_one_cell);
    }
  }
}
