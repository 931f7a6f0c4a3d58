// The dilatant model (DPM) in whole simulations: its NDPM limit, and the paper's transient cases 3
// (plowing: drag fluctuations vs initial packing) and 4 (loose intrusion: the rigid wedge sharpens
// to the slip-line angle), at the coarsest resolution that still shows each effect. Unit tests of
// the point update (relaxation of phi_d from both sides, phi_min reset) live in material_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>

#include "engine/analysis.hpp"
#include "engine/io/field_store.hpp"
#include "engine/simulation.hpp"
#include "tests/engine/paper_claims.hpp"
#include "tests/engine/test_scenes.hpp"

using namespace furrow;
using test_scenes::bed_scene;
using test_scenes::plate;
using paper::approaches;

namespace {

Material dpm_material(const std::string& name, double rho_g, double mu_c, double chi, double E_Pa) {
  Material m;
  m.name = name;
  m.model = MaterialModel::DPM;
  m.grain_density_kg_m3 = rho_g;
  m.phi_c = 0.60;
  m.mu = mu_c;
  m.chi = chi;
  m.phi_min = 0.45;
  m.youngs_modulus_Pa = E_Pa;
  m.poisson_ratio = 0.3;
  return m;
}

}  // namespace

// ------------------------------------------------------------------------ chi = 0 is NDPM
// A plate pushed into a bed at phi_i = phi_c: with chi = 0 the DPM state never moves
// (d phi_d / d gamma = -chi phi_c (phi_d - phi_c) = 0), its friction is mu_c and its dense
// threshold phi_c, so every force and stress must match the NDPM run to round-off. The run must
// also exercise what could differ: plastic flow and open (stress-free) material.
TEST(DpmLimit, ZeroChiEqualsNdpmInAWholeRun) {
  Scene ndpm = bed_scene(0.2, 0.1, 0.03, 0.005, 1.0);
  ndpm.bodies.push_back(plate(0.04, 0.01, 0.1, 0.1, Vec2(0.0, -0.3)));
  ndpm.outputs.fields = {"plastic_strain"};  // the solver tracks plastic strain only when asked
  Scene dpm = ndpm;
  dpm.materials[0] = dpm_material("glass_beads", 2520.0, 0.4, 0.0, 5.0e6);
  dpm.effects.dilatancy = true;
  // the time step bounds the wave speed of a DPM material dense at phi_min (lighter, so faster);
  // an unused copy of that material gives the NDPM scene the same steps, and it stays NDPM
  // (dilatancy off, its bed's material is NDPM)
  ndpm.materials.push_back(dpm_material("unused", 2520.0, 0.4, 0.0, 5.0e6));
  Simulation a(ndpm), b(dpm);
  ASSERT_TRUE(a.particles().phi_d.empty());
  ASSERT_EQ(b.particles().phi_d.size(), b.particles().size());
  double fmax = 0.0, worst_force = 0.0;
  for (int k = 0; k < 600; ++k) {  // 1.6e-2 s: the plate goes 4.7 mm (a cell) into the bed
    a.step();
    b.step();
    ASSERT_EQ(a.last_dt_s(), b.last_dt_s());
    const Vec2 fa = a.bodies()[0].force_N_per_m, fb = b.bodies()[0].force_N_per_m;
    fmax = std::max(fmax, fa.norm());
    worst_force = std::max(worst_force, (fa - fb).norm());
  }
  ASSERT_GT(fmax, 10.0);  // N/m: the plate did push
  EXPECT_LE(worst_force, 1e-12 * fmax);
  const auto &pa = a.particles(), &pb = b.particles();
  ASSERT_EQ(pa.size(), pb.size());
  double pmax = 0.0, worst_stress = 0.0, worst_x = 0.0;
  int plastic = 0, open = 0;
  for (size_t i = 0; i < pa.size(); ++i) {
    pmax = std::max(pmax, double(pa.pressure[i]));
    for (auto m : {&Particles::pressure, &Particles::sxx, &Particles::syy, &Particles::sxy, &Particles::szz})
      worst_stress = std::max(worst_stress, std::abs(double((pa.*m)[i]) - (pb.*m)[i]));
    worst_x = std::max({worst_x, std::abs(pa.x[i] - pb.x[i]), std::abs(pa.y[i] - pb.y[i])});
    plastic += pa.plastic_strain[i] > 0.0;
    open += pa.pressure[i] == 0.0;
    EXPECT_EQ(pb.phi_d[i], 0.60);  // the state never moved
  }
  EXPECT_LE(worst_stress, 1e-12 * pmax);
  EXPECT_LE(worst_x, 1e-12);
  EXPECT_GT(plastic, 50);
  EXPECT_GT(open, 10);
}

