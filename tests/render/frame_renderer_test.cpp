// FrameRenderer on synthetic frames with known fields (DISPLAY unset). Set FURROW_TEST_DUMP=DIR
// to keep the rendered images for a look.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "engine/io/field_store.hpp"
#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"
#include "render/colormap.hpp"
#include "render/force_series.hpp"
#include "render/frame_renderer.hpp"
#include "tests/render/capture_output.hpp"
#include "tests/render/synthetic_frames.hpp"

using namespace furrow;
using namespace furrow::render;

namespace {
// Bed 0.4 m x 0.25 m (160 x 100 cells of 2.5 mm), material up to 0.2 m, a plate across the surface.
constexpr int kNx = 160, kNy = 100;
constexpr double kDx = 0.0025, kSurface = 0.2;
constexpr double kPlateX0 = 0.20, kPlateX1 = 0.30, kPlateY0 = 0.17, kPlateY1 = 0.23;

FieldFrame test_frame() {
  FieldFrame f = test::hydrostatic_frame(kNx, kNy, kDx, kSurface);
  f.bodies.push_back(test::box_body("plate", kPlateX0, kPlateY0, kPlateX1, kPlateY1));
  return f;
}

double max_pressure() { return test::kRhoBulk_kg_m3 * test::kG_m_s2 * kSurface; }

void dump(const RgbImage& img, const std::string& name) {
  if (const char* d = std::getenv("FURROW_TEST_DUMP")) {
    std::filesystem::create_directories(d);
    write_png(img, (std::filesystem::path(d) / (name + ".png")).string(), true);
  }
}

bool near_rgb(const uint8_t* px, const std::array<float, 3>& c, int tol) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(int(px[k]) - int(std::lround(255 * c[k]))) > tol) return false;
  return true;
}
}  // namespace

