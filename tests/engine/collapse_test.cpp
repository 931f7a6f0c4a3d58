// Column collapse (issue 16): the runout analysis run.json reports, and the template's runout
// against the laws of quasi-2D experiments between side walls (Lube et al. 2005; Lajeunesse et al.
// 2005: (Lf - L0) / L0 = 1.2a to 1.8a for a up to about 2-3).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "engine/analysis.hpp"
#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"
#include "tests/engine/test_scenes.hpp"

using namespace furrow;

namespace {

Scene collapse_template(std::vector<std::string> sets) {
  sets.push_back("outputs.fields=[]");
  sets.push_back("outputs.movies=[]");
  return load_scene((std::filesystem::path(FURROW_SOURCE_DIR) / "scenes" / "column_collapse.json").string(), sets);
}

// The test resolution: dx 4 mm, a quarter of the template's cost per step and half its steps (the
// template's 2 mm is where the runout has converged; 4 mm runs 5-7% shorter, tests/README.md).
const std::string kTestDx = "domain.dx_m=0.004";
// A column twice as tall as wide in a domain that holds its runout. The fronts stop by 0.44 s
// (a = 1) and 0.58 s (a = 2) at this dx; `settled` checks that the runs were long enough.
const std::vector<std::string> kOnce = {kTestDx, "solver.end_time_s=0.5"};
const std::vector<std::string> kTwice = {kTestDx, "beds.0.max_m=[0.1,0.2]", "domain.height_m=0.25",
                                         "domain.width_m=0.6", "solver.end_time_s=0.65"};

nlohmann::json run_collapse(const Scene& s) {
  Simulation sim(s);
  CollapseAnalysis c(s);
  c.add_step(0.0, sim.particle_view());
  while (!sim.finished()) {
    sim.step();
    c.add_step(sim.time_s(), sim.particle_view());
  }
  c.add_step(sim.time_s(), sim.particle_view(), true);
  return c.to_json();
}

// Points on a lattice of spacing h filling [x0, x0 + L] x [0, H].
struct Cloud {
  std::vector<double> x, y, v;
  ParticleView view() const {
    ParticleView p;
    p.count = x.size();
    p.x_m = x.data();
    p.y_m = y.data();
    p.volume_m2 = v.data();
    return p;
  }
};
Cloud lattice(double x0, double L, double H, double h) {
  Cloud c;
  for (double y = 0.5 * h; y < H; y += h)
    for (double x = x0 + 0.5 * h; x < x0 + L; x += h) c.x.push_back(x), c.y.push_back(y), c.v.push_back(h * h);
  return c;
}

}  // namespace

TEST(CollapseGeometry, TheBackIsTheWallTheColumnTouches) {
  const Scene s = collapse_template({});
  const CollapseGeometry g = collapse_geometry(s);
  ASSERT_TRUE(g.active);
  EXPECT_EQ(g.side, 1);
  EXPECT_DOUBLE_EQ(g.back_x_m, 0.0);
  EXPECT_DOUBLE_EQ(g.L0_m, 0.1);
  EXPECT_DOUBLE_EQ(g.H0_m, 0.1);

  Scene right = s;  // mirrored: against the right wall, spreading toward -x
  right.beds[0].min_m.x() = s.domain.width_m - 0.1;
  right.beds[0].max_m.x() = s.domain.width_m;
  const CollapseGeometry gr = collapse_geometry(right);
  EXPECT_EQ(gr.side, -1);
  EXPECT_DOUBLE_EQ(gr.back_x_m, s.domain.width_m);

  Scene middle = s;  // free on both sides: half-widths from the centre line
  middle.beds[0].min_m.x() = 0.2;
  middle.beds[0].max_m.x() = 0.3;
  const CollapseGeometry gm = collapse_geometry(middle);
  EXPECT_EQ(gm.side, 0);
  EXPECT_DOUBLE_EQ(gm.back_x_m, 0.25);
  EXPECT_DOUBLE_EQ(gm.L0_m, 0.05);

  Scene full = s;  // wall to wall: nothing is released
  full.beds[0].max_m.x() = s.domain.width_m;
  EXPECT_FALSE(collapse_geometry(full).active);
  Scene with_body = test_scenes::bed_scene(0.2, 0.1, 0.03, 0.005, 1.0);
  with_body.beds[0].max_m.x() = 0.1;
  with_body.bodies.push_back(test_scenes::plate(0.04, 0.01, 0.05, 0.11, Vec2(0.0, -0.1)));
  EXPECT_FALSE(collapse_geometry(with_body).active);
}

// An unmoved column measures its own size, and a few grains thrown far ahead do not count.
TEST(CollapseGeometry, FrontAndHeightOfAColumnAtRest) {
  const Scene s = collapse_template({});
  const CollapseGeometry g = collapse_geometry(s);
  const double h = s.domain.dx_m / s.solver.particles_per_cell_1d;  // the seeded spacing
  Cloud c = lattice(0.0, 0.1, 0.1, h);
  CollapseSample m = measure_collapse(c.view(), g, 0.0);
  EXPECT_NEAR(m.front_m, 0.1, 0.01 * 0.1);  // 0.5% of the points lie in the last 0.5% of L0
  EXPECT_NEAR(m.height_m, 0.1, 1e-12);
  const size_t n = c.x.size();
  for (size_t k = 0; k < n / 400; ++k) c.x.push_back(1.0), c.y.push_back(0.5 * h), c.v.push_back(h * h);  // 0.25%
  m = measure_collapse(c.view(), g, 0.0);
  EXPECT_LT(m.front_m, 0.1 * 1.01);
}

