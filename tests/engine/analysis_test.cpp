// engine/analysis on synthetic inputs with known answers: drag-signal statistics (mean, detrended
// fluctuation, dominant period) and the rigid-wedge measurement on a rasterized velocity field.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "engine/analysis.hpp"
#include "engine/io/field_store.hpp"
#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"
#include "tests/engine/test_scenes.hpp"

using namespace furrow;

namespace {

constexpr double kPi = 3.14159265358979323846;

// one sample per 0.1 mm of travel over [0, 0.3] m, like a per-step force log at coarse dt
struct Signal {
  std::vector<double> s, f;
};
template <class F>
Signal sample(F f, double ds = 1e-4, double to = 0.3) {
  Signal g;
  // sample k at (k + 1/2) ds: none falls on a bin boundary
  for (long k = 0; (k + 0.5) * ds < to; ++k) {
    g.s.push_back((k + 0.5) * ds);
    g.f.push_back(f(g.s.back()));
  }
  return g;
}

}  // namespace

// A plow's drag: a ramp (spoil accumulating) plus a periodic shear-band cycle of known period and
// amplitude, plus white noise. The window holds 0.25 / 0.037 = 6.8 cycles, not a whole number, so
// the period must come from the interpolated spectral peak, not a lucky bin.
TEST(DragStatistics, SineOnRampGivesPeriodAmplitudeAndMean) {
  const double p = 0.037, A = 15.0;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 5.0);
  const Signal g = sample([&](double s) { return 100.0 + 200.0 * s + A * std::sin(2 * kPi * s / p + 0.4) + noise(rng); });
  DragStatsOptions o;
  o.from_m = 0.05;
  o.to_m = 0.3;
  o.bin_m = 0.002;
  const DragStats st = drag_statistics(g.s, g.f, o);
  EXPECT_EQ(st.bins, 125);
  EXPECT_NEAR(st.samples, 2500, 2);
  // mean of the ramp over the window is 100 + 200 * 0.175 = 135; an incomplete sine cycle shifts
  // a travel mean by at most A p / (pi * 0.25) = 0.7 N/m
  EXPECT_NEAR(st.mean_N_per_m, 135.0, 0.8);
  // the removed trend is the ramp's slope, up to the sine's projection on a line (~ A p / 0.25^2)
  EXPECT_NEAR(st.trend_N_per_m2, 200.0, 10.0);
  // RMS of a sine is A / sqrt 2; a 2 mm box passes a 37 mm sine at sinc(pi 2/37) = 0.995, and
  // noise of 5 N/m averaged over 20 samples per bin adds 1.1 N/m in quadrature (0.6% of 10.6)
  EXPECT_NEAR(st.rms_N_per_m, A / std::sqrt(2.0), 0.03 * A / std::sqrt(2.0));
  EXPECT_NEAR(st.relative_fluctuation, st.rms_N_per_m / 135.0, 1e-3);
  EXPECT_LT(st.period_p_value, 1e-6);
  EXPECT_NEAR(st.period_m, p, 0.02 * p);
}

TEST(DragStatistics, WhiteNoiseHasNoDominantPeriod) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 10.0);
    const Signal g = sample([&](double) { return 50.0 + noise(rng); });
    DragStatsOptions o;
    o.bin_m = 0.002;
    const DragStats st = drag_statistics(g.s, g.f, o);
    EXPECT_TRUE(std::isnan(st.period_m)) << "seed " << seed << " period " << st.period_m;
    EXPECT_GT(st.period_p_value, o.alpha) << "seed " << seed;
    EXPECT_NEAR(st.mean_N_per_m, 50.0, 1.0);
    // 20 samples per bin: the bins' scatter is 10 / sqrt(20) = 2.2 N/m
    EXPECT_NEAR(st.rms_N_per_m, 10.0 / std::sqrt(20.0), 0.4);
  }
}

