// The front and back walls of a quasi-2D channel (walls.front_back): Coulomb friction
// 2 mu |sigma_zz| / gap per unit volume against the in-plane motion.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "engine/analysis.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"

using namespace furrow;

namespace {

// The collapse template in plane strain (it has side walls of its own): each test adds the walls it needs.
Scene collapse(std::vector<std::string> sets) {
  sets.insert(sets.begin(), {"domain.dx_m=0.008", "walls.front_back=null", "outputs.fields=[]", "outputs.movies=[]"});
  return load_scene((std::filesystem::path(FURROW_SOURCE_DIR) / "scenes" / "column_collapse.json").string(), sets);
}

double runout(const Scene& s) {
  Simulation sim(s);
  while (!sim.finished()) sim.step();
  return measure_collapse(sim.particle_view(), collapse_geometry(s), sim.time_s()).front_m / s.beds[0].max_m.x() - 1.0;
}

}  // namespace

// Momentum: with a slip floor, the media's horizontal momentum changes in a step by what the side
// walls and the front/back walls took, to round-off (transfers conserve momentum exactly).
TEST(FrontBackWalls, MomentumChangesByTheirImpulseToRoundOff) {
  Scene s = collapse({"walls.bottom={\"type\":\"slip\"}", R"(walls.front_back={"gap_m":0.05,"friction":0.4})"});
  Simulation sim(s);
  for (size_t p = 0; p < sim.particles().size(); ++p) sim.mutable_particles().vx[p] = 0.3;
  double taken = 0.0, worst = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const double before = sim.total_momentum().x();
    sim.step();
    double walls_x = 0.0;
    for (const Vec2& f : sim.wall_forces()) walls_x -= f.x() * sim.last_dt_s();
    const double fb = sim.stats().front_back_impulse_N_s_per_m.x();
    taken += fb;
    worst = std::max(worst, std::abs(sim.total_momentum().x() - before - walls_x - fb));
  }
  const double p0 = sim.total_mass() * 0.3;
  std::printf("front/back walls took %.4g of %.4g N s/m; worst step imbalance %.3g\n", -taken, p0, worst);
  EXPECT_LT(taken, -0.05 * p0);   // they did act
  EXPECT_LT(worst, 1e-12 * p0);   // and nothing else did
}

// A released column runs out less in a narrower channel; friction 0 is plane strain exactly.
TEST(FrontBackWalls, NarrowerChannelShortensTheRunout) {
  const double none = runout(collapse({}));
  const double wide = runout(collapse({R"(walls.front_back={"gap_m":0.2,"friction":0.3})"}));
  const double narrow = runout(collapse({R"(walls.front_back={"gap_m":0.05,"friction":0.3})"}));
  const double frictionless = runout(collapse({R"(walls.front_back={"gap_m":0.05,"friction":0})"}));
  std::printf("runout (Lf - L0)/L0: plane strain %.3f, gap 0.2 m %.3f, gap 0.05 m %.3f, frictionless %.3f\n", none,
              wide, narrow, frictionless);
  EXPECT_LT(wide, none);
  EXPECT_LT(narrow, 0.95 * wide);
  EXPECT_EQ(frictionless, none);
}

TEST(FrontBackWalls, SceneKeysRoundTripAndAreChecked) {
  const Scene s = collapse({R"(walls.front_back={"gap_m":0.05,"friction":0.3})"});
  EXPECT_DOUBLE_EQ(s.walls.front_back.gap_m, 0.05);
  EXPECT_DOUBLE_EQ(s.walls.front_back.friction, 0.3);
  const Scene back = parse_scene_text(format_scene(s), "<written>");
  EXPECT_DOUBLE_EQ(back.walls.front_back.gap_m, 0.05);
  EXPECT_DOUBLE_EQ(back.walls.front_back.friction, 0.3);
  EXPECT_FALSE(collapse({}).walls.front_back.present());
  EXPECT_NE(format_scene(collapse({})).find("\"front_back\": null"), std::string::npos);  // plane strain
  for (const char* bad : {R"(walls.front_back={"gap_m":0,"friction":0.3})", R"(walls.front_back={"gap_m":0.05})",
                          R"(walls.front_back={"gap_m":0.05,"friction":-1})", R"(walls.front_back={"gap":0.05,"friction":0.3})"}) {
    try {
      collapse({bad});
      ADD_FAILURE() << bad << " was accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("/walls/front_back"), std::string::npos) << e.what();
    }
  }
}
