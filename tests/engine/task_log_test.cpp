// The task log behind `furrow bench --ceiling`: its schedule, and that timing a run's tasks
// changes none of its results.
#include <gtest/gtest.h>

#include <vector>

#include "engine/simulation.hpp"
#include "engine/task_log.hpp"
#include "tests/engine/test_scenes.hpp"

using namespace furrow;

// List scheduling, each task in order to the thread free first: the makespans worked by hand.
TEST(TaskLog, ListScheduleSharesTasksInOrderToTheFirstFreeThread) {
  EXPECT_DOUBLE_EQ(list_schedule_s({3, 1, 1, 1}, 1), 6.0);
  EXPECT_DOUBLE_EQ(list_schedule_s({3, 1, 1, 1}, 2), 3.0);  // 3 | 1 + 1 + 1
  EXPECT_DOUBLE_EQ(list_schedule_s({4, 1, 1}, 2), 4.0);  // 4 | 1 + 1
  EXPECT_DOUBLE_EQ(list_schedule_s({1, 1, 4}, 2), 5.0);  // 1 + 4 | 1: the order counts
  EXPECT_DOUBLE_EQ(list_schedule_s({2, 2, 2}, 2), 4.0);
  EXPECT_DOUBLE_EQ(list_schedule_s(std::vector<double>(8, 1.0), 16), 1.0);
  EXPECT_DOUBLE_EQ(list_schedule_s({}, 4), 0.0);
}

// A run with its tasks timed, with the bands split as for sixteen threads, keeps an untimed run's
// bits at every step; the log holds every region of the default path (P2G, one grid update with
// the bands, one G2P pass a step) with their tasks' seconds, which sum to no more than
// the regions' wall time on one thread.
TEST(TaskLog, TimingTheTasksChangesNoResult) {
  Scene s = test_scenes::bed_scene(0.4, 0.1, 0.03, 0.005, 1.0);
  s.bodies.push_back(test_scenes::plate(0.1, 0.01, 0.2, 0.101, Vec2(0.0, -0.2)));
  s.solver.threads = 1;
  Simulation plain(s), timed(s);
  TaskLog log;
  log.plan_threads = 16;
  timed.set_task_log(&log);
  const int steps = 100;
  int steps_differ = 0;
  for (int k = 0; k < steps; ++k) {
    plain.step();
    timed.step();
    steps_differ += plain.bodies()[0].force_N_per_m != timed.bodies()[0].force_N_per_m;
  }
  EXPECT_NE(plain.bodies()[0].force_N_per_m.y(), 0.0);
  EXPECT_EQ(steps_differ, 0);
  EXPECT_EQ(plain.particles().x, timed.particles().x);
  const auto& p2g = log.phases[size_t(StepPhase::P2G)];
  const auto& grid = log.phases[size_t(StepPhase::Grid)];
  const auto& g2p = log.phases[size_t(StepPhase::G2PConstitutive)];
  EXPECT_EQ(p2g.regions, steps);
  EXPECT_EQ(grid.regions, steps);
  EXPECT_EQ(g2p.regions, steps);
  EXPECT_EQ(g2p.tasks % steps, 0);  // the same tasks every step
  EXPECT_GT(g2p.tasks / steps, 1);
  EXPECT_GT(log.phases[size_t(StepPhase::Reorder)].regions, 0);
  for (const auto& phase : log.phases) {
    EXPECT_LE(phase.shared_s[0], phase.region_wall_s);
    for (size_t k = 1; k < TaskLog::kThreads.size(); ++k) EXPECT_LE(phase.shared_s[k], phase.shared_s[k - 1]);
  }
}