// The grid-crossing noise of an MPM plate has period dx in travel; a one-cell box removes it,
// leaving only the (here white) noise on top, so no period is reported either.
TEST(DragStatistics, OneCellBoxRemovesCellCrossingNoise) {
  const double dx = 0.005;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 2.0);
  // 500 samples per cell
  const Signal g = sample([&](double s) { return 80.0 + 30.0 * (s / dx - std::floor(s / dx)) + noise(rng); }, 1e-5);
  DragStatsOptions o;
  o.bin_m = dx;
  const DragStats st = drag_statistics(g.s, g.f, o);
  EXPECT_NEAR(st.mean_N_per_m, 95.0, 0.05);
  // what is left is the noise averaged over 500 samples: 2 / sqrt(500) = 0.09 N/m
  EXPECT_NEAR(st.rms_N_per_m, 2.0 / std::sqrt(500.0), 0.03);
  EXPECT_TRUE(std::isnan(st.period_m));
  // the same signal in boxes of a fifth of a cell keeps the sawtooth (RMS 30 / sqrt 12 = 8.7,
  // less the part averaged within a box)
  o.bin_m = dx / 5;
  EXPECT_GT(drag_statistics(g.s, g.f, o).rms_N_per_m, 5.0);
}

TEST(DragStatistics, SamplesOutsideTheWindowAreIgnoredAndShortWindowsGiveNaN) {
  const Signal g = sample([](double s) { return s < 0.1 ? 1e6 : 42.0; });
  DragStatsOptions o;
  o.from_m = 0.1;
  o.bin_m = 0.01;
  DragStats st = drag_statistics(g.s, g.f, o);
  EXPECT_DOUBLE_EQ(st.mean_N_per_m, 42.0);
  EXPECT_DOUBLE_EQ(st.rms_N_per_m, 0.0);
  EXPECT_TRUE(std::isnan(st.period_m));
  o.from_m = 0.28;  // two bins: a mean, but no fluctuation about a line
  st = drag_statistics(g.s, g.f, o);
  EXPECT_DOUBLE_EQ(st.mean_N_per_m, 42.0);
  EXPECT_TRUE(std::isnan(st.rms_N_per_m));
  o.from_m = 0.4;  // beyond the data
  o.to_m = 0.5;
  EXPECT_TRUE(std::isnan(drag_statistics(g.s, g.f, o).mean_N_per_m));
  EXPECT_THROW(drag_statistics(g.s, {1.0}, o), std::invalid_argument);
}

TEST(DragStatistics, AverageWindowByTimeOrDisplacement) {
  Outputs out;  // default: whole run by time
  EXPECT_TRUE(in_average_window(out, 0.0, 0.0));
  EXPECT_TRUE(in_average_window(out, 9.0, 5.0));
  out.average_from_m = 0.2;  // {"from_m": 0.2, "to_m": null}
  EXPECT_FALSE(in_average_window(out, 9.0, 0.1));
  EXPECT_TRUE(in_average_window(out, 0.0, 0.25));
  out.average_to_m = 0.3;
  EXPECT_FALSE(in_average_window(out, 0.0, 0.31));
  Outputs by_time;
  by_time.average_from_s = 1.0;
  by_time.average_to_s = 2.0;
  EXPECT_FALSE(in_average_window(by_time, 0.5, 1.0));
  EXPECT_TRUE(in_average_window(by_time, 1.5, 0.0));
  EXPECT_FALSE(in_average_window(by_time, 2.5, 1.0));
}

// ------------------------------------------------------------------------------- wedge

