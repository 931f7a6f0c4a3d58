// The paper's claims for cases 1 and 2 (sections 3.1-3.2), at the coarsest resolution that still
// shows them. Every choice that trades accuracy for time is stated where it is made, with what was
// measured when it was chosen; tolerances come from the claims, not from one run.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "engine/scene/scene_io.hpp"
#include "tests/engine/paper_cases_helpers.hpp"

namespace furrow::paper {
namespace {

// ---- case 1: cylinder dragged sideways at depth ----------------------------------------------
// Paper: D = 4 mm, dx = 0.5 mm (8 cells per D), 0.20 x 0.16 m bed, mu_s 0.48, mu_f 0.35.
// Here dx = D/6 with cell-fraction contact, as the cylinder_drag template ships (since 2026-12-03;
// node contact at D/4 until then). Node contact's force steps each time the circle's front crosses
// a node line (largest step 2.3x the one-cell mean, RMS 18%, at 6 cells per D and 15 D; cell
// fraction 1.13x, 2.6%), and its 10 -> 15 D lift change moved from 0.09 to 0.47 to 0.28 of the
// drag's at 4, 6, 8 cells per D. Cell fraction reads 0.78, 0.30, 0.35: at 4 cells its 10 D lift is
// 23% low, so 6 is the coarsest at which it shows the lift levelling off (engine/README.md, "Body contact").
//
// Transfer: 10% APIC in the velocity update (flip_blend 0.9). With the default 0.99 the drag
// saturates beyond |z| ~ 10 D at 4 and 8 cells per D alike (node contact: dx 1 mm 13 -> 12.5 N/m
// from 10 D to 15 D; dx 0.5 mm 15.2 -> 15.5 N/m), because the particle-level volume noise of nearly
// pure FLIP opens ("separates") much of the sheared material around the cylinder. With 0.9 the deep
// drag is the same at dx 1 mm and 0.5 mm (17.4 / 18.9 N/m at 10 D, E 5 MPa) and the shallow drag
// matches the default's within 4%. Pure APIC (0) adds a numerical viscosity that doubles the deep drag.
//
// Stiffness: E = 50 MPa, ten times the other cases'. The paper gives no modulus for the media;
// the model is meant to be rigid-plastic, so E must be stiff enough not to matter, and for this
// case 5 MPa is not. Drag/F0 at 2.5, 5, 10, 15 D (node contact, 4 cells per D, 3-8 mm of travel):
// E 5 MPa 18.7, 44.3, 91.4, 129; 50 MPa 21.2, 47.4, 105, 201; 100 MPa 22.4, 48.4, 109, 209. Lift/F0
// at 10 -> 15 D: 5 MPa levels off in these beds but not in the paper's (+42% there, with a ~1.5 mm
// tunnel behind the cylinder filled from above and material sliding up its front face); 50 MPa
// 18.9 -> 21.6 (+14%); 100 MPa 20.0 -> 24.8 (+24%). A soft bed or a slow drag let a falling,
// stress-free column form above the wake (0.09 m bed, 10 -> 15 D: E 1 MPa drag 13.7 -> 15.2 N/m;
// E 5 MPa at 0.03 m/s 14.4 -> 16.2 N/m), which caps the drag. Cost: steps grow as sqrt(E).
constexpr double kD = 0.004, kCylE = 5.0e7;
const double kCylF0 = kPi * 0.25 * kD * kD * kRhoD * kG;  // pi (D/2)^2 rho_d g w

// The cylinder starts `behind` from the left wall with `below` of bed under its centre and
// `ahead` of bed beyond the end of its drag.
Scene cylinder_scene(double dx_m, ContactMethod contact, double depth_m, double behind_m, double below_m,
                     double ahead_m, double travel_m) {
  Scene s = bed(behind_m + travel_m + ahead_m, depth_m + below_m, 0.01, dx_m, 0.48);
  s.solver.contact = contact;
  s.materials[0].youngs_modulus_Pa = kCylE;
  s.solver.flip_blend = 0.9;
  s.solver.end_displacement_m = travel_m;
  s.bodies.push_back(circle_body("cylinder", kD, Vec2(behind_m, below_m), Vec2(0.1, 0.0)));
  return s;
}

// The lift claim over depths zD (3 or more, increasing): the lift levels off, its growth per D
// over the deepest interval under half its steepest growth per D before (levelling_ratio). A lift
// growing linearly reads 1, one growing with the steepening drag above 1, and one growing +38% from
// 10 to 15 D while the drag grows +78% reads 0.52 (PaperClaimMeasures.LevellingOffRejectsALift-
// GrowingWithTheDrag). Until 2026-12-05 the claim was the lift's relative change under half the
// drag's between the two deepest depths, which that +38% passed (0.49); it is still printed.
void expect_lift_levels_off(const std::vector<double>& zD, const std::vector<double>& drag,
                            const std::vector<double>& lift) {
  const size_t a = zD.size() - 2, b = a + 1;
  const double drag_change = drag[b] / drag[a] - 1, lift_change = lift[b] / lift[a] - 1;
  const double ratio = levelling_ratio(zD, lift);
  std::printf("case 1: %g D -> %g D: drag %+.1f%%, lift %+.1f%% (%.2f of the drag's); the lift's growth per D there "
              "over its steepest before: %.3f\n",
              zD[a], zD[b], 100 * drag_change, 100 * lift_change, lift_change / drag_change, ratio);
  EXPECT_GT(drag_change, 0.0);
  EXPECT_GT(lift[a], 0.0);
  EXPECT_LT(ratio, 0.5);
}

// Beds: for each depth z the smallest that does not change the drag much: 30 mm (7.5 D) of bed
// under the centre (90 mm: the same drag at 15 D within 2%), 30 mm behind the start and
// 1.5 z + 10 mm ahead of the end of the drag (node contact, 4 cells per D, E 5 MPa: at 15 D
// 25.3 N/m against 26.2 N/m in the paper's 0.2 m bed; 42 mm ahead gave 20 N/m). Over a 20 mm drag
// these beds give the paper bed's 10 -> 15 D changes within a point (node +83% / +7.6% against
// +83% / +8%; cell fraction +66% / +51.5% against +65.8% / +48.5%, 4 cells per D).
// The drag: 12 mm; the mean over 5-12 mm. The deep runs start high and collapse between 2 and 4 mm
// of travel (15 D, 8 cells: 250, 168, 231, 240 F0 in 2 mm bins), so the mean starts after that;
// over a 20 mm drag at 6 cells, 5-12 mm reads 0.30 of the drag's change, as 5-20 mm does (5 mm
// windows: 0.11 to 0.45). Measured when chosen: drag/F0 25.95, 54.49, 138.2, 245.6 at 2.5, 5, 10,
// 15 D, R^2 0.989; lift/F0 7.10, 9.93, 37.6, 47.1 (10 -> 15 D: +25.4% for drag +77.7%, 0.33);
// 8 min on 2 cores (the 15 D run 468 s on one; at 4 cells with node contact it was 189 s).
// Since 2026-12-07 the beds are 30% smaller for CI's budget: 20 mm under the centre and z + 10 mm
// ahead. At 15 D drag/F0 244.60 -> 244.72, lift/F0 47.59 -> 48.07 (115k -> 81k points, 558 -> 386 s
// on one core); at 10 D 138.87 -> 139.34, 36.71 -> 36.72; the levelling ratio 0.399 -> 0.418, the
// slope ratio 1.837 -> 1.838. Cutting further (z * 0.75 + 10 mm ahead, 15 mm under, 20 mm behind)
// moved the 15 D drag and lift by -1.9% and -2.0%.
TEST(PaperCase1, CylinderDragGrowsLinearlyWhileLiftLevelsOff) {
  const double dx = kD / 6, travel = 0.012, from = 0.005;
  const std::vector<double> depths_m = {0.010, 0.020, 0.040, 0.060};  // 2.5, 5, 10, 15 D
  std::vector<Scene> scenes;
  for (double z : depths_m)
    scenes.push_back(cylinder_scene(dx, ContactMethod::CellFraction, z, 0.03, 0.02, z + 0.01, travel));
  const std::vector<Trace> traces = run_all(scenes);

  std::vector<double> zD, drag, lift;
  for (size_t i = 0; i < depths_m.size(); ++i) {
    zD.push_back(depths_m[i] / kD);
    drag.push_back(-window_mean(traces[i], 0, 0, from, travel) / kCylF0);
    lift.push_back(window_mean(traces[i], 0, 1, from, travel) / kCylF0);
    std::printf("case 1: |z|/D %5.2f  drag/F0 %7.2f  lift/F0 %6.2f  (F0 %.4f N/m; %zu particles, %lld steps, %.1f s)\n",
                zD.back(), drag.back(), lift.back(), kCylF0, traces[i].particles, (long long)traces[i].steps,
                traces[i].wall_s);
  }
  const Fit f = fit_line(zD, drag);
  const double curvature = secant_slope_ratio(zD, drag);
  std::printf("case 1: drag/F0 = %.3f + %.3f |z|/D, R^2 %.4f; log-log exponent %.3f; deepest over shallowest slope %.3f "
              "(linear 1; z^0.85 %.3f, z^1.15 %.3f; sqrt(z) %.3f, z^1.5 %.3f)\n",
              f.intercept, f.slope, f.r2, fit_power_law(zD, drag).slope, curvature, power_law_slope_ratio(zD, 0.85),
              power_law_slope_ratio(zD, 1.15), power_law_slope_ratio(zD, 0.5), power_law_slope_ratio(zD, 1.5));
  // resisting and growing with depth. Linear in it, the paper's claim, does not hold here: as straight
  // as z^(1 +- 0.15) on these depths (deepest over shallowest slope 0.83..1.20), which sqrt(z) and
  // z^1.5 are not (PaperClaimMeasures.LinearInDepthRejectsSqrtAndThreeHalvesPowers), the drag
  // steepens as z^1.5 does: 1.845 (2026-12-05: drag/F0 26.10 / 54.88 / 138.92 / 245.11; z^1.5 1.831),
  // where R^2 0.990 of a straight line, the check until then, could not tell (z^1.5 reads 0.990;
  // the lift's levelling ratio 0.400: 6.82 / 9.44 / 36.81 / 47.77 F0). So it is measured and
  // printed, not asserted, until the solver's drag is linear (README, claims table).
  for (size_t i = 0; i < drag.size(); ++i) EXPECT_GT(drag[i], 0.0) << "|z|/D " << zD[i];
  for (size_t i = 1; i < drag.size(); ++i) EXPECT_GT(drag[i], drag[i - 1]) << "|z|/D " << zD[i];
  std::printf("case 1: drag linear in depth (z^(1 +- 0.15)): %s\n", linear_in_depth(zD, drag, 0.15) ? "yes" : "no");
  // the lift levels off: its growth per D from 10 to 15 D under half its steepest before
  expect_lift_levels_off(zD, drag, lift);
}

// The same lift claim in the paper's whole 0.20 x 0.16 m bed, cylinder from x = 0.05 m, dragged
// 20 mm, mean over 5..20 mm, at the test's 6 cells per D (`furrow sweep scenes/cylinder_drag.json
// --set domain.dx_m=0.000667 --vary bodies.cylinder.start_m.1=0.12,0.10 --set
// solver.end_displacement_m=0.02 --set outputs.average_window.from_m=0.005 --set
// outputs.average_window.to_m=0.02`). Measured: 10 D -> 15 D drag 25.92 -> 46.11 N/m (+77.9%), lift
// 7.16 -> 9.14 N/m (+27.6%, 0.35 of the drag's): 139 / 247 F0 and 38.4 / 49.0 F0, the compact beds'
// 20 mm numbers within 3% (139.2 / 246.1, 38.9 / 48.0). 28 min on 2 cores, so it runs only with
// FURROW_LONG_PAPER_TESTS=1. Node contact at 4 cells per D gave +83% / +8% here, cell fraction at 4
// +65.8% / +48.5% (its 10 D lift is low at that dx, above). Since 2026-12-05 a 5 D run gives the
// lift's growth before it levels off (expect_lift_levels_off): three runs of ~28 min each on one core,
// so about an hour (estimated; not yet run with it).
TEST(PaperCase1, CylinderLiftLevelsOffInPaperBed) {
  if (!std::getenv("FURROW_LONG_PAPER_TESTS"))
    GTEST_SKIP() << "the paper-bed check takes about an hour on 2 cores (measured: 10 D -> 15 D drag +77.9%, lift "
                    "+27.6%); set FURROW_LONG_PAPER_TESTS=1 to run it (ctest -L paper_long)";
  const double travel = 0.02, from = 0.005;
  const std::vector<double> depths_m = {0.020, 0.040, 0.060};  // 5, 10, 15 D
  std::vector<Scene> scenes;
  for (double z : depths_m)
    scenes.push_back(cylinder_scene(kD / 6, ContactMethod::CellFraction, z, 0.05, 0.16 - z, 0.2 - 0.05 - travel, travel));
  const std::vector<Trace> traces = run_all(scenes);
  std::vector<double> zD, drag, lift;
  for (size_t i = 0; i < depths_m.size(); ++i) {
    zD.push_back(depths_m[i] / kD);
    drag.push_back(-window_mean(traces[i], 0, 0, from, travel));
    lift.push_back(window_mean(traces[i], 0, 1, from, travel));
    std::printf("case 1 lift: |z|/D %5.2f  drag %.2f N/m  lift %.2f N/m (%.1f s)\n", depths_m[i] / kD, drag[i], lift[i],
                traces[i].wall_s);
  }
  expect_lift_levels_off(zD, drag, lift);
}

// ---- case 2: plates pushed down into the bed --------------------------------------------------
// Paper: plates L = 0.05..0.25 m in a 1.2 x 0.6 m bed at dx 1.25 mm (40..200 cells per plate),
// mu_s 0.40, mu_f 0.35, 0.1 m/s. NDPM has no length scale but L, so the claims are about L/dx-free
// shapes; the tests use 8..30 cells per plate, beds sized to each run, and two speed-ups:
//  * 0.2 m/s instead of 0.1: the inertial stress rho v^2 = 60 Pa stays under 1% of the bearing
//    stress in the deep windows and ~5% at the surface (measured: +5..9% shallow, +2..7% deep for a
//    0.06 m plate at dx 5 mm), the same fraction for every width, so exponents and ratios keep;
//  * E = 1.25 MPa instead of 5 MPa: halves the wave speed and doubles the time step; the volumetric
//    strain under a plate stays near 1% (P ~ 10 kPa, K ~ 1 MPa). Deep forces and pair ratios are
//    the same at 20 MPa (measured below); the onset force is not, so it runs at 5 MPa.
constexpr double kPlateV = 0.2, kPlateE = 1.25e6;

// A bed of `width` x `depth` with plates of width L (thickness 2 dx) whose bottoms start half a cell
// above the surface at the given centres, all moving down together. Cell-fraction contact, as the
// plate_intrusion and two_plates templates use (node contact until 2026-12-02; engine/README.md, "Which template uses which").
Scene plates_scene(double width_m, double depth_m, double dx_m, double L_m, const std::vector<double>& centres_m,
                   double travel_m, double E_Pa = kPlateE) {
  Scene s = bed(width_m, depth_m, 4.0 * dx_m, dx_m, 0.40);
  s.solver.contact = ContactMethod::CellFraction;
  s.materials[0].youngs_modulus_Pa = E_Pa;
  const double gap = 0.5 * dx_m, t = 2.0 * dx_m;
  s.solver.end_displacement_m = gap + travel_m;
  const char* names[] = {"plate_left", "plate_right"};
  for (size_t i = 0; i < centres_m.size(); ++i)
    s.bodies.push_back(box_body(names[i % 2], L_m, t, Vec2(centres_m[i], depth_m + gap + 0.5 * t), Vec2(0.0, -kPlateV)));
  return s;
}

// Total drag (upward force) of all plates against plate-bottom depth z = travel - gap.
struct DepthTrace {
  std::vector<double> z_m, F_N_per_m;
};
DepthTrace depth_trace(const Trace& t, double gap_m) {
  DepthTrace d;
  for (size_t k = 0; k < t.travel_m.size(); ++k) {
    double F = 0.0;
    for (const auto& body : t.force_N_per_m) F += body[k].y();
    d.z_m.push_back(t.travel_m[k] - gap_m);
    d.F_N_per_m.push_back(F);
  }
  return d;
}
double depth_mean(const DepthTrace& d, double from_m, double to_m) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t k = 0; k < d.z_m.size(); ++k)
    if (d.z_m[k] >= from_m && d.z_m[k] <= to_m) sum += d.F_N_per_m[k], ++n;
  return n ? sum / double(n) : std::nan("");
}

