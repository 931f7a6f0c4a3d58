// Solver throughput (particle-steps per second) on the plate_intrusion template at its default
// resolution, with 1 and 2 threads, NDPM vs the same scene with dilatancy on (chi = 0, so the
// physics is identical and only the cost of carrying the DPM state differs).
// Run: build/bench/furrow_engine_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>

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

}  // namespace

BENCHMARK(BM_StepNdpm)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_StepDilatancyOn)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK_MAIN();