namespace {

constexpr double kDx = 0.002, kL = 0.04, kFaceX0 = 0.23;
const Vec2 kVPlate(0.0, -0.15);

BodyOutline plate_outline(double face_y) {
  BodyOutline o;
  o.name = "plate";
  for (const Vec2& v : {Vec2(kFaceX0, face_y), Vec2(kFaceX0 + kL, face_y), Vec2(kFaceX0 + kL, face_y + 0.02),
                       Vec2(kFaceX0, face_y + 0.02)})
    o.outline_m.push_back(v);
  o.position_m = Vec2(kFaceX0 + 0.5 * kL, face_y + 0.01);
  return o;
}

// A bed with a rigid zone under the plate: the symmetric wedge of full apex angle `apex_deg` on
// the face, cut at depth `cut_m` (a trapezoid when the cut is above the apex). As across a real
// shear band the velocity changes smoothly: with d the distance outside the zone (negative
// inside), the mismatch |v - v_plate| / |v_plate| is tol (1 + d / 3 dx), clamped to [0, 1], so
// the tolerance contour is exactly the zone's outline and the field is linear over three cells
// either side.
FieldFrame wedge_frame(double apex_deg, double face_y, double cut_m = 1.0, double tol = 0.1) {
  FieldFrame f;
  f.dx_m = kDx;
  f.nx = 250;
  f.ny = int(std::ceil(face_y / kDx)) + 15;
  const size_t n = size_t(f.nx) * f.ny;
  f.active.assign(n, 0);
  f.velocity_x.assign(n, 0.0f);
  f.velocity_y.assign(n, 0.0f);
  const double half = 0.5 * apex_deg * kPi / 180.0, xm = kFaceX0 + 0.5 * kL;
  for (int j = 0; j < f.ny; ++j)
    for (int i = 0; i < f.nx; ++i) {
      const double x = (i + 0.5) * kDx, y = (j + 0.5) * kDx, z = face_y - y;
      const size_t k = f.index(i, j);
      // material: the bed below the surface at face_y + 0.01, except inside the plate
      const bool in_plate = x > kFaceX0 && x < kFaceX0 + kL && y > face_y;
      if (y > face_y + 0.01 || in_plate) continue;
      f.active[k] = 1;
      // distance outside the flanks (perpendicular), the face and the cut
      const double d_flank = (std::abs(x - xm) - 0.5 * kL) * std::cos(half) + z * std::sin(half);
      const double d = std::max({d_flank, -z, z - cut_m});
      const double e = std::clamp(tol * (1.0 + d / (3.0 * kDx)), 0.0, 1.0);
      const double ux = x < xm ? -0.6 : 0.6, uy = 0.8;  // outside: sideways and less fast down
      f.velocity_x[k] = float(kVPlate.x() + e * kVPlate.norm() * ux);
      f.velocity_y[k] = float(kVPlate.y() + e * kVPlate.norm() * uy);
    }
  return f;
}

}  // namespace

class WedgeAngle : public ::testing::TestWithParam<double> {};

// The edges are interpolated where the mismatch crosses the tolerance; the synthetic field is
// linear there, so the flanks come back to float round-off, up to the kink where a flank meets
// the face within a cell of the top row: 0.5 degrees. The height is that of the deepest row
// holding a cell centre inside, which for a wedge of half-angle a centred on a cell boundary is
// H - dx / (2 tan a) to within half a cell.
TEST_P(WedgeAngle, RecoversApexAngleAndHeightOfARasterizedWedge) {
  const double apex = GetParam(), half = 0.5 * apex * kPi / 180.0;
  for (double face_y : {0.15, 0.1513}) {  // face on a cell boundary and off it
    const FieldFrame f = wedge_frame(apex, face_y);
    const WedgeMeasure m = measure_wedge(f, plate_outline(face_y), kVPlate);
    ASSERT_TRUE(m.found);
    const double H = 0.5 * kL / std::tan(half);
    EXPECT_NEAR(m.apex_angle_deg, apex, 0.5) << "face " << face_y;
    EXPECT_NEAR(m.left_flank_deg, m.right_flank_deg, 0.5);
    EXPECT_NEAR(m.apex_depth_m, H, 0.25 * kDx) << "face " << face_y;
    // the flank lines meet the face at the plate's corners (what the inspector's overlay draws)
    EXPECT_NEAR(m.left_flank_x_m, kFaceX0, 0.25 * kDx) << "face " << face_y;
    EXPECT_NEAR(m.right_flank_x_m, kFaceX0 + kL, 0.25 * kDx) << "face " << face_y;
    EXPECT_DOUBLE_EQ(m.face_y_m, face_y);
    EXPECT_NEAR(m.height_m, H - 0.5 * kDx / std::tan(half), 0.5 * kDx + 1e-9) << "face " << face_y;
    EXPECT_GE(m.fit_rows, 8);
    // region = the wedge's cells: its area is L H / 2 within a perimeter's worth of cells
    EXPECT_NEAR(m.cells * kDx * kDx, 0.5 * kL * H, (kL + 2 * H) * kDx);
  }
}