// Single plates. Near the surface the model has no length but L, so F(z) = rho_d g L^2 f(z / L)
// (the paper's eq. 8), and the initial peak, "the force requirement for initiating media flow",
// sits at a fixed z / L: its force ~ L^2. The solver gives no drop after that initiation at any
// resolution tried (L/dx 8..40, with and without a velocity ramp): once smoothed over a cell the
// trace rises monotonically. What is left of the claim is a finite force that starts the flow and
// scales as L^2: the bearing-capacity line F = rho_d g L (N_q z + N_gamma L / 2), a ~ L^2 at
// z -> 0 and b ~ L in z. Since 2026-12-05 it is tested as that: F = a + b z fitted per width over
// one window of absolute depth, and the exponents of a and b against L (onset_scaling). Until then
// the onset was the mean force over z in [L/8, L/2], a window that scales with L: any F = rho_d g
// L^2 f(z / L), F = c z L included (no onset force at all), gives exponent 2 there, so it could not
// tell the claim from its absence (PaperClaimMeasures.OnsetScalingRejectsATraceWithoutAnOnsetForce).
// The deep force is the mean over z in [0.10, 0.14] m, 1.8..2.5 L_max deep, where the L^2 term
// falls under ~10% of the force.
//
// History: a window in z / L replaced the line's z -> 0 intercept on 2026-12-02, because the intercept
// extrapolates a trace that fluctuates by 10-20% (the node comb, the ringing), and its exponent
// moved with everything but the physics. Measured (L = 0.04 / 0.06 / 0.08 m, E 5 MPa, intercept
// over z in [dx, L/2] -> mean over [L/8, L/2]): dx 2.5 mm `node` 1.871 -> 1.964, `cell_fraction`
// 1.648 -> 1.893; dx 1.25 mm `node` 1.658 -> 2.146, `cell_fraction` 1.718 -> 2.105; dx 2.5 mm with a
// 0.05 s ramp to full speed `node` 1.643 -> 1.977, `cell_fraction` 1.585 -> 1.869; intercepts over
// [L/8, L/2], [L/4, L] or [L/16, L] gave anything from 1.45 to 2.39. The passing 1.87 of `node` at dx 2.5 mm
// was its under-resolution of the narrow plate: at dx 1.25 mm the narrow plate's intercept rose
// from 79 to 95 N/m and the exponent fell to 1.66.
//
// The onset needs what the deep force does not (measured with the intercept, L = 0.04 / 0.06 /
// 0.08 m): a stiff enough bed: at dx 5 mm 69 / 136 / 239 N/m at E 1.25 MPa, 105 / 197 / 313 at 5 MPa,
// 107 / 199 / 337 at 20 MPa: the soft bed's compliance delays the small plates' loading most. So
// the onset runs at dx 2.5 mm (16..32 cells) and E 5 MPa, in the same beds but only to z = L/2; the
// deep force keeps dx 5 mm and E 1.25 MPa, where its exponent is the same as at 5 and 20 MPa
// (0.91, 0.91, 0.89).
TEST(PaperCase2, SinglePlateOnsetForceScalesAsL2AndDeepForceAsL) {
  const double dx = 0.005, z_from = 0.10, z_to = 0.14;
  const double onset_dx = 0.0025, onset_E = 5.0e6;
  const std::vector<double> widths_m = {0.04, 0.06, 0.08};  // 8, 12, 16 cells (16, 24, 32 for the onset)
  const double Lmax = widths_m.back(), W = 6.0 * Lmax;       // 3 L_max of bed each side of the plate
  std::vector<Scene> scenes;
  const double H = z_to + Lmax;  // L_max of bed under the deep window (the onset: a 2 L_max bed gave 1.75)
  for (double L : widths_m) scenes.push_back(plates_scene(W, H, onset_dx, L, {0.5 * W}, 0.5 * L, onset_E));
  for (double L : widths_m) scenes.push_back(plates_scene(W, H, dx, L, {0.5 * W}, z_to));
  const std::vector<Trace> traces = run_all(scenes);
  const size_t n = widths_m.size();
  // the onset: F = a + b z per width over one window of absolute depth (PaperClaimMeasures.
  // OnsetScalingRejectsATraceWithoutAnOnsetForce: F = c z L fails it), from two cells down (the
  // contact engages over a cell; the impact's ringing, a period of ~L / c = 1.4 ms at L_max, is
  // gone after 0.3 mm) to L_min / 2, where the narrowest plate's run ends
  const double window_from = 2.0 * onset_dx, window_to = 0.5 * widths_m.front();
  std::vector<std::vector<double>> z_m(n), F_N_per_m(n);
  std::vector<double> onset_mean, deep;
  for (size_t i = 0; i < n; ++i) {
    const double L = widths_m[i];
    const DepthTrace d = depth_trace(traces[i], 0.5 * onset_dx);
    z_m[i] = d.z_m;
    F_N_per_m[i] = d.F_N_per_m;
    onset_mean.push_back(depth_mean(d, 0.125 * L, 0.5 * L));  // the measure until 2026-12-05, for the log
    deep.push_back(depth_mean(depth_trace(traces[n + i], 0.5 * dx), z_from, z_to));
  }
  const OnsetScaling onset = onset_scaling(widths_m, z_m, F_N_per_m, window_from, window_to);
  for (size_t i = 0; i < n; ++i) {
    const double L = widths_m[i];
    std::printf("case 2 single: L %.3f m  onset (F = a + b z over z %.1f-%.1f mm) a %.1f N/m (N_gamma = 2 a/(rho_d g L^2 w) "
                "%.2f), b %.0f N/m^2 (N_q %.2f); mean over z/L 1/8..1/2 %.1f N/m  deep mean %.1f N/m "
                "(F/(rho_d g z L w) %.2f)  (%zu + %zu particles, %.1f + %.1f s)\n",
                L, 1e3 * window_from, 1e3 * window_to, onset.onset_N_per_m[i],
                onset.onset_N_per_m[i] / (0.5 * kRhoD * kG * L * L), onset.slope_N_per_m2[i],
                onset.slope_N_per_m2[i] / (kRhoD * kG * L), onset_mean[i], deep[i],
                deep[i] / (kRhoD * kG * 0.5 * (z_from + z_to) * L), traces[i].particles, traces[n + i].particles,
                traces[i].wall_s, traces[n + i].wall_s);
  }
  for (double from : {0.0075, 0.01}) {  // how the exponents move with the window's start (for the log)
    const OnsetScaling o = onset_scaling(widths_m, z_m, F_N_per_m, from, window_to);
    std::printf("case 2 single: window from %.1f mm: a exponent %.3f, b exponent %.3f\n", 1e3 * from, o.onset_exponent,
                o.slope_exponent);
  }
  const Fit f_mean = fit_power_law(widths_m, onset_mean), f_deep = fit_power_law(widths_m, deep);
  std::printf("case 2 single: exponents: onset force a %.3f, its growth b %.3f (mean over z/L 1/8..1/2: %.3f), deep %.3f "
              "(R^2 %.4f)\n",
              onset.onset_exponent, onset.slope_exponent, f_mean.slope, f_deep.slope, f_deep.r2);
  // A finite onset force ~ L^2 (measured 2026-12-05: a 98.3 / 218.4 / 407.7 N/m, exponent 2.047).
  // Its growth b ~ L does not hold (7574 / 10388 / 10438 N/m^2, exponent 0.48), and both move with
  // the window's start (from 7.5 mm: 1.23 and 1.60; from 10 mm: 1.90 and 0.55): the shallow traces
  // are not straight over 5-20 mm, so b is printed, not asserted, and the claims table says
  // "partly holds".
  for (size_t i = 0; i < n; ++i) EXPECT_GT(onset.onset_N_per_m[i], 0.0) << "L " << widths_m[i];
  EXPECT_NEAR(onset.onset_exponent, 2.0, 0.3);
  EXPECT_NEAR(f_deep.slope, 1.0, 0.15);
}