// ------------------------------------------------------------------------ case 3: plowing
namespace {

// Paper case 3, cut to what the drag needs (paper: 2.4 x 0.4 m bed, dx 4 mm, 0.03 x 0.08 m plate).
// The resolution is the paper's: the plate's 5 cm depth spans 12.5 cells; at dx 5 mm (10 cells)
// the dense bed's drag is already nearly smooth (relative fluctuation 0.020 vs 0.016 loose,
// measured), because a shear band 2-3 cells wide no longer fits many times into the failure
// wedge ahead of the plate. The bed is 0.6 x 0.1 m: 0.05 m of bed under the plate, and 0.3 m
// ahead of the plate at the end, so the compaction front of the loose bed (it compacts ~5% by
// volume, pushing material far ahead) does not reach the far wall within the window (with a
// 0.5 m bed the loose drag curves up by 30% over the last 0.05 m, measured). The plate moves at
// 0.2 m/s (paper: 0.1): a Froude number v^2/(g depth) of 0.08 keeps inertia small, and it
// halves the steps. chi = 5 as in the caption of the paper's figure 7, which shows the
// fluctuations (its text says 2.5): at phi_i = 0.63 the friction softens from 0.55 to 0.40.
Scene plowing_scene(double phi_i, double dx, double travel_m, double bed_w, double bed_h, double air_m) {
  const double plate_h = 0.08, depth = 0.05;
  Scene s = bed_scene(dpm_material("glass_beads", 2520.0, 0.40, 5.0, 5.0e6), bed_w, bed_h, air_m, dx, 100.0, phi_i);
  s.name = "plowing_test";
  s.solver.contact = ContactMethod::CellFraction;  // as the plowing template (node until 2026-12-02)
  s.solver.end_displacement_m = travel_m;
  s.solver.threads = 1;  // the two beds run side by side, one core each
  s.effects.dilatancy = true;
  Body p = plate(0.03, plate_h, 0.1, bed_h - depth, Vec2(0.2, 0.0));
  s.bodies.push_back(p);
  return s;
}

struct PlowRun {
  std::vector<double> travel_m, drag_N_per_m;
  bool finite = true;
  double travel_end_m = 0.0;
};

PlowRun plow(const Scene& s) {
  Simulation sim(s);
  PlowRun r;
  while (!sim.finished()) {
    sim.step();
    const double drag = -sim.bodies()[0].force_N_per_m.x();
    r.finite &= std::isfinite(drag);
    r.travel_m.push_back(sim.lead_body_travel_m());
    r.drag_N_per_m.push_back(drag);
  }
  r.travel_end_m = sim.lead_body_travel_m();
  return r;
}

}  // namespace

