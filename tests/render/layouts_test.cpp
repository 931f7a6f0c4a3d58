// The paper's layouts at the library level: dimensionless colorbars and a force panel drawn as its
// one-cell running mean over the raw trace.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/scene/scene_io.hpp"
#include "render/force_series.hpp"
#include "render/frame_renderer.hpp"
#include "render/layouts.hpp"
#include "render/point_splat.hpp"
#include "tests/render/synthetic_frames.hpp"

using namespace furrow;
using namespace furrow::render;

// plate_intrusion's plate: v = 0.1 m/s down, 0.1 m wide; the synthetic bed moves at vy = -0.04 m/s,
// which reads -0.4 v: the colorbar's ticks are in units of v (|tick| <= 0.4), dimensionless.
TEST(Layouts, NormalizedVelocityColorbarCountsInUnitsOfTheBodySpeed) {
  const Scene scene = parse_scene_text(find_scene_template("plate_intrusion")->text, "<template>");
  const BodyScales sc = body_scales(scene, "<template>");
  EXPECT_EQ(sc.body, "plate");
  EXPECT_DOUBLE_EQ(sc.speed_m_s, 0.1);
  EXPECT_NEAR(sc.length_m, 0.1, 1e-12);  // across a downward travel: the plate's width, not its 0.02 m height
  FieldFrame f = test::hydrostatic_frame(80, 50, 0.005, 0.2);
  FrameStyle style;
  style.field = "velocity_y";
  style.width = 640, style.height = 360;
  style.range = {-0.05, 0.05, false};  // SI, as scanned
  FrameStyle plain = style;
  normalize_style(sc, &style);
  EXPECT_DOUBLE_EQ(style.range.lo, -0.5);
  EXPECT_DOUBLE_EQ(style.range.hi, 0.5);
  EXPECT_EQ(style.value_title, "Vertical velocity / v");
  EXPECT_EQ(style.time_label, "t v/L");
  EXPECT_DOUBLE_EQ(style.time_scale, 1.0);
  EXPECT_NE(style.title.find("v = 0.1 m/s, L = 0.1 m"), std::string::npos) << style.title;
  FrameRenderer r(style), q(plain);
  r.render(f);
  q.render(f);
  ASSERT_FALSE(r.layout().colorbar_ticks.empty());
  double widest = 0, widest_plain = 0;
  for (const auto& t : r.layout().colorbar_ticks) widest = std::max(widest, std::abs(t.value));
  for (const auto& t : q.layout().colorbar_ticks) widest_plain = std::max(widest_plain, std::abs(t.value));
  EXPECT_GE(widest, 0.3);
  EXPECT_LE(widest, 0.5);
  EXPECT_LE(widest_plain, 0.05);  // the same frame in m/s
  EXPECT_EQ(r.layout().colorbar_unit, "");  // no unit: dimensionless
  // strain rate over v/L: the same number for L = v = 0.1
  FrameStyle rate;
  rate.field = "strain_rate";
  rate.range = {1e-3, 10.0, true};
  normalize_style({"plate", 0.2, 0.1}, &rate);
  EXPECT_DOUBLE_EQ(rate.value_scale, 0.5);
  EXPECT_DOUBLE_EQ(rate.range.hi, 5.0);
  EXPECT_EQ(rate.value_title, "Equivalent plastic shear rate / (v/L)");
}

// A trace of 100 N/m with a single-step kick of +13% every 40 steps (a cell of travel is 100
// steps): the running mean over one cell stays within 1% of 100 while the raw trace keeps its
// kicks; the raw comes first, marked faint, and the title says what is drawn.
TEST(Layouts, ForcePanelDrawsTheOneCellMeanOverTheFaintRawTrace) {
  ForcePanel panel;
  ForceSeries s;
  s.label = "plate";
  for (int k = 0; k < 2000; ++k) {
    s.t_s.push_back(k * 1e-4);
    s.x.push_back(k * 0.05);  // mm
    s.y.push_back(k % 40 == 0 ? 113.0 : 100.0);
  }
  panel.series.push_back(s);
  const ForcePanel m = with_running_mean(panel, 5.0, "1 cell = 5 mm");
  ASSERT_EQ(m.series.size(), 2u);
  EXPECT_TRUE(m.series[0].faint);
  EXPECT_FALSE(m.series[1].faint);
  EXPECT_EQ(m.series[0].y, s.y);
  const double mean = 100.0 + 13.0 / 40.0;
  double worst = 0;
  for (size_t k = 50; k + 50 < s.y.size(); ++k) worst = std::max(worst, std::abs(m.series[1].y[k] / mean - 1.0));
  EXPECT_LT(worst, 0.01);
  EXPECT_NE(m.title.find("mean over 1 cell = 5 mm"), std::string::npos) << m.title;
  // against time (no body moves) nothing is averaged
  ForcePanel by_time = panel;
  by_time.x_label = "time (s)";
  EXPECT_EQ(with_running_mean(by_time, 5.0, "").series.size(), 1u);
}

// Points drawn as discs: each disc covers about its point's area (pi r^2 = V), carries its point's
// own value, and nothing lies between discs that are apart.
TEST(Layouts, PointsAreDiscsOfTheirOwnAreaAndValue) {
  FieldFrame grid;
  grid.nx = 20, grid.ny = 10, grid.dx_m = 0.01;
  PointFrame pts;
  pts.dx_m = 0.01;
  pts.time_s = 0.5;
  for (int k = 0; k < 5; ++k) {
    pts.x_m.push_back(0.02 + 0.035 * k), pts.y_m.push_back(0.05);
    pts.vx_m_s.push_back(0.f), pts.vy_m_s.push_back(-0.1f * k);
    pts.volume_m2.push_back(float(M_PI * 0.004 * 0.004));  // discs of radius 4 mm
    pts.pressure_Pa.push_back(100.f * float(k + 1));
  }
  const int sub = 8;  // 1.25 mm texels
  const FieldFrame f = splat_points(pts, grid, sub, {"pressure", "velocity_y"}, "test");
  EXPECT_EQ(f.nx, 160);
  EXPECT_DOUBLE_EQ(f.time_s, 0.5);
  const double texel_area = 0.00125 * 0.00125, disc_area = M_PI * 0.004 * 0.004;
  for (int k = 0; k < 5; ++k) {
    int covered = 0;
    for (size_t c = 0; c < f.active.size(); ++c)
      if (f.active[c] && f.scalars.at("pressure")[c] == 100.f * float(k + 1)) ++covered;
    EXPECT_NEAR(covered * texel_area, disc_area, 0.25 * disc_area) << k;
  }
  EXPECT_EQ(f.velocity_y[f.index(int(0.09 / 0.00125), int(0.05 / 0.00125))], -0.2f);  // point 2's own value
  EXPECT_EQ(f.active[f.index(int(0.0375 / 0.00125), int(0.05 / 0.00125))], 0);  // between points 0 and 1
  EXPECT_THROW(splat_points(pts, grid, sub, {"strain_rate"}, "test"), std::runtime_error);  // not stored
}