// Pairs of equal plates at inner-edge gap s: per-plate drag over rho_d g z L w, averaged over
// plate-bottom depths z in [0.07, 0.09] m, 2..3.6 plate widths deep (the F ~ z L regime the paper's
// scaling assumes; its own window, 0.4..0.8 L, is where a 2 L plate still carries a large L^2 share).
// s = 0 is one plate of width 2 L, s -> infinity one plate of width L (per plate: its own force).
// dx 2.5 mm: 10 and 15 cells per plate; gaps of 3 cells and more (s/L >= 0.3 at 10 cells): node
// contact reaches ~1.5 cells beyond each plate, so a narrower gap was numerically closed (kept
// with cell_fraction, which holds material only once it touches).
// Each bed: the plate system's span, 1.5 spans of bed on each side and one span under the window
// (a floor 0.7 spans under the plates raised the force of a 2 L plate).
constexpr double kPairDx = 0.0025;
struct DepthWindow {
  double from_m, to_m;
};
constexpr DepthWindow kPeakWindow{0.07, 0.09};

// s_over_L < 0: one plate of width L (s -> infinity); 0: one plate of width 2 L; else two plates.
Scene pair_scene(double L, double s_over_L, DepthWindow win) {
  const double span = s_over_L < 0 ? L : s_over_L == 0 ? 2 * L : (2 + s_over_L) * L;
  const double W = 4.0 * span, H = win.to_m + span, x0 = 0.5 * W;
  std::vector<double> centres;
  if (s_over_L > 0) {
    centres.push_back(x0 - 0.5 * (s_over_L * L + L));
    centres.push_back(x0 + 0.5 * (s_over_L * L + L));
  } else {
    centres.push_back(x0);
  }
  return plates_scene(W, H, kPairDx, s_over_L == 0 ? 2 * L : L, centres, win.to_m);
}