// Below phi_c the bed compacts where it shears, strengthens there and spreads the shearing:
// smooth drag. Above it, shear dilates and softens a band until a new band is cheaper: the drag
// builds and drops (paper figure 7D). Fluctuation = RMS of the drag about a line in travel over
// the window, relative to the mean (engine/analysis.hpp), in one-cell travel bins that remove
// the plate's cell-crossing noise. Measured here: 0.066 at 0.63 vs 0.010 at 0.57.
TEST(DpmPlowing, DenseBedFluctuatesAtLeastTwiceAsMuchAndDragsHarder) {
  const double dx = 0.004, travel = 0.2;
  PlowRun loose, dense;
  std::thread t([&] { loose = plow(plowing_scene(0.57, dx, travel, 0.6, 0.1, 0.08)); });
  dense = plow(plowing_scene(0.63, dx, travel, 0.6, 0.1, 0.08));
  t.join();
  ASSERT_TRUE(loose.finite && dense.finite);
  ASSERT_GE(loose.travel_end_m, travel);
  ASSERT_GE(dense.travel_end_m, travel);
  // window: after the first plate depth of travel (the heap ahead forms) to the end
  DragStatsOptions o;
  o.from_m = 0.05;
  o.to_m = travel;
  o.bin_m = dx;
  const DragStats a = drag_statistics(loose.travel_m, loose.drag_N_per_m, o);
  const DragStats b = drag_statistics(dense.travel_m, dense.drag_N_per_m, o);
  RecordProperty("loose_mean_N_per_m", std::to_string(a.mean_N_per_m));
  RecordProperty("dense_mean_N_per_m", std::to_string(b.mean_N_per_m));
  RecordProperty("loose_relative_fluctuation", std::to_string(a.relative_fluctuation));
  RecordProperty("dense_relative_fluctuation", std::to_string(b.relative_fluctuation));
  std::printf("case 3: relative fluctuation %.3f at phi 0.63 vs %.3f at 0.57 (%.1fx); mean drag %.1f vs %.1f N/m\n",
              b.relative_fluctuation, a.relative_fluctuation, b.relative_fluctuation / a.relative_fluctuation,
              b.mean_N_per_m, a.mean_N_per_m);
  EXPECT_GE(b.relative_fluctuation, 2.0 * a.relative_fluctuation)
      << "loose " << a.relative_fluctuation << ", dense " << b.relative_fluctuation;
  // the dense bed is stronger (friction 0.55 before it softens, vs at most 0.40 for the loose bed
  // once compacted): its mean drag is higher by more than both beds' fluctuations put together
  EXPECT_GT(b.mean_N_per_m - a.mean_N_per_m, 3.0 * (a.rms_N_per_m + b.rms_N_per_m))
      << "loose " << a.mean_N_per_m << " +- " << a.rms_N_per_m << ", dense " << b.mean_N_per_m << " +- "
      << b.rms_N_per_m;
  // scale: passive earth pressure on the plate, F ~ Kp rho_d g depth^2 / 2 with Kp of a few,
  // raised by the growing heap ahead (measured 7 and 10 times rho_d g depth^2 / 2)
  const double rho_g_d2 = 2520 * 0.6 * 9.81 * 0.05 * 0.05 / 2;
  EXPECT_GT(a.mean_N_per_m / rho_g_d2, 2.0);
  EXPECT_LT(b.mean_N_per_m / rho_g_d2, 20.0);
}

// An over-compacted bed beyond the paper's range (phi_i 0.66: friction 0.70 softening to 0.40,
// the strongest dilation) plowed 0.3 m at dx 8 mm, until the heap is pressed against the far
// wall (0.085 m ahead of the plate at the end) and rises along it: nothing blows up, nothing leaves
// the domain, and dense material stays between phi_min (it cannot be dense below its
// phi_d >= phi_min) and 0.75 (beyond any granular packing; the elastic law would need
// P = K ln(0.75 / 0.66) ~ 0.5 MPa, some 50 times the plate's mean pressure).
TEST(DpmPlowing, OverCompactedBedStaysFiniteInsideAndPhysical) {
  const double dx = 0.008, travel = 0.3, bed_w = 0.5, bed_h = 0.1;
  // 0.2 m of air: the heap squeezed against the wall rises above the 0.08 m plate
  const Scene s = plowing_scene(0.66, dx, travel, bed_w, bed_h, 0.2);
  Simulation sim(s);
  const double W = s.domain.width_m, H = s.domain.height_m;
  bool forces_finite = true;
  int64_t bad_state = 0, outside = 0;
  double phi_lo = 1.0, phi_hi = 0.0, phi_d_lo = 1.0, phi_d_hi = 0.0;
  auto check = [&] {
    const auto& p = sim.particles();
    for (size_t i = 0; i < p.size(); ++i) {
      const double phi = p.mass[i] / (2520.0 * p.volume[i]);
      bad_state += !(std::isfinite(p.x[i]) && std::isfinite(p.y[i]) && std::isfinite(p.vx[i]) && std::isfinite(p.vy[i]) &&
                     std::isfinite(p.pressure[i]) && std::isfinite(p.sxy[i]) && std::isfinite(phi));
      // walls act on grid nodes on and beyond their line, so material pressed against a wall
      // may sit up to about half a cell past it (0.4 dx measured); leaving means going further
      outside += !(p.x[i] >= -0.5 * dx && p.x[i] <= W + 0.5 * dx && p.y[i] >= -0.5 * dx && p.y[i] <= H);
      phi_d_lo = std::min(phi_d_lo, p.phi_d[i]);
      phi_d_hi = std::max(phi_d_hi, p.phi_d[i]);
      if (p.pressure[i] > 0.0) {
        phi_lo = std::min(phi_lo, phi);
        phi_hi = std::max(phi_hi, phi);
      }
    }
  };
  while (!sim.finished()) {
    sim.step();
    forces_finite &= sim.bodies()[0].force_N_per_m.allFinite();
    if (sim.step_count() % 1000 == 0) check();
  }
  check();
  EXPECT_TRUE(forces_finite);
  EXPECT_GE(sim.lead_body_travel_m(), travel);  // ended by travel, not by max_steps
  EXPECT_EQ(bad_state, 0);
  EXPECT_EQ(outside, 0);
  EXPECT_GE(phi_lo, 0.45);
  EXPECT_LE(phi_hi, 0.75);
  // the state only relaxes toward phi_c (or resets to phi_min when torn open)
  EXPECT_GE(phi_d_lo, 0.45);
  EXPECT_LE(phi_d_hi, 0.66 + 1e-12);
  RecordProperty("dense_phi_min", std::to_string(phi_lo));
  RecordProperty("dense_phi_max", std::to_string(phi_hi));
}

