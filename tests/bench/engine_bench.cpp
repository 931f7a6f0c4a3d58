// Solver throughput (particle-steps per second) on the plate_intrusion template at its default
// resolution, with 1 and 2 threads:
// - NDPM vs the same scene with dilatancy on (chi = 0, so the physics is identical and only the
//   cost of carrying the DPM state differs);
// - the plate as it ships (translating) vs the same plate turning at a prescribed rate, free to
//   turn, or free to sink under a load: what a body that turns or responds costs a step.
// Run: build/bench/furrow_engine_bench [--benchmark_filter=...]; compare within one run.
#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>

#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"

using namespace furrow;

namespace {

Scene plate_scene(int threads, bool dilatancy) {
  const SceneTemplate* t = find_scene_template("plate_intrusion");
  Scene s = parse_scene_text(t->text, "<template plate_intrusion>");
  s.solver.threads = threads;
  if (dilatancy) {
    for (auto& m : s.materials) {
      m.model = MaterialModel::DPM;
      m.chi = 0.0;
    }
    s.effects.dilatancy = true;
  }
  return s;
}

void run(benchmark::State& state, bool dilatancy) {
  Simulation sim(plate_scene(int(state.range(0)), dilatancy));
  // get the plate into the bed so contact and plastic flow are part of the cost
  while (sim.lead_body_travel_m() < 0.02) sim.step();
  int64_t steps = 0;
  for (auto _ : state) {
    sim.step();
    ++steps;
  }
  state.counters["particles"] = double(sim.particles().size());
  state.counters["particle_steps_per_s"] =
      benchmark::Counter(double(steps) * double(sim.particles().size()), benchmark::Counter::kIsRate);
}

void BM_StepNdpm(benchmark::State& state) { run(state, false); }
void BM_StepDilatancyOn(benchmark::State& state) { run(state, true); }

enum class BodyMotion { Translating, Turning, FreeAngle, FreeY };

// The template's plate with its body's JSON changed, parsed as a user's scene would be (the
// free DOFs' mass and inertia come from the same rules).
Scene plate_scene_moving(int threads, BodyMotion how) {
  const SceneTemplate* t = find_scene_template("plate_intrusion");
  nlohmann::json j = nlohmann::json::parse(t->text);
  nlohmann::json& plate = j["bodies"][0];
  switch (how) {
    case BodyMotion::Translating: break;
    case BodyMotion::Turning: plate["motion"]["angular_velocity_rad_s"] = 0.5; break;  // ~6 deg in the warm-up
    case BodyMotion::FreeAngle:
      plate["free"] = {"angle"};
      plate["density_kg_m3"] = 7800;
      break;
    case BodyMotion::FreeY:  // starts at the plate's speed, a load that keeps it going into the bed
      plate["free"] = {"y"};
      plate["density_kg_m3"] = 7800;
      plate["applied_force_N_per_m"] = {0.0, -750.0};
      break;
  }
  Scene s = parse_scene_text(j.dump(), "<template plate_intrusion, body changed>");
  s.solver.threads = threads;
  return s;
}

void run_body(benchmark::State& state, BodyMotion how) {
  Simulation sim(plate_scene_moving(int(state.range(0)), how));
  while (sim.time_s() < 0.2) sim.step();  // 20 mm into the bed at the prescribed 0.1 m/s
  const double contact0_s = sim.phase_seconds().contact;
  int64_t steps = 0;
  for (auto _ : state) {
    sim.step();
    ++steps;
  }
  // the contact phase alone: where turning or responding costs, and a few % of a step, so the
  // step's own noise on a shared machine would hide it
  state.counters["contact_us_per_step"] = 1e6 * (sim.phase_seconds().contact - contact0_s) / double(steps);
  // the plate's bottom below the bed's top (0.6 m; the plate is 20 mm tall)
  state.counters["depth_mm"] = 1e3 * (0.6 - (sim.bodies()[0].position_m.y() - 0.01));
  state.counters["particle_steps_per_s"] =
      benchmark::Counter(double(steps) * double(sim.particles().size()), benchmark::Counter::kIsRate);
}

void BM_BodyTranslating(benchmark::State& state) { run_body(state, BodyMotion::Translating); }
void BM_BodyTurning(benchmark::State& state) { run_body(state, BodyMotion::Turning); }
void BM_BodyFreeAngle(benchmark::State& state) { run_body(state, BodyMotion::FreeAngle); }
void BM_BodyFreeY(benchmark::State& state) { run_body(state, BodyMotion::FreeY); }

}  // namespace

BENCHMARK(BM_StepNdpm)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_StepDilatancyOn)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_BodyTranslating)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_BodyTurning)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_BodyFreeAngle)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_BodyFreeY)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK_MAIN();