TEST(FrameRenderer, HydrostaticPressureColoursRiseMonotonicallyWithDepth) {
  FrameStyle style;
  style.field = "pressure";
  style.range = {0.0, max_pressure(), false};
  FieldFrame frame = test_frame();
  RgbImage img;
  FrameLayout L;
  const std::string noise = test::capture_output([&] {
    FrameRenderer r(style);
    img = r.render(frame);
    L = r.layout();
  });
  dump(img, "pressure");
  EXPECT_FALSE(test::mentions_gl_trouble(noise)) << noise;
  ASSERT_EQ(img.width, 1280);
  ASSERT_EQ(img.height, 720);
  EXPECT_EQ(style.colormap, "");  // the style passed in is not modified
  const Colormap& cmap = load_colormap("viridis");

  // Aspect ratio of the bed is kept.
  EXPECT_NEAR((L.bed_x1 - L.bed_x0) / (L.bed_y1 - L.bed_y0), (kNx * kDx) / (kNy * kDx), 1e-9);

  // Down a vertical line at x = 0.08 m (clear of the plate), from 1 px below the free surface to
  // 1 px above the bottom: every pixel is a viridis colour, its index never decreases with depth,
  // and it matches the pressure at its depth (index = floor(256 p / p_max), within 2): drawn blended
  // between cell centres, a linear field reads exactly, held at the outer cells' centres.
  const int px = int(L.to_pixel({0.08, 0.0}).x());
  const int y_surface = int(std::ceil(L.to_pixel({0.0, kSurface}).y()));
  const int y_bottom = int(std::floor(L.to_pixel({0.0, 0.0}).y()));
  ASSERT_GT(y_bottom - y_surface, 200);
  int previous = -1, checked = 0;
  for (int y = y_surface + 1; y < y_bottom - 1; ++y) {
    double dist = 0;
    const int idx = cmap.nearest_index(img.at(px, y), &dist);
    ASSERT_LE(dist, 3.0) << "pixel (" << px << "," << y << ") is not a colormap colour";
    ASSERT_GE(idx, previous) << "colour index fell with depth at y = " << y;
    previous = idx;
    const double y_m = (L.bed_y1 - (y + 0.5)) / L.px_per_m;
    const double depth_m = std::clamp(kSurface - y_m, 0.5 * kDx, kSurface - 0.5 * kDx);
    const double expect = std::min(255.0, std::floor(256.0 * depth_m / kSurface));
    EXPECT_NEAR(idx, expect, 2.0) << "at depth " << kSurface - y_m << " m";
    ++checked;
  }
  EXPECT_GT(checked, 200);
  // Just below the surface the colour is near the bottom of the map, at the bed bottom near the top.
  EXPECT_LE(cmap.nearest_index(img.at(px, y_surface + 2)), 8);
  EXPECT_GE(cmap.nearest_index(img.at(px, y_bottom - 2)), 247);

  // Above the free surface (no material): the neutral empty colour.
  const int y_air = int(L.to_pixel({0.0, 0.5 * (kSurface + kNy * kDx)}).y());
  EXPECT_TRUE(near_rgb(img.at(px, y_air), style.empty_rgb, 1));

  // Body outline: cyan pixels lie on the plate's edges (within 3 px) and nowhere else.
  const Eigen::Vector2d a = L.to_pixel({kPlateX0, kPlateY1}), b = L.to_pixel({kPlateX1, kPlateY0});
  int on_edges = 0, elsewhere = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (!near_rgb(img.at(x, y), style.outline_rgb, 40)) continue;
      const double dx_out = std::max({a.x() - x - 0.5, x + 0.5 - b.x(), 0.0});
      const double dy_out = std::max({a.y() - y - 0.5, y + 0.5 - b.y(), 0.0});
      const double d_in = std::min({x + 0.5 - a.x(), b.x() - x - 0.5, y + 0.5 - a.y(), b.y() - y - 0.5});
      const double dist = (dx_out > 0 || dy_out > 0) ? std::hypot(dx_out, dy_out) : d_in;
      (dist <= 3.0 ? on_edges : elsewhere) += 1;
    }
  const double perimeter_px = 2.0 * ((b.x() - a.x()) + (b.y() - a.y()));
  EXPECT_GT(on_edges, perimeter_px) << "outline should be at least 1 px wide all round";
  EXPECT_EQ(elsewhere, 0);

  // Colorbar: most of the 256 colours appear in its box.
  std::vector<bool> seen(cmap.rgb.size(), false);
  for (int y = L.colorbar_y0; y < L.colorbar_y1; ++y)
    for (int x = L.colorbar_x0; x < L.colorbar_x1; ++x) {
      double dist = 0;
      const int idx = cmap.nearest_index(img.at(x, y), &dist);
      if (dist < 1.5) seen[idx] = true;
    }
  EXPECT_GT(std::count(seen.begin(), seen.end(), true), 200);
  // Colorbar title/labels and the time stamp: dark text pixels in their boxes.
  auto dark_pixels = [&](int x0, int y0, int x1, int y1) {
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) n += img.at(x, y)[0] < 90 && img.at(x, y)[1] < 90 && img.at(x, y)[2] < 90;
    return n;
  };
  EXPECT_GT(dark_pixels(L.colorbar_x0, L.colorbar_y0, L.colorbar_x1, L.colorbar_y1), 300);
  EXPECT_GT(dark_pixels(L.time_x0, L.time_y0, L.time_x1, L.time_y1), 100);
}

TEST(FrameRenderer, SameFrameTwiceGivesIdenticalImages) {
  FrameStyle style;
  style.field = "pressure";
  style.width = 640, style.height = 360;
  style.range = {0.0, max_pressure(), false};
  FrameRenderer r(style);
  const FieldFrame f = test_frame();
  const RgbImage a = r.render(f);
  const RgbImage b = r.render(f);
  EXPECT_EQ(a.rgb, b.rgb);
  FrameRenderer r2(style);
  EXPECT_EQ(r2.render(f).rgb, a.rgb);
}

