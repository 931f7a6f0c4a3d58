// Helpers for the paper-claim tests (paper_cases_test.cpp): scenes built in code (so the tests do
// not move when someone retunes a template), runs spread over the cores one simulation per
// thread, force traces against travel and window means (the fits and claim measures:
// paper_claims.hpp).
#pragma once
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "engine/scene/scene.hpp"
#include "engine/simulation.hpp"
#include "tests/engine/paper_claims.hpp"
#include "tests/engine/test_scenes.hpp"

namespace furrow::paper {

constexpr double kRhoG = 2520.0, kPhi = 0.60, kG = 9.81;
constexpr double kRhoD = kRhoG * kPhi;  // 1512 kg/m^3, the paper's rho_d
constexpr double kPi = 3.14159265358979323846;

// A bed filling [0, width] x [0, depth] with air above, slip sides and a rough floor, one thread.
inline Scene bed(double width_m, double depth_m, double air_m, double dx_m, double mu_s) {
  Scene s = test_scenes::bed_scene(test_scenes::glass_beads(mu_s), width_m, depth_m, air_m, dx_m, 100.0, kPhi);
  s.name = "paper_case";  // runs end on end_displacement_m
  s.solver.threads = 1;   // one simulation per core (see run_all)
  return s;
}

inline Body box_body(const char* name, double L_m, double t_m, Vec2 start_m, Vec2 velocity_m_s) {
  Body b;
  b.name = name;
  b.shape.kind = Shape::Kind::Box;
  b.shape.size_m = Vec2(L_m, t_m);
  b.start_m = start_m;
  b.motion.velocity_m_s = velocity_m_s;
  b.friction = 0.35;
  return b;
}

inline Body circle_body(const char* name, double D_m, Vec2 start_m, Vec2 velocity_m_s) {
  Body b;
  b.name = name;
  b.shape.kind = Shape::Kind::Circle;
  b.shape.radius_m = 0.5 * D_m;
  b.start_m = start_m;
  b.motion.velocity_m_s = velocity_m_s;
  b.friction = 0.35;
  return b;
}

// Per-step forces of every body against the lead body's travel.
struct Trace {
  std::vector<double> travel_m;
  std::vector<std::vector<Vec2>> force_N_per_m;  // [body][step]
  double wall_s = 0.0;
  size_t particles = 0;
  int64_t steps = 0;
};

inline Trace run_trace(const Scene& scene) {
  const auto t0 = std::chrono::steady_clock::now();
  Simulation sim(scene);
  Trace t;
  t.force_N_per_m.resize(scene.bodies.size());
  while (!sim.finished()) {
    sim.step();
    t.travel_m.push_back(sim.lead_body_travel_m());
    for (size_t b = 0; b < scene.bodies.size(); ++b) t.force_N_per_m[b].push_back(sim.bodies()[b].force_N_per_m);
  }
  t.particles = sim.particles().size();
  t.steps = sim.step_count();
  t.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

// Runs the scenes one per hardware thread (each scene single-threaded: small grids scale better
// across runs than within one, and the solver is deterministic for any thread count).
inline std::vector<Trace> run_all(const std::vector<Scene>& scenes) {
  std::vector<Trace> out(scenes.size());
  const unsigned workers = std::max(1u, std::min<unsigned>(std::thread::hardware_concurrency(), unsigned(scenes.size())));
  // longest first, so the last runs do not leave a core idle: order by particles x steps estimate
  std::vector<size_t> order(scenes.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto cost = [&](size_t i) {
    const Scene& s = scenes[i];
    double area = 0.0;
    for (const auto& b : s.beds) area += (b.max_m - b.min_m).prod();
    return area / (s.domain.dx_m * s.domain.dx_m) * s.solver.end_displacement_m / s.domain.dx_m;
  };
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return cost(a) > cost(b); });
  std::atomic<size_t> next{0};
  std::vector<std::thread> pool;
  for (unsigned w = 0; w < workers; ++w)
    pool.emplace_back([&] {
      for (size_t k = next++; k < order.size(); k = next++) out[order[k]] = run_trace(scenes[order[k]]);
    });
  for (auto& th : pool) th.join();
  return out;
}

// Mean of component c of body b's force over steps with travel in [from, to] (each step is one
// time step of equal length for these constant-velocity runs up to the CFL's small variation).
inline double window_mean(const Trace& t, size_t body, int c, double from_m, double to_m) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t k = 0; k < t.travel_m.size(); ++k)
    if (t.travel_m[k] >= from_m && t.travel_m[k] <= to_m) sum += t.force_N_per_m[body][k][c], ++n;
  return n ? sum / double(n) : std::nan("");
}

// Moving average of component c over `width_m` of travel, sampled every `every_m`.
inline std::vector<std::pair<double, double>> smoothed(const Trace& t, size_t body, int c, double width_m,
                                                       double every_m) {
  std::vector<std::pair<double, double>> out;
  if (t.travel_m.empty()) return out;
  for (double d = 0.5 * width_m; d <= t.travel_m.back() - 0.5 * width_m + 1e-12; d += every_m)
    out.emplace_back(d, window_mean(t, body, c, d - 0.5 * width_m, d + 0.5 * width_m));
  return out;
}

}  // namespace furrow::paper