INSTANTIATE_TEST_SUITE_P(Angles, WedgeAngle, ::testing::Values(50.0, 62.1, 74.4, 90.0));

// Early in loose media the zone is a short trapezoid: its flanks already have an angle, and that
// angle, not the (absent) apex, is what the measurement reports; the height is the cut.
TEST(Wedge, TrapezoidReportsFlankAngleAndItsHeight) {
  const FieldFrame f = wedge_frame(74.4, 0.15, 0.016);
  const WedgeMeasure m = measure_wedge(f, plate_outline(0.15), kVPlate);
  ASSERT_TRUE(m.found);
  EXPECT_NEAR(m.height_m, 0.016, 0.5 * kDx);
  EXPECT_EQ(m.fit_rows, 8);
  EXPECT_NEAR(m.apex_angle_deg, 74.4, 1.5);  // the bottom row sits on the cut's kink
  EXPECT_GT(m.apex_depth_m, m.height_m);    // the flanks would meet below the region
}

// The layer touching the face may slide along it (or lag the plate for a few steps as the face
// crosses a grid node line) while the zone below moves with the plate: the region grows from
// the first three rows, and the flanks start at the widest of them.
TEST(Wedge, ASlidingContactLayerDoesNotHideTheZoneBelow) {
  const WedgeMeasure ref = measure_wedge(wedge_frame(62.1, 0.15), plate_outline(0.15), kVPlate);
  for (int qualifying : {0, 6}) {  // none of the top row moves with the plate, or its middle 6 cells
    FieldFrame f = wedge_frame(62.1, 0.15);
    const int jtop = int(std::floor(0.15 / kDx)) - 1, im = int(std::round((kFaceX0 + 0.5 * kL) / kDx));
    for (int i = 0; i < f.nx; ++i) {
      if (std::abs(i - im + 0.5) < 0.5 * qualifying) continue;
      f.velocity_x[f.index(i, jtop)] = 0.5f * float(kVPlate.norm());  // sliding outward
      f.velocity_y[f.index(i, jtop)] = float(kVPlate.y());
    }
    const WedgeMeasure m = measure_wedge(f, plate_outline(0.15), kVPlate);
    ASSERT_TRUE(m.found) << qualifying;
    EXPECT_EQ(m.fit_rows, ref.fit_rows - 1) << qualifying;
    EXPECT_NEAR(m.apex_angle_deg, 62.1, 0.5) << qualifying;
    EXPECT_NEAR(m.apex_depth_m, ref.apex_depth_m, 0.25 * kDx) << qualifying;
  }
}

