// The shared checker can fail: each of its bounds, fed a state that breaks it by a little, says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include "tests/stability/stability_check.hpp"
#include "tests/stability/stability_scenes.hpp"

using namespace furrow;
using namespace furrow::stability;

namespace {

// A 40 mm column 0.1 m above the floor, with a 20 mm plate held still beside it.
Scene falling_column() {
  Scene s = bed(0.16, 0.04, 0.2, 0.005, 1.0);
  s.beds[0].min_m = Vec2(0.06, 0.1);
  s.beds[0].max_m = Vec2(0.1, 0.14);
  s.beds[0].geostatic = false;
  s.bodies.push_back(box("plate", Vec2(0.02, 0.02), Vec2(0.13, 0.05), Vec2(0.0, 0.0)));
  return s;
}

// Runs `steps` clean steps, then one more whose result `tamper` edits before the checker sees it.
::testing::AssertionResult tampered(int steps, const std::function<void(Simulation&)>& tamper) {
  Simulation sim(falling_column());
  Checker check(sim);
  for (int k = 0; k < steps; ++k) {
    check.before_step(sim);
    sim.step();
    if (auto r = check.after_step(sim, true); !r) return ::testing::AssertionFailure() << "clean step failed: " << r.message();
  }
  check.before_step(sim);
  sim.step();
  tamper(sim);
  return check.after_step(sim, true);
}

void expect_caught(const ::testing::AssertionResult& r, const std::string& what) {
  EXPECT_FALSE(r);
  EXPECT_NE(std::string(r.message()).find(what), std::string::npos) << r.message();
}

}  // namespace

TEST(Checker, PassesTheUntamperedRun) { EXPECT_TRUE(tampered(200, [](Simulation&) {})); }

TEST(Checker, CatchesEnergyFromNowhere) {
  // in free fall KE equals the work of gravity; 1% more speed is 2% more energy than was put in
  expect_caught(tampered(200, [](Simulation& sim) {
                  auto& p = sim.mutable_particles();
                  for (size_t i = 0; i < p.size(); ++i) p.vy[i] *= 1.01;
                }),
                "kinetic energy");
}

TEST(Checker, CatchesNonFiniteValues) {
  expect_caught(tampered(10, [](Simulation& sim) { sim.mutable_particles().sxy[7] = std::nan(""); }), "sxy");
  expect_caught(tampered(10, [](Simulation& sim) {
                  sim.mutable_particles().c10[3] = std::numeric_limits<double>::infinity();
                }),
                "c10");
}

TEST(Checker, CatchesMassChangeAndEscape) {
  // one point's mass up by 1e-10, or by one unit in the last place where the stored precision
  // (float by default, engine/simulation.hpp) cannot hold a change that small
  expect_caught(tampered(10, [](Simulation& sim) {
                  auto& m = sim.mutable_particles().mass[0];
                  using T = std::decay_t<decltype(m)>;
                  m = std::max(T(double(m) * (1.0 + 1e-10)), std::nextafter(m, T(2) * m));
                }),
                "mass");
  expect_caught(tampered(10, [](Simulation& sim) { sim.mutable_particles().x[5] = -0.3 * 0.005; }), "outside");
}

TEST(Checker, CatchesAPointDeepInsideABody) {
  // the plate's left face is at x = 0.12; put a point 0.3 cells inside it
  expect_caught(tampered(10, [](Simulation& sim) {
                  auto& p = sim.mutable_particles();
                  p.x[5] = 0.12 + 0.3 * 0.005;
                  p.y[5] = 0.05;
                }),
                "inside a body");
}