TEST(FrameRenderer, StrainRateUsesLogScale) {
  // strain rate = 10^(4 x / W - 3): on a log scale over [1e-3, 10] the colour index is linear in x.
  FrameStyle style;
  style.field = "strain_rate";
  style.range = {1e-3, 10.0, true};
  FieldFrame f = test_frame();
  f.bodies.clear();
  FrameRenderer r(style);
  const RgbImage img = r.render(f);
  dump(img, "strain_rate");
  const FrameLayout& L = r.layout();
  const Colormap& cmap = load_colormap("magma");  // default for strain rate
  const int y = int(L.to_pixel({0.0, 0.5 * kSurface}).y());
  int checked = 0;
  for (int x = int(std::ceil(L.bed_x0)) + 1; x < int(L.bed_x1) - 1; x += 7) {
    const double x_m = (x + 0.5 - L.bed_x0) / L.px_per_m;
    const double cell_x = (std::floor(x_m / kDx) + 0.5) * kDx;
    const double expect = std::min(255.0, std::floor(256.0 * (cell_x / (kNx * kDx))));
    double dist = 0;
    EXPECT_NEAR(cmap.nearest_index(img.at(x, y), &dist), expect, 2.0) << "x = " << x_m << " m";
    EXPECT_LE(dist, 3.0);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(FrameRenderer, ForcePanelGrowsWithTime) {
  FrameStyle style;
  style.field = "pressure";
  style.range = {0.0, max_pressure(), false};
  ForcePanel panel;
  ForceSeries s;
  s.label = "plate";
  for (int k = 0; k <= 100; ++k) {
    s.t_s.push_back(0.01 * k);
    s.x.push_back(1.0 * k);              // mm
    s.y.push_back(50.0 * std::sqrt(k));  // N/m
  }
  panel.series.push_back(s);
  style.panel = panel;
  FrameRenderer r(style);
  FieldFrame f = test_frame();
  const FrameLayout& L = r.layout();
  auto series_pixels = [&](const RgbImage& img) {
    int n = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = L.panel_x0; x < L.panel_x1; ++x) {
        const uint8_t* p = img.at(x, y);
        n += std::abs(p[0] - 31) < 40 && std::abs(p[1] - 92) < 40 && std::abs(p[2] - 180) < 40 && p[2] > p[0] + 80;
      }
    return n;
  };
  // at and before the first sample the curve is a single point: drawn silently
  for (double t : {-0.1, 0.0}) {
    f.time_s = t;
    const std::string noise = test::capture_output([&] { r.render(f); });
    EXPECT_FALSE(test::mentions_gl_trouble(noise) || noise.find("ERR") != std::string::npos) << noise;
  }
  f.time_s = 0.2;
  const RgbImage early = r.render(f);
  f.time_s = 0.9;
  const RgbImage late = r.render(f);
  dump(late, "panel");
  ASSERT_GT(L.panel_x1, L.panel_x0);
  // the bed is still drawn with its aspect ratio in the narrower field area
  EXPECT_LE(L.bed_x1, L.panel_x0);
  EXPECT_NEAR((L.bed_x1 - L.bed_x0) / (L.bed_y1 - L.bed_y0), 0.4 / 0.25, 1e-9);
  const int n_early = series_pixels(early), n_late = series_pixels(late);
  EXPECT_GT(n_early, 50);
  EXPECT_GT(n_late, n_early + 100) << "the curve must extend as time advances";
}

// A steady drag of 19 N/m with a start-up impulse of 114 N/m in its first step (cylinder_drag's
// trace): the axis fits the trace and names the impulse; a trace that rises to its end, or one of
// too few samples for a percentile, keeps all of it in view.
TEST(FrameRenderer, ForceAxisFitsTheTraceNotAStartUpImpulse) {
  auto panel_of = [](std::vector<double> y) {
    ForcePanel panel;
    ForceSeries s;
    for (size_t k = 0; k < y.size(); ++k) s.x.push_back(0.01 * double(k)), s.t_s.push_back(1e-3 * double(k));
    s.y = std::move(y);
    panel.series.push_back(s);
    return panel;
  };
  std::vector<double> steady(2000);
  for (size_t k = 0; k < steady.size(); ++k) steady[k] = 19.0 + std::sin(0.1 * double(k));
  steady[0] = 114.0;
  const ForceAxes a = force_panel_axes(panel_of(steady));
  EXPECT_EQ(a.clipped_hi, 114.0);
  EXPECT_TRUE(std::isnan(a.clipped_lo));
  EXPECT_EQ(a.y_lo, 0.0);                    // a resisting force's axis starts at zero
  EXPECT_GT(a.y_hi, 20.0);                   // the whole steady trace in view
  EXPECT_LT(a.y_hi, 0.5 * 114.0);            // the axis ends under half the impulse
  EXPECT_NEAR(a.x_hi, 0.01 * 1999, 1e-12);

  std::vector<double> rising(2000);
  for (size_t k = 0; k < rising.size(); ++k) rising[k] = 50.0 * std::sqrt(double(k));
  const ForceAxes b = force_panel_axes(panel_of(rising));
  EXPECT_TRUE(std::isnan(b.clipped_hi));
  EXPECT_GE(b.y_hi, rising.back());

  std::vector<double> few(100, 19.0);
  few[0] = 114.0;
  const ForceAxes c = force_panel_axes(panel_of(few));
  EXPECT_TRUE(std::isnan(c.clipped_hi));
  EXPECT_GE(c.y_hi, 114.0);
}

TEST(FrameRenderer, RejectsUnknownFieldListingValidOnes) {
  FrameStyle style;
  style.field = "temperature";
  try {
    FrameRenderer r(style);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("pressure"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("temperature"), std::string::npos) << e.what();
  }
}

TEST(FrameRenderer, RangeAccumulatorUsesActiveCellsAndLogFloor) {
  const FieldFrame f = test_frame();
  RangeAccumulator p("pressure");
  p.add(f);
  const FieldRange rp = p.range();
  EXPECT_FALSE(rp.log);
  // cell centres: shallowest 1.25 mm deep, deepest 198.75 mm
  EXPECT_NEAR(rp.lo, test::kRhoBulk_kg_m3 * test::kG_m_s2 * 0.5 * kDx, 1e-2);
  EXPECT_NEAR(rp.hi, test::kRhoBulk_kg_m3 * test::kG_m_s2 * (kSurface - 0.5 * kDx), 1e-1);
  RangeAccumulator s("strain_rate");
  s.add(f);
  const FieldRange rs = s.range();
  EXPECT_TRUE(rs.log);
  EXPECT_NEAR(std::log10(rs.hi), 4.0 * (kNx - 0.5) / kNx - 3.0, 1e-5);
  EXPECT_NEAR(std::log10(rs.lo), 4.0 * 0.5 / kNx - 3.0, 1e-5);  // above hi/1e4, so the data minimum
  RangeAccumulator v("velocity");
  v.add(f);
  // |(0.03, -0.04)| = 0.05 everywhere: a flat field gets a +-5% range so it still maps
  EXPECT_NEAR(v.range().lo, 0.0475, 1e-6);
  EXPECT_NEAR(v.range().hi, 0.0525, 1e-6);
  // A few extreme cells (here 5 of 12800, < 0.5%) do not set the range; the exact range sees them.
  FieldFrame spiky = f;
  for (int i = 0; i < 5; ++i) spiky.scalars["pressure"][spiky.index(70 + i, 40)] = 1e9f;
  RangeAccumulator ps("pressure");
  ps.add(spiky);
  EXPECT_NEAR(ps.range().hi, rp.hi, 1e-1);
  EXPECT_FLOAT_EQ(float(ps.exact_range().hi), 1e9f);
  EXPECT_EQ(colorbar_title("pressure", false), "Pressure (Pa)");
  EXPECT_EQ(colorbar_title("packing_fraction", false), "Packing fraction");
  EXPECT_EQ(colorbar_title("velocity", false), "Velocity magnitude (m/s)");
}

TEST(FrameRenderer, ColorbarTicksSitAtRoundValuesInKilopascal) {
  // 0..2967 Pa: ticks every 0.5 kPa, each where the bar shows that value's colour, text under each
  FrameStyle style;
  style.field = "pressure";
  style.range = {0.0, max_pressure(), false};
  FrameRenderer r(style);
  const RgbImage img = r.render(test_frame());
  dump(img, "colorbar_ticks");
  const FrameLayout& L = r.layout();
  EXPECT_EQ(L.colorbar_unit, "kPa");
  std::vector<std::string> labels;
  for (const auto& t : L.colorbar_ticks) labels.push_back(t.label);
  EXPECT_EQ(labels, (std::vector<std::string>{"0", "0.5", "1.0", "1.5", "2.0", "2.5"}));
  const Colormap& cmap = load_colormap("viridis");
  const int y_bar = (L.colorbar_bar_y0 + L.colorbar_bar_y1) / 2;
  for (const auto& t : L.colorbar_ticks) {
    const int x = std::clamp(int(std::lround(t.x_px)), L.colorbar_x0 + 1, L.colorbar_x1 - 2);
    double dist = 0;
    const int idx = cmap.nearest_index(img.at(x, y_bar), &dist);
    EXPECT_LE(dist, 3.0) << t.label;
    EXPECT_NEAR(idx, std::min(255.0, 256.0 * t.value / max_pressure()), 2.0) << t.label;
    // a dark tick mark just under the bar and label text centred under it
    int dark = 0;
    for (int y = L.colorbar_bar_y1; y < L.colorbar_y1; ++y)
      for (int xx = x - 12; xx <= x + 12; ++xx) dark += img.at(xx, y)[0] < 90 && img.at(xx, y)[2] < 90;
    EXPECT_GT(dark, 15) << t.label;
  }
  // between two ticks, under the bar: no text
  const int gap_x = int(0.5 * (L.colorbar_ticks[1].x_px + L.colorbar_ticks[2].x_px));
  int dark_gap = 0;
  for (int y = L.colorbar_bar_y1; y < L.colorbar_y1; ++y)
    for (int x = gap_x - 10; x <= gap_x + 10; ++x) dark_gap += img.at(x, y)[0] < 90 && img.at(x, y)[2] < 90;
  EXPECT_EQ(dark_gap, 0);
  // the title reads in the labels' unit
  EXPECT_EQ(colorbar_title("pressure", false, L.colorbar_unit), "Pressure (kPa)");
}

TEST(FrameRenderer, LogColorbarHasDecadeTicks) {
  FrameStyle style;
  style.field = "strain_rate";
  style.range = {1e-3, 10.0, true};
  FrameRenderer r(style);
  r.render(test_frame());
  const FrameLayout& L = r.layout();
  ASSERT_EQ(L.colorbar_ticks.size(), 5u);
  const double bar_w = L.colorbar_x1 - L.colorbar_x0;
  for (size_t k = 0; k < 5; ++k) {
    EXPECT_NEAR(L.colorbar_ticks[k].value, std::pow(10.0, double(k) - 3.0), 1e-12);
    EXPECT_NEAR(L.colorbar_ticks[k].x_px, L.colorbar_x0 + bar_w * double(k) / 4.0, 1e-6);  // evenly spaced
  }
  EXPECT_EQ(L.colorbar_ticks[0].label, "0.001");
  EXPECT_EQ(L.colorbar_ticks[4].label, "10");
  EXPECT_EQ(L.colorbar_unit, "1/s");
}

TEST(FrameRenderer, SmoothDisplayStaysInsideTheMaterialAndRemovesTheStaircase) {
  // a stored frame in coarse 1 cm cells whose free surface slopes: material only below it
  FieldFrame f = test::hydrostatic_frame(40, 25, 0.01, 0.2);
  for (int j = 0; j < f.ny; ++j)
    for (int i = 0; i < f.nx; ++i)
      if ((j + 0.5) * 0.01 > 0.1 + 0.25 * (i + 0.5) * 0.01) {
        f.active[f.index(i, j)] = 0;
        f.scalars["pressure"][f.index(i, j)] = 0.f;
      }
  const std::string path =
      (std::filesystem::temp_directory_path() / ("furrow_smooth_" + std::to_string(::getpid()) + ".vdb")).string();
  write_frame_vdb(path, f);
  const FieldFrame stored = read_frame(path);
  std::filesystem::remove(path);
  const std::vector<float> stored_pressure = stored.scalars.at("pressure");

  FrameStyle style;
  style.field = "pressure";
  style.width = 960, style.height = 540;
  style.range = {0.0, max_pressure(), false};
  style.smooth = false;
  FrameRenderer flat_r(style);
  style.smooth = true;
  FrameRenderer smooth_r(style);
  const RgbImage flat = flat_r.render(stored), smooth = smooth_r.render(stored);
  dump(smooth, "smooth");
  EXPECT_EQ(stored.scalars.at("pressure"), stored_pressure);  // display only
  const FrameLayout& L = smooth_r.layout();
  const double cell_px = L.px_per_m * 0.01;
  ASSERT_GT(cell_px, 8.0);
  const Colormap& cmap = load_colormap("viridis");
  // the cell under a pixel centre; `clear`: whether the pixel lies more than half a cell and 1.5 px
  // from every cell of the other kind (material / none): the smoothed surface may move by up to half
  // a cell from the cells' outline, no more
  auto cell_of = [&](int x, int y, bool* clear) -> long {
    const double cx = (x + 0.5 - L.bed_x0) / cell_px, cy = (L.bed_y1 - y - 0.5) / cell_px;
    if (cx <= 0 || cy <= 0 || cx >= f.nx || cy >= f.ny) return -1;
    const long c = long(stored.index(int(cx), int(cy)));
    const uint8_t kind = stored.active[size_t(c)];
    double d = 1e9;  // in cells, to the nearest cell of the other kind
    for (int j = int(cy) - 2; j <= int(cy) + 2; ++j)
      for (int i = int(cx) - 2; i <= int(cx) + 2; ++i) {
        if (i < 0 || j < 0 || i >= f.nx || j >= f.ny || stored.active[stored.index(i, j)] == kind) continue;
        const double ex = std::max({i - cx, 0.0, cx - (i + 1)}), ey = std::max({j - cy, 0.0, cy - (j + 1)});
        d = std::min(d, std::hypot(ex, ey));
      }
    *clear = d > 0.5 + 1.5 / cell_px;
    return c;
  };
  // a cell whose 8 neighbours all hold material (away from the free surface)
  auto deep_inside = [&](long c) {
    const int i = int(c % f.nx), j = int(c / f.nx);
    for (int b = -1; b <= 1; ++b)
      for (int a = -1; a <= 1; ++a) {
        const int ii = std::clamp(i + a, 0, f.nx - 1), jj = std::clamp(j + b, 0, f.ny - 1);
        if (!stored.active[stored.index(ii, jj)]) return false;
      }
    return true;
  };
  int outside_material = 0, empty_checked = 0, material_checked = 0, pairs = 0;
  double sq_flat = 0, sq_smooth = 0;
  for (int y = int(L.bed_y0); y + 1 < int(L.bed_y1); ++y)
    for (int x = int(L.bed_x0); x < int(L.bed_x1); ++x) {
      bool clear = false, unused = false;
      const long c = cell_of(x, y, &clear);
      if (c < 0) continue;
      if (clear && !stored.active[size_t(c)]) {
        ++empty_checked;
        outside_material += !near_rgb(smooth.at(x, y), style.empty_rgb, 1);
      }
      if (clear && stored.active[size_t(c)]) {
        ++material_checked;
        double d = 0;
        cmap.nearest_index(smooth.at(x, y), &d);
        EXPECT_LE(d, 3.0) << "not a colormap colour at (" << x << ", " << y << ")";
      }
      // vertical neighbours inside the material, across cell edges too (the field varies with depth)
      const long below = cell_of(x, y + 1, &unused);
      if (below < 0 || !deep_inside(c) || !deep_inside(below)) continue;
      const int s0 = cmap.nearest_index(smooth.at(x, y)), s1 = cmap.nearest_index(smooth.at(x, y + 1));
      const int f0 = cmap.nearest_index(flat.at(x, y)), f1 = cmap.nearest_index(flat.at(x, y + 1));
      sq_smooth += double(s1 - s0) * (s1 - s0);
      sq_flat += double(f1 - f0) * (f1 - f0);
      ++pairs;
    }
  EXPECT_GT(empty_checked, 10000);
  EXPECT_GT(material_checked, 20000);
  EXPECT_GT(pairs, 20000);
  EXPECT_EQ(outside_material, 0) << "smoothed colour outside the material mask";
  // per-cell colours jump ~13 indices at each cell row and not between; the blend ~1 per pixel
  // row: the mean squared jump drops by about the pixels per cell
  EXPECT_GT(sq_flat, 4.0 * sq_smooth) << "mean squared jump, flat " << sq_flat / pairs << ", smooth " << sq_smooth / pairs;
}

// A body that turns and sinks: its torque and depth against time in two charts under the force
// chart, in the colour of its force trace; the depth trace reaches further down as time goes on.
// Rows only for the inspector (speed, angle) leave the panel as the force chart alone.
TEST(FrameRenderer, PanelRowsDrawTorqueAndDepthUnderTheForceChart) {
  FrameStyle style;
  style.field = "pressure";
  style.range = {0.0, max_pressure(), false};
  ForcePanel panel;
  ForceSeries s, torque, depth;
  s.label = torque.label = depth.label = "wheel";
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.01 * k;
    for (ForceSeries* f : {&s, &torque, &depth}) f->t_s.push_back(t);
    s.x.push_back(1.0 * k), s.y.push_back(20.0 + std::sin(0.3 * k));
    torque.x.push_back(t), torque.y.push_back(-0.5 * std::sqrt(t));
    depth.x.push_back(t), depth.y.push_back(12.0 * t);  // mm
  }
  panel.series.push_back(s);
  panel.rows.push_back({"speed", "speed (m/s)", false, {torque}});
  style.panel = panel;
  FieldFrame f = test_frame();
  f.time_s = 0.9;
  // inspector-only rows: the same image as without them
  FrameStyle plain = style;
  plain.panel->rows.clear();
  FrameRenderer r_plain(plain), r_speed(style);
  const RgbImage a = r_plain.render(f), b = r_speed.render(f);
  EXPECT_TRUE(r_speed.layout().panel_rows.empty());
  EXPECT_EQ(a.rgb, b.rgb) << "rows not drawn in movies must leave the panel as it was";

  style.panel->rows = {{"torque", "torque (N m/m)", true, {torque}}, {"depth", "depth below start (mm)", true, {depth}},
                       {"angle", "angle (deg)", false, {torque}}};
  FrameRenderer r(style);
  const FrameLayout& L = r.layout();
  // rows of blue (the first trace's colour) pixels inside one row chart: count, top and bottom
  struct Extent { int n = 0, top = 1 << 30, bottom = -1; };
  auto blue = [&](const RgbImage& img, const std::array<int, 4>& box) {
    Extent e;
    for (int y = box[1]; y < box[3]; ++y)
      for (int x = box[0]; x < box[2]; ++x) {
        const uint8_t* p = img.at(x, y);
        if (std::abs(p[0] - 31) < 40 && std::abs(p[1] - 92) < 40 && std::abs(p[2] - 180) < 40 && p[2] > p[0] + 80)
          ++e.n, e.top = std::min(e.top, y), e.bottom = std::max(e.bottom, y);
      }
    return e;
  };
  f.time_s = 0.2;
  const RgbImage early = r.render(f);
  f.time_s = 0.9;
  const RgbImage late = r.render(f);
  dump(late, "panel_rows");
  ASSERT_EQ(L.panel_rows.size(), 2u);
  for (const auto& box : L.panel_rows) {
    EXPECT_GE(box[0], L.panel_x0);
    EXPECT_LE(box[2], L.panel_x1);
    EXPECT_GT(box[3] - box[1], late.height / 6);
  }
  EXPECT_LT(L.panel_rows[0][3], L.panel_rows[1][1] + 2) << "torque above depth";
  const Extent tq = blue(late, L.panel_rows[0]), d_early = blue(early, L.panel_rows[1]), d_late = blue(late, L.panel_rows[1]);
  EXPECT_GT(tq.n, 50);
  EXPECT_GT(d_early.n, 30);
  EXPECT_GT(d_late.n, d_early.n + 50) << "the depth trace must extend as time advances";
  // depth grows downwards on the chart's upward axis: the late trace spans more rows of pixels
  EXPECT_GT(d_late.bottom - d_late.top, (d_early.bottom - d_early.top) + 20);
  // the force chart above still draws its trace
  EXPECT_GT(blue(late, {L.panel_x0, 0, L.panel_x1, L.panel_rows[0][1]}).n, 50);
}