// ------------------------------------------------------------------------ case 4: loose intrusion

// Paper case 4: a 0.04 x 0.02 m plate pushed down at 0.15 m/s into loose poppy seeds (phi_i 0.55,
// so friction 0.53 + (0.55 - 0.60) 5 = 0.28 until sheared, mu_c 0.53). The zone moving with the
// plate starts short and blunt (slip-line apex pi/2 - atan 0.28 = 74 deg, plus the trapezoid's
// truncation) and sharpens, as its flanks compact and strengthen, toward pi/2 - atan(mu_c) =
// 62 deg (engine/analysis.hpp: why the full apex angle).
//
// Resolution: dx 2 mm puts 20 cells across the plate (paper: 80). Measured with `node` at tolerance 0.1,
// late medians: 61-64 deg at dx 2.5 and 2 mm; 67 deg at dx 3.3 mm, where the flanks' shear
// bands (2-3 cells) are a fifth of the plate wide. `cell_fraction` spreads the plate's edge over
// a cell's share, so it needs the finer of the two: at dx 2.5 mm 67.9 deg, and 70.8 after a
// round-off change (the pressure's log series, 2026-12-03), too near the 8 deg bound to test the
// claim; at dx 2 mm 64.8 and 65.1 deg. Bed 0.25 x 0.16 m (paper 0.5 x 0.2): the
// Prandtl mechanism of a 40 mm plate reaches about 2.5 plate widths across and the final zone's
// apex sits 85 mm above the floor; a 0.3 x 0.2 m bed gives a late median within 3 deg of this
// one (measured 60.9 vs 63.7).
//
// Frames: one per third of a cell of travel, taken when the face is 0.45, 0.65 and 0.85 cell
// above the grid node line below it. With `node` contact the body constrains only grid nodes inside
// it, so as the face descends through a cell the layer under it is pushed less and less and the zone
// could vanish from a frame; `cell_fraction` (the template's since 2026-12-03) takes a share that
// moves smoothly with the face instead, and the offsets are kept so both methods are sampled alike. Single frames scatter
// by ~8 deg (particle noise on 16-20 cells), so the claim is tested on medians: early = the first
// 12.5 mm of intrusion (0.3 L), late = 30-50 mm.
//
// Growth: a complete slip-line wedge under a plate of width L is (L/2) / tan(apex/2) tall, 26.3 mm
// at the initial friction (apex 74.4 deg) and 33.2 mm at mu_c (62.1 deg). The paper's early zone is
// at most that short wedge, so it is at most tan(31.0 deg) / tan(37.2 deg) = 0.79 of the late one
// (both shortened alike by the 10% speed criterion); a zone that did not grow gives 1. Until
// 2026-12-03 the bound was 0.6, set from `node`'s 0.54 with no physics behind it; `cell_fraction`
// measured 0.606 and 0.661 at dx 2.5 mm, 0.550 and 0.546 at 2 mm (engine/README.md, "Body contact").
TEST(DpmLooseIntrusion, RigidWedgeSharpensToTheSlipLineAngle) {
  const double dx = 0.002, bed_w = 0.25, bed_h = 0.16, gap = 0.002, v = 0.15, travel = 0.05;
  Scene s = bed_scene(dpm_material("poppy_seeds", 1100.0, 0.53, 5.0, 2.0e6), bed_w, bed_h, 0.03, dx, 10.0, 0.55);
  s.name = "loose_intrusion_test";
  s.solver.contact = ContactMethod::CellFraction;  // as the loose_intrusion template (node until 2026-12-03)
  s.solver.end_displacement_m = gap + travel;
  s.effects.dilatancy = true;
  s.bodies.push_back(plate(0.04, 0.02, 0.5 * bed_w, bed_h + gap, Vec2(0.0, -v)));
  Simulation sim(s);
  RasterSpec raster;
  raster.nx = sim.grid().nx;
  raster.ny = sim.grid().ny;
  raster.dx_m = dx;
  std::vector<double> early_deg, late_deg, early_h, late_h;
  int late_frames = 0;
  double prev_offset = 2.0;
  while (!sim.finished()) {
    sim.step();
    const double face = sim.bodies()[0].position_m.y() - 0.01;
    const double offset = face / dx - std::floor(face / dx);
    bool take = false;
    for (double target : {0.45, 0.65, 0.85}) take |= prev_offset > target && offset <= target;
    prev_offset = offset;
    const double depth = bed_h - face;
    const bool early = depth >= 0.005 && depth <= 0.0125, late = depth >= 0.03 && depth <= 0.05;
    if (!take || !(early || late)) continue;
    FieldFrame f = rasterize(sim.particle_view(), raster, {"velocity"});
    const auto outlines = sim.body_outlines();
    const WedgeMeasure m = measure_wedge(f, outlines[0], sim.bodies()[0].velocity_m_s);
    (early ? early_deg : late_deg).push_back(m.apex_angle_deg);
    if (m.found) (early ? early_h : late_h).push_back(m.height_m);
    late_frames += late;
  }
  const double early_apex = median_finite(early_deg), late_apex = median_finite(late_deg);
  const double slip_line = slip_line_apex_angle_deg(0.53);
  std::printf("case 4: apex early %.1f deg, late %.1f deg (slip line %.1f deg at mu_c)\n", early_apex, late_apex,
              slip_line);
  RecordProperty("early_apex_deg", std::to_string(early_apex));
  RecordProperty("late_apex_deg", std::to_string(late_apex));
  ASSERT_GE(early_deg.size(), 6u);
  ASSERT_EQ(late_frames, 30);  // 20 mm = 10 cells, 3 frames each
  // the zone exists and has flanks in nearly every late frame
  EXPECT_GE(std::count_if(late_deg.begin(), late_deg.end(), [](double a) { return std::isfinite(a); }), 27);
  // it sharpens to the slip-line angle at mu_c: from the initial friction's (74.4 deg) to within a
  // third of the way of mu_c's (62.1 +- 4.1 deg); a zone stuck at 74.4 deg or gone halfway fails
  // (PaperClaimMeasures.WedgeApproachRejectsAZoneThatDidNotSharpen; the bound until 2026-12-05,
  // 62.1 +- 8 deg, accepted 70 deg)
  const MaterialParams bed = MaterialParams::from(s.materials[0], true);
  const double initial_slip_line = slip_line_apex_angle_deg(bed.friction(s.beds[0].packing_fraction));
  EXPECT_TRUE(approaches(late_apex, slip_line, initial_slip_line))
      << "early " << early_apex << ", late " << late_apex << ", slip line " << slip_line << " from " << initial_slip_line;
  EXPECT_GE(early_apex, late_apex + 5.0) << "early " << early_apex << ", late " << late_apex;
  // it grows: early no taller than the slip-line wedge at the initial friction, scaled to the late one
  const double early_height = median_finite(early_h), late_height = median_finite(late_h);
  const auto half_tan = [](double mu) { return std::tan(0.5 * slip_line_apex_angle_deg(mu) * M_PI / 180.0); };
  const double full_wedge_ratio = half_tan(bed.mu) / half_tan(bed.friction(s.beds[0].packing_fraction));  // 0.79
  RecordProperty("early_over_late_height", std::to_string(early_height / late_height));
  std::printf("case 4: early height %.1f mm, late %.1f mm (%.3f; bound %.2f)\n", 1e3 * early_height, 1e3 * late_height,
              early_height / late_height, full_wedge_ratio);
  EXPECT_LT(early_height, full_wedge_ratio * late_height) << "early " << early_height << ", late " << late_height;
}