// Per-plate window-mean drag over rho_d g z L w (z the window's middle).
double pair_normalized(const Trace& t, double L, double s_over_L, DepthWindow win) {
  const double plates = s_over_L > 0 ? 2.0 : s_over_L == 0 ? 2.0 : 1.0;
  const double F = depth_mean(depth_trace(t, 0.5 * kPairDx), win.from_m, win.to_m) / plates;
  const double Fn = F / (kRhoD * kG * 0.5 * (win.from_m + win.to_m) * L);
  std::printf("case 2 pair: L %.4f m  s/L %4s  per-plate drag %6.1f N/m  F/(rho_d g z L w) %.2f  (%zu particles, "
              "%lld steps, %.1f s)\n",
              L, s_over_L < 0 ? "inf" : std::to_string(s_over_L).substr(0, 4).c_str(), F, Fn, t.particles,
              (long long)t.steps, t.wall_s);
  return Fn;
}

// Measured when chosen (L = 0.025 m): s -> inf 10.16, s = 0 10.41, s/L 0.3 12.53, s/L 0.6 12.64.
// Those four samples rose from 0.3 to 0.6 and could not show where the peak sits; s/L 1 and 1.5
// (since 2026-12-05) put samples past it, so the test sees a maximum with lower values on both sides
// (PaperClaimMeasures.InteriorPeakNeedsLowerValuesPastIt: a curve still rising at 1.5 fails).
// Measured 2026-12-05: 11.13 / 13.15 / 13.91 / 13.42 / 13.48 / 10.91 at s/L 0 / 0.3 / 0.6 / 1 / 1.5 /
// inf: the top is broad (0.6 is 3.2-3.6% above 1 and 1.5); 71 s on 2 loaded cores.
TEST(PaperCase2, PlatePairDragPeaksAtSmallSeparation) {
  const double L = 0.025;
  const std::vector<double> s_over_L = {0.0, 0.3, 0.6, 1.0, 1.5, -1.0};  // increasing, s -> inf last
  std::vector<Scene> scenes;
  for (double r : s_over_L) scenes.push_back(pair_scene(L, r, kPeakWindow));
  const std::vector<Trace> traces = run_all(scenes);
  std::vector<double> Fn;
  for (size_t i = 0; i < s_over_L.size(); ++i) Fn.push_back(pair_normalized(traces[i], L, s_over_L[i], kPeakWindow));
  size_t k = 0;
  const bool peak = interior_peak(Fn, 0.05, &k);
  const double touching = Fn.front(), far = Fn.back();
  std::printf("case 2 pair: peak %.2f at s/L %.2f; s = 0: %.2f (peak %+.1f%%), s -> inf: %.2f (peak %+.1f%%), "
              "largest finite s/L %.1f: %.2f (peak %+.1f%%)\n",
              Fn[k], s_over_L[k], touching, 100 * (Fn[k] / touching - 1), far, 100 * (Fn[k] / far - 1),
              s_over_L[s_over_L.size() - 2], Fn[Fn.size() - 2], 100 * (Fn[k] / Fn[Fn.size() - 2] - 1));
  // an interior maximum (0 < s/L < 1.5) above both ends by at least 5%, lower past it
  EXPECT_TRUE(peak) << "largest at s/L " << (s_over_L[k] < 0 ? "inf" : std::to_string(s_over_L[k]));
}