TEST(Wedge, OnlyMaterialBelowTheFaceAndConnectedToItCounts) {
  FieldFrame f = wedge_frame(62.1, 0.15);
  // a detached blob moving with the plate deep below, and material beside the plate dragged along
  for (int j = 5; j < 10; ++j)
    for (int i = 120; i < 130; ++i) {
      f.velocity_x[f.index(i, j)] = float(kVPlate.x());
      f.velocity_y[f.index(i, j)] = float(kVPlate.y());
    }
  for (int j = 75; j < 80; ++j)
    for (int i = 110; i < 115; ++i) {
      f.velocity_x[f.index(i, j)] = float(kVPlate.x());
      f.velocity_y[f.index(i, j)] = float(kVPlate.y());
    }
  const WedgeMeasure ref = measure_wedge(wedge_frame(62.1, 0.15), plate_outline(0.15), kVPlate);
  const WedgeMeasure m = measure_wedge(f, plate_outline(0.15), kVPlate);
  EXPECT_EQ(m.cells, ref.cells);
  EXPECT_EQ(m.apex_angle_deg, ref.apex_angle_deg);
  EXPECT_EQ(m.mask[f.index(125, 7)], 0);
}

TEST(Wedge, NoRegionWhenNothingMovesWithThePlateAndErrorsOnBadInput) {
  FieldFrame f = wedge_frame(62.1, 0.15);
  const WedgeMeasure none = measure_wedge(f, plate_outline(0.15), Vec2(0.0, -0.5));
  EXPECT_FALSE(none.found);
  EXPECT_TRUE(std::isnan(none.apex_angle_deg));
  EXPECT_THROW(measure_wedge(f, plate_outline(0.15), Vec2(0.0, 0.0)), std::invalid_argument);
  f.velocity_x.clear();
  EXPECT_THROW(measure_wedge(f, plate_outline(0.15), kVPlate), std::invalid_argument);
}