// The rows from a real run rather than made-up series: the wheel template coarsened to dx 6 mm and
// 0.15 s (under a second). Its forces.csv and scene.json give torque and depth rows for the movie
// (the wheel turns and its y is free) and speed and angle for the inspector; the driven wheel's
// torque (~0.3 N m/m) is signal, far above the row's floor; the wheel sinks; a stored frame drawn
// with that panel shows both traces in the wheel's colour. At 4 kg/m, the template's load until
// 2026-12-07, so that it sinks well past the bound by 0.15 s (at the template's 2 kg/m, 0.29 mm).
TEST(FrameRenderer, AWheelRunsPanelDrawsItsTorqueAndDepthRows) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("furrow_wheel_rows_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const Scene scene = parse_scene_text(find_scene_template("wheel")->text, "<template wheel>",
                                       {"domain.dx_m=0.006", "solver.end_time_s=0.15", "outputs.frame_interval_s=0.05",
                                        "outputs.force_interval_s=0.005", "outputs.average_window.from_s=0",
                                        "outputs.average_window.to_s=0.15", "solver.threads=1",
                                        "bodies.0.mass_kg_per_m=4.0"});
  RunOptions options;
  options.out_dir = dir.string();
  options.write_paraview = false;
  run_scene(scene, options);

  const ForcePanel panel = read_force_panel((dir / "forces.csv").string());
  ASSERT_EQ(panel.rows.size(), 4u);
  EXPECT_EQ(panel.rows[0].key, "torque");
  EXPECT_EQ(panel.rows[1].key, "depth");
  EXPECT_TRUE(panel.rows[0].movie && panel.rows[1].movie);
  EXPECT_FALSE(panel.rows[2].movie || panel.rows[3].movie);
  double torque_max = 0.0;
  for (double t : panel.rows[0].series[0].y) torque_max = std::max(torque_max, std::abs(t));
  EXPECT_GT(torque_max, 10.0 * panel.rows[0].y_floor);
  EXPECT_GT(panel.rows[1].series[0].y.back(), 0.5);  // mm below its start

  FrameStyle style;
  style.field = "pressure";
  style.range = {0.0, 2000.0, false};
  style.panel = panel;
  FieldFrame f = read_frame(frame_path(dir.string(), 3));
  FrameRenderer r(style);
  const RgbImage img = r.render(f);
  dump(img, "wheel_rows");
  const FrameLayout& L = r.layout();
  ASSERT_EQ(L.panel_rows.size(), 2u);
  for (const auto& box : L.panel_rows) {
    int n = 0;
    for (int y = box[1]; y < box[3]; ++y)
      for (int x = box[0]; x < box[2]; ++x) {
        const uint8_t* p = img.at(x, y);
        n += std::abs(p[0] - 31) < 40 && std::abs(p[1] - 92) < 40 && std::abs(p[2] - 180) < 40 && p[2] > p[0] + 80;
      }
    EXPECT_GT(n, 30) << "row " << box[1];
  }
  fs::remove_all(dir);
}