// The same claim where a user first looks: the two_plates template at its preview dx (10 mm, 10
// cells per plate) over its own window, the paper's (plate bottom 0.04..0.08 m deep, 0.4..0.8 L),
// the plates moved apart symmetrically about the bed's middle. In that shallow window the touching
// pair (one 2 L plate) carries an L^2 share, so the paper expects F(0) / F(inf) between 1 and
// (2 L)^2 / 2 L^2 = 2; the peak sits at a smaller s/L than in the deep window above. Measured when
// chosen (cell_fraction, per plate): s/L 0 / 0.1 / 0.2 / 0.3 / 0.4 / 4: 1960 / 2107 / 2155 / 1962 /
// 1860 / 1475 N/m; at dx 5 mm 1981 / 2117 / 2149 / - / 1882 / 1519 (within 1.2% of the preview's,
// 3% at s/L 4), so the peak (+10% over s = 0) is resolved at the preview, not made by it. Until
// 2026-12-03 only s/L 0, 0.4, 0.6, 4 were run and the curve looked monotonic.
TEST(PaperCase2, TwoPlatesTemplateShowsThePairPeakAtItsPreview) {
  const Scene base = load_scene(std::string(FURROW_SOURCE_DIR) + "/scenes/two_plates.json");
  ASSERT_EQ(base.bodies.size(), 2u);
  const double L = base.bodies[0].shape.size_m.x(), mid_x = 0.5 * base.domain.width_m;
  const double window_to = base.outputs.average_to_m;
  const std::vector<double> s_over_L = {0.0, 0.2, 4.0};
  std::vector<Scene> scenes;
  for (double r : s_over_L) {
    Scene s = base;
    s.solver.threads = 1;
    s.solver.end_displacement_m = window_to + 0.5 * s.domain.dx_m;  // nothing after the window
    s.outputs.fields.clear();
    s.bodies[0].start_m.x() = mid_x - 0.5 * (r * L + L);
    s.bodies[1].start_m.x() = mid_x + 0.5 * (r * L + L);
    scenes.push_back(s);
  }
  const std::vector<Trace> traces = run_all(scenes);
  std::vector<double> F;  // per-plate mean drag over the window
  for (size_t i = 0; i < traces.size(); ++i) {
    const double left = window_mean(traces[i], 0, 1, base.outputs.average_from_m, window_to);
    const double right = window_mean(traces[i], 1, 1, base.outputs.average_from_m, window_to);
    std::printf("two_plates preview: s/L %.1f  drag per plate %.1f / %.1f N/m  (%zu particles, %lld steps, %.1f s)\n",
                s_over_L[i], left, right, traces[i].particles, (long long)traces[i].steps, traces[i].wall_s);
    EXPECT_NEAR(left, right, 0.01 * right) << "mirror-symmetric pair at s/L " << s_over_L[i];
    F.push_back(0.5 * (left + right));
  }
  std::printf("two_plates preview: peak at s/L 0.2 %+.1f%% over s = 0, %+.1f%% over s/L 4; F(0)/F(4) %.2f\n",
              100 * (F[1] / F[0] - 1), 100 * (F[1] / F[2] - 1), F[0] / F[2]);
  EXPECT_GE(F[1], 1.05 * F[0]);
  EXPECT_GE(F[1], 1.05 * F[2]);
  EXPECT_GT(F[0], F[2]);
  EXPECT_LT(F[0], 2.0 * F[2]);
}