TEST(Wedge, MedianSkipsMissingAngles) {
  EXPECT_DOUBLE_EQ(median_finite({3.0, NAN, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(median_finite({4.0, 1.0, NAN, 2.0, 3.0, INFINITY}), 2.5);
  EXPECT_TRUE(std::isnan(median_finite({NAN})));
}

TEST(Wedge, SlipLineAngle) {
  EXPECT_NEAR(slip_line_apex_angle_deg(0.0), 90.0, 1e-12);  // Prandtl's frictionless wedge
  EXPECT_NEAR(slip_line_apex_angle_deg(0.53), 62.08, 0.01);
  EXPECT_NEAR(slip_line_apex_angle_deg(0.28), 74.36, 0.01);
}

// ------------------------------------------------------------------------------- run.json

namespace {

std::string temp_run_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("furrow_analysis_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  return d.string();
}

}  // namespace

// A plate intrusion with velocity frames: run.json carries the drag statistics of the plate over
// the averaging window and one wedge entry per frame. The scene is the loose_intrusion template
// (case 4) coarsened to dx 4 mm, 10 cells across the plate, 29 mm of travel (a few seconds), where
// the zone under the plate has flanks to fit once it is in: a 4-cell plate in a dense bed, used
// until 2026-12-05, never had one, and the flank checks below checked nothing.
TEST(RunAnalysis, RunJsonHasDragStatisticsAndWedgePerFrame) {
  const SceneTemplate* t = find_scene_template("loose_intrusion");
  ASSERT_NE(t, nullptr);
  Scene s = parse_scene_text(t->text, "<template loose_intrusion>",
                             {"domain.width_m=0.2", "domain.height_m=0.13", "domain.dx_m=0.004", "beds.0.max_m=[0.2,0.1]",
                              "bodies.plate.start_m=[0.1,0.112]", "solver.end_displacement_m=0.029",
                              "outputs.frame_interval_s=0.01", "outputs.fields=[\"velocity\"]", "outputs.movies=[]"});
  s.outputs.average_from_m = 0.005;  // by travel
  const std::string dir = temp_run_dir("plate");
  RunOptions opt;
  opt.out_dir = dir;
  opt.write_paraview = false;
  // a follower sees each frame complete as it is stored, numbered in order
  int64_t written = 0;
  opt.frame_written = [&](int64_t index, const std::string& path) {
    EXPECT_EQ(index, written++);
    EXPECT_FALSE(read_frame(path).velocity_x.empty()) << path;  // the stored field is there
  };
  const RunSummary r = run_scene(s, opt);
  EXPECT_EQ(written, r.run_json.at("frames").get<int64_t>());
  const auto& a = r.run_json.at("analysis");
  EXPECT_EQ(a.at("lead_body"), "plate");
  const auto& d = a.at("drag");
  EXPECT_NEAR(d.at("from_m").get<double>(), 0.005, 1e-3);
  EXPECT_NEAR(d.at("to_m").get<double>(), 0.029, 1e-4);
  // the plate pushes down: drag is the upward reaction, positive
  EXPECT_GT(d.at("mean_N_per_m").get<double>(), 0.0);
  const auto& w = a.at("wedge");
  EXPECT_EQ(w.at("frames").size(), size_t(r.run_json.at("frames").get<int64_t>()));
  // a frame with an angle carries its flank lines, consistent with it; a frame without one carries
  // none (the plate is in the bed from the second frame on, so at least one frame has its zone)
  int with_angle = 0;
  for (const auto& e : w.at("frames")) {
    EXPECT_TRUE(e.contains("apex_angle_deg") && e.contains("height_m"));
    const bool angle = e.at("apex_angle_deg").is_number();
    with_angle += angle;
    EXPECT_EQ(e.at("left_flank_x_m").is_number(), angle) << e.dump();
    EXPECT_EQ(e.at("right_flank_x_m").is_number(), angle) << e.dump();
    if (!angle) continue;
    EXPECT_NEAR(e.at("left_flank_deg").get<double>() + e.at("right_flank_deg").get<double>(),
                e.at("apex_angle_deg").get<double>(), 1e-9);
    EXPECT_LT(e.at("left_flank_x_m").get<double>(), e.at("right_flank_x_m").get<double>());
    EXPECT_TRUE(e.at("face_y_m").is_number());
  }
  EXPECT_GE(with_angle, 1) << w.dump();
  EXPECT_TRUE(w.contains("early_median_apex_angle_deg") && w.contains("late_median_apex_angle_deg"));
  std::ifstream in(dir + "/run.json");
  EXPECT_EQ(nlohmann::json::parse(in).at("analysis"), a);
  std::filesystem::remove_all(dir);
}

TEST(RunAnalysis, NothingForScenesWithoutMovingBodies) {
  Scene s = test_scenes::bed_scene(0.05, 0.02, 0.01, 0.005, 0.002);
  RunAnalysis a(s);
  EXPECT_FALSE(a.active());
  EXPECT_FALSE(a.wants_frames());
  EXPECT_TRUE(a.to_json().is_null());
}

// A single-step kick stands out from its neighbours' mean; a fluctuation of the flow (here 3% at a
// period of 6 mm of travel, 600 samples a period) does not, however large its RMS.
TEST(ForceSmoothness, TickMeasureSeparatesSingleStepKicksFromSlowFluctuations) {
  const double kPi = 3.14159265358979323846;
  auto flow = [&](double s) { return 1000.0 * (1.0 + 0.03 * std::sin(2 * kPi * s / 0.006)); };
  const Signal smooth = sample(flow, 1e-5, 0.1);
  Signal kicked = smooth;
  for (size_t k = 150; k < kicked.f.size(); k += 300) kicked.f[k] += 100.0;  // +10% every 3 mm
  const ForceSmoothness a = force_smoothness(smooth.s, smooth.f, 0.01, 0.02, 0.08);
  const ForceSmoothness b = force_smoothness(kicked.s, kicked.f, 0.01, 0.02, 0.08);
  // the slow part's second difference: 0.03 (2 pi ds / period)^2 / 2 = 1.6e-5 of the mean
  EXPECT_LT(a.tick_max_relative, 1e-4);
  EXPECT_GT(a.rms_relative, 0.01);  // the flow's own fluctuation: not what the tick measure sees
  EXPECT_NEAR(b.tick_max_relative, 0.1, 0.005);
}
