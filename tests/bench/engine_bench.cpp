// Solver throughput (particle-steps per second) on the plate_intrusion template at its default
// resolution, from 20 mm into the bed:
// - NDPM (the plate as it ships, translating) vs the same scene with dilatancy on (chi = 0, so the
//   physics is identical and only the cost of carrying the DPM state differs), 1 and 2 threads;
// - the same plate turning at a prescribed rate, free to turn, or free to sink under a load, one
//   thread: what a body that turns or responds costs a step against BM_StepNdpm/1.
// Each reports the contact phase's microseconds per step beside the step's time: turning or
// responding costs there, a few % of a step, which the step's own noise on a shared machine hides.
// Run: build/bench/furrow_engine_bench [--benchmark_filter=...]; compare within one run.
#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>

#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"

using namespace furrow;

namespace {

enum class Variant { Ndpm, DilatancyOn, Turning, FreeAngle, FreeY };

// The template's plate, its body's JSON changed for the variant and parsed as a user's scene would
// be (a free DOF's mass and inertia come from the same rules).
Scene plate_scene(int threads, Variant v) {
  nlohmann::json j = nlohmann::json::parse(find_scene_template("plate_intrusion")->text);
  nlohmann::json& plate = j["bodies"][0];
  switch (v) {
    case Variant::Ndpm:
    case Variant::DilatancyOn: break;
    case Variant::Turning: plate["motion"]["angular_velocity_rad_s"] = 0.5; break;  // ~6 deg in the warm-up
    case Variant::FreeAngle:
      plate["free"] = {"angle"};
      plate["density_kg_m3"] = 7800;
      break;
    case Variant::FreeY:  // starts at the plate's speed, a load that keeps it going into the bed
      plate["free"] = {"y"};
      plate["density_kg_m3"] = 7800;
      plate["applied_force_N_per_m"] = {0.0, -750.0};
      break;
  }
  Scene s = parse_scene_text(j.dump(), "<template plate_intrusion>");
  s.solver.threads = threads;
  if (v == Variant::DilatancyOn) {
    for (auto& m : s.materials) {
      m.model = MaterialModel::DPM;
      m.chi = 0.0;
    }
    s.effects.dilatancy = true;
  }
  return s;
}

void run(benchmark::State& state, Variant v) {
  const Scene scene = plate_scene(int(state.range(0)), v);
  Simulation sim(scene);
  // into the bed (20 mm at the prescribed 0.1 m/s) so contact and plastic flow are part of the cost
  while (sim.time_s() < 0.2) sim.step();
  const double contact0_s = sim.phase_seconds().contact;
  int64_t steps = 0;
  for (auto _ : state) {
    sim.step();
    ++steps;
  }
  state.counters["particles"] = double(sim.particles().size());
  state.counters["contact_us_per_step"] = 1e6 * (sim.phase_seconds().contact - contact0_s) / double(steps);
  // the plate's bottom below the bed's top
  const double bottom_m = sim.bodies()[0].position_m.y() - 0.5 * scene.bodies[0].shape.size_m.y();
  state.counters["depth_mm"] = 1e3 * (scene.beds[0].max_m.y() - bottom_m);
  state.counters["particle_steps_per_s"] =
      benchmark::Counter(double(steps) * double(sim.particles().size()), benchmark::Counter::kIsRate);
}

void BM_StepNdpm(benchmark::State& state) { run(state, Variant::Ndpm); }
void BM_StepDilatancyOn(benchmark::State& state) { run(state, Variant::DilatancyOn); }
void BM_StepTurning(benchmark::State& state) { run(state, Variant::Turning); }
void BM_StepFreeAngle(benchmark::State& state) { run(state, Variant::FreeAngle); }
void BM_StepFreeY(benchmark::State& state) { run(state, Variant::FreeY); }

}  // namespace

BENCHMARK(BM_StepNdpm)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_StepDilatancyOn)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_StepTurning)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_StepFreeAngle)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_StepFreeY)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK_MAIN();