// The paper's scaling (its eq. 11): where F ~ z L, F/(rho_d g z L w) is a function of s/L alone, the
// same for every L. That regime needs depth: the per-plate excess of a pair over a lone plate has
// an N_gamma-like share ~ 9 rho_d g L^2 that does not grow with z, so at shallow windows the curves
// split by L/z. Measured peak excess over s -> inf against z/L (8..15-cell plates, one curve
// whatever the resolution): 0.47 (z/L 1.7), 0.40 (2.3), 0.37 (2.5), 0.23 (3.2), 0.24 (3.5). At the
// peak test's window (0.07..0.09 m) L = 0.025 vs 0.0375 m differ by up to 19%; from z/L 3.2 on
// (window 0.12..0.14 m, z/L 3.5 and 5.2) they agree: measured when chosen s -> inf 9.94 / 10.02,
// s = 0 10.37 / 10.17, s/L 0.3 11.95 / 12.12 (worst 1.9%; 170 s on 2 cores). At E 5 MPa: 10.28 / 10.53,
// 10.85 / 10.86, 12.68 / 12.38 (worst 2.4%), so the soft bed does not make the collapse.
constexpr DepthWindow kCollapseWindow{0.12, 0.14};
TEST(PaperCase2, PlatePairCurvesCollapseOverWidth) {
  const std::vector<double> widths_m = {0.025, 0.0375}, s_over_L = {-1.0, 0.0, 0.3};
  std::vector<Scene> scenes;
  for (double L : widths_m)
    for (double r : s_over_L) scenes.push_back(pair_scene(L, r, kCollapseWindow));
  const std::vector<Trace> traces = run_all(scenes);
  std::vector<double> a, b;
  for (size_t k = 0; k < s_over_L.size(); ++k) {
    a.push_back(pair_normalized(traces[k], widths_m[0], s_over_L[k], kCollapseWindow));
    b.push_back(pair_normalized(traces[s_over_L.size() + k], widths_m[1], s_over_L[k], kCollapseWindow));
  }
  for (size_t k = 0; k < a.size(); ++k) {
    std::printf("case 2 pair collapse: s/L %s: %.2f vs %.2f (%+.1f%%)\n",
                s_over_L[k] < 0 ? "inf" : std::to_string(s_over_L[k]).substr(0, 3).c_str(), a[k], b[k],
                100 * (b[k] / a[k] - 1));
    EXPECT_NEAR(b[k], a[k], 0.10 * a[k]) << "s/L point " << k;
  }
  // and the curve keeps its interior peak at this depth
  EXPECT_GE(a[2], 1.05 * std::max(a[0], a[1]));
  EXPECT_GE(b[2], 1.05 * std::max(b[0], b[1]));
}

}  // namespace
}  // namespace furrow::paper