// run.json carries the collapse section, sampled at the frame interval and at the end.
TEST(CollapseAnalysis, RunJsonHasTheRunoutSeries) {
  Scene s = collapse_template({"domain.dx_m=0.01", "solver.end_time_s=0.05"});
  s.outputs.frame_interval_s = 0.02;
  const auto dir = std::filesystem::temp_directory_path() / ("furrow_collapse_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  RunOptions opt;
  opt.out_dir = dir.string();
  opt.write_paraview = false;
  const RunSummary r = run_scene(s, opt);
  const auto& c = r.run_json.at("collapse");
  const auto& t = c.at("t_s");
  ASSERT_EQ(t.size(), 4u);  // 0, 0.02, 0.04 and the end
  EXPECT_DOUBLE_EQ(t[0].get<double>(), 0.0);
  EXPECT_NEAR(t[3].get<double>(), 0.05, 1e-3);
  EXPECT_EQ(c.at("front_m").size(), 4u);
  EXPECT_NEAR(c.at("front_m")[0].get<double>(), 0.1, 0.001);
  // the geostatic start is elastically compressed: rho g H0^2 / (2 E) ~ 1.5e-6 m
  EXPECT_NEAR(c.at("height_m")[0].get<double>(), 0.1, 1e-5);
  EXPECT_DOUBLE_EQ(c.at("aspect_ratio").get<double>(), 1.0);
  // the final surface: one point per cell column holding material, its highest the final height
  const auto& xs = c.at("final_surface").at("x_m");
  const auto& hs = c.at("final_surface").at("height_m");
  ASSERT_EQ(xs.size(), hs.size());
  ASSERT_GE(xs.size(), 10u);  // the column was 10 cells wide
  double top = 0.0;
  for (const auto& h : hs) top = std::max(top, h.get<double>());
  EXPECT_DOUBLE_EQ(top, c.at("final_height_m").get<double>());
  std::ifstream in(dir / "run.json");
  EXPECT_EQ(nlohmann::json::parse(in).at("collapse"), c);
  std::filesystem::remove_all(dir);
}

// The template (glass beads, mu(I), rough floor, glass side walls 0.1 m apart) at the test dx,
// a = 1 and 2: the runout lies between the cited laws, 1.2a (Lube et al. 2005) and 1.8a (Lajeunesse
// et al. 2005), and grows linearly with a as they find for a up to about 2-3 (ratio 2; the a^(2/3)
// regime beyond would give 1.59). mu(I) shortens it: the friction rises with the shear rate (at
// I ~ 0.1 by ~0.07, 18% of mu_s). The side walls take 2 mu_w |sigma_zz| / W per unit volume; in
// plane strain the same runs give 1.88 and 4.00, above the upper law (tests/README.md).
TEST(ColumnCollapse, RunoutIsLinearInAspectRatioAndMuIShortensIt) {
  std::vector<std::string> off = kOnce;
  off.push_back("effects.rate_dependence=false");
  const nlohmann::json one = run_collapse(collapse_template(kOnce));
  const nlohmann::json two = run_collapse(collapse_template(kTwice));
  const nlohmann::json no_mu_i = run_collapse(collapse_template(off));
  const double r1 = one.at("runout_relative").get<double>(), r2 = two.at("runout_relative").get<double>(),
               r0 = no_mu_i.at("runout_relative").get<double>();
  std::printf("runout (Lf - L0)/L0: a = 1: %.3f (%.3f without mu(I)), a = 2: %.3f; Hf/H0 %.3f, %.3f\n", r1, r0, r2,
              one.at("final_height_relative").get<double>(), two.at("final_height_relative").get<double>());
  EXPECT_TRUE(one.at("settled").get<bool>());
  EXPECT_TRUE(two.at("settled").get<bool>());
  EXPECT_TRUE(no_mu_i.at("settled").get<bool>());
  ASSERT_DOUBLE_EQ(one.at("aspect_ratio").get<double>(), 1.0);
  ASSERT_DOUBLE_EQ(two.at("aspect_ratio").get<double>(), 2.0);
  // inside the experiments' band at both aspect ratios
  for (const auto& [a, r] : {std::pair{1.0, r1}, std::pair{2.0, r2}}) {
    EXPECT_GE(r, 1.2 * a) << "a = " << a << ": shorter than Lube et al.";
    EXPECT_LE(r, 1.8 * a) << "a = " << a << ": longer than Lajeunesse et al.";
  }
  EXPECT_GT(r2 / r1, 1.8);  // linear: 2 (the a^(2/3) regime: 1.59)
  EXPECT_LT(r2 / r1, 2.3);
  EXPECT_LT(r1, 0.96 * r0);
}
