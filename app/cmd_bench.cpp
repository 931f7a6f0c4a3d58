// furrow bench: this machine's particle-steps per second for each shape function and model on one
// and all threads, stored for validate/run/study to predict wall times.
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>

#include "app/calibration.hpp"
#include "app/commands.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"

namespace furrow::cli {

namespace {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      return colon == std::string::npos ? line : line.substr(colon + 2);
    }
  return "unknown";
}

// The single-plate paper case at dx 5 mm (about 115k particles, between the preview and the paper's
// resolution), the plate already 20 mm into the bed so contact and plastic flow are part of the cost.
Scene bench_scene(ShapeFunction shape, bool dpm, int threads, double dx_m = 0.005) {
  Scene s = parse_scene_text(find_scene_template("plate_intrusion")->text, "<template plate_intrusion>");
  s.domain.dx_m = dx_m;
  s.solver.shape_function = shape;
  s.solver.threads = threads;
  // the template's fields stay listed: its strain-rate output makes the constitutive update keep
  // the plastic strain and its rate (as every intrusion template does; ~7% of a step at 1.84M
  // points), but no frame is written
  s.outputs.movies.clear();
  s.outputs.frame_interval_s = 0.0;
  s.bodies[0].start_m.y() -= 0.025;
  if (dpm) {
    for (auto& m : s.materials) {
      m.model = MaterialModel::DPM;
      m.chi = 2.5;
    }
    s.effects.dilatancy = true;
  }
  return s;
}

// Particle-steps per wall second over at least `seconds` and `min_steps` steps, after 10 steps of warm-up;
// *phases: the phase seconds of the measured steps.
// *log: the measured steps' tasks (task_log.hpp).
double measure_rate(Simulation& sim, double seconds, PhaseSeconds* phases, int64_t min_steps = 20,
                    TaskLog* log = nullptr) {
  for (int i = 0; i < 10; ++i) sim.step();  // first touches of memory and contact warm-up
  sim.set_task_log(log);
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const PhaseSeconds before = sim.phase_seconds();
  int64_t steps = 0;
  double elapsed = 0.0;
  while (steps < min_steps || elapsed < seconds) {
    sim.step();
    ++steps;
    elapsed = std::chrono::duration<double>(clock::now() - t0).count();
  }
  if (phases) {
    const PhaseSeconds& ph = sim.phase_seconds();
    *phases = {ph.p2g - before.p2g,         ph.grid - before.grid,
               ph.contact - before.contact, ph.g2p - before.g2p,
               ph.constitutive - before.constitutive, ph.reorder - before.reorder,
               ph.g2p_constitutive - before.g2p_constitutive};
  }
  sim.set_task_log(nullptr);
  return double(steps) * double(sim.particles().size()) / elapsed;
}

// "1,2,4" -> {1, 2, 4}; anything else is a usage error naming the option.
std::vector<int> parse_thread_list(const std::string& text) {
  std::vector<int> out;
  size_t at = 0;
  while (at <= text.size()) {
    const size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    char* end = nullptr;
    const long n = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || n < 1 || n > 4096)
      throw UsageError("--threads " + text + ": expected a comma-separated list of thread counts, each 1 to 4096 (e.g. 1,2,4)");
    out.push_back(int(n));
    at = comma + 1;
  }
  return out;
}

// The bench's phases in StepPhase order, then the whole step (G2P and the constitutive update as one).
constexpr const char* kPhaseNames[] = {"p2g", "grid", "contact", "g2p+const", "reorder", "step"};
std::array<double, kStepPhases + 1> bench_phases(const PhaseSeconds& ph) {
  return {ph.p2g, ph.grid, ph.contact, ph.g2p + ph.constitutive + ph.g2p_constitutive, ph.reorder, ph.total()};
}

// What the step's tasks allow on more threads than this machine has: for each T of 1, 2, ... 64,
// one run of the steps on one thread with every task timed and the work split as a T-thread run
// would split it (task_log.hpp). Per phase, its serial part (what ran outside its tasks, dispatch
// included) plus its tasks shared out on T threads, as a speedup over the T = 1 run: a ceiling (no
// thread wake-ups, memory-bandwidth limit or stealing cost) that names the phases short of work.
// Some splits add work as T grows (cell_fraction's bands, the reorder's groups), so the speedup is
// over the one-thread split's time, rescaled to each run's pace by P2G and G2P, whose work is the
// same in every run (the shared VM's pace drifts between runs).
void print_task_ceiling(double dx_m, int steps) {
  constexpr auto& T = TaskLog::kThreads;
  // a task's two clock reads cost one read outside its timed span, which an untimed run does not pay
  using clock = std::chrono::steady_clock;
  constexpr int kReads = 100000;
  const auto t0 = clock::now();
  for (int i = 0; i < kReads; ++i) (void)clock::now();
  const double read_s = std::chrono::duration<double>(clock::now() - t0).count() / kReads;
  constexpr size_t kP2G = size_t(StepPhase::P2G), kG2P = size_t(StepPhase::G2PConstitutive);
  std::array<std::array<double, kStepPhases>, T.size()> wall_s{}, at_s{};
  std::array<double, kStepPhases> serial_s{}, tasks_per_region{};
  for (size_t k = 0; k < T.size(); ++k) {
    Simulation sim(bench_scene(ShapeFunction::Quadratic, false, 1, dx_m));
    PhaseSeconds ph;
    TaskLog log;
    log.plan_threads = T[k];
    measure_rate(sim, 0.0, &ph, steps, &log);
    const auto phase_s = bench_phases(ph);
    for (size_t i = 0; i < kStepPhases; ++i) {
      const TaskLog::PhaseTasks& p = log.phases[i];
      wall_s[k][i] = phase_s[i] - p.log_s - double(p.tasks) * read_s;
      const double serial = std::max(0.0, wall_s[k][i] - p.shared_s[0]);
      at_s[k][i] = serial + p.shared_s[k];
      if (k == 0) {
        serial_s[i] = serial;
        tasks_per_region[i] = p.regions > 0 ? double(p.tasks) / double(p.regions) : 0.0;
      }
    }
  }
  std::printf("\nceiling: one-thread runs with every task timed, the work split as on T threads; a phase's serial\n"
              "part (outside its tasks) plus its tasks shared out on T threads (each, in order, to the first free\n"
              "one), as a speedup over the one-thread split. No thread wake-ups, memory-bandwidth limit or\n"
              "stealing cost: real runs fall below it; a phase far below T is short of work to share\n");
  std::printf("%-10s %9s %8s %13s", "phase", "seconds", "serial", "tasks/region");
  for (size_t k = 1; k < T.size(); ++k) std::printf(" %6s", ("T=" + std::to_string(T[k])).c_str());
  std::printf("\n");
  auto pace = [&](size_t k) { return (wall_s[k][kP2G] + wall_s[k][kG2P]) / (wall_s[0][kP2G] + wall_s[0][kG2P]); };
  for (size_t i = 0; i <= kStepPhases; ++i) {
    const bool step = i == kStepPhases;
    double one_s = 0.0, one_serial_s = 0.0;
    for (size_t j = 0; j < kStepPhases; ++j)
      if (step || j == i) one_s += wall_s[0][j], one_serial_s += serial_s[j];
    std::printf("%-10s %9.4f %7.2f%% ", kPhaseNames[i], one_s, 100.0 * one_serial_s / std::max(one_s, 1e-30));
    if (!step)
      std::printf("%13.1f", tasks_per_region[i]);
    else
      std::printf("%13s", "");
    for (size_t k = 1; k < T.size(); ++k) {
      double at = 0.0;
      for (size_t j = 0; j < kStepPhases; ++j)
        if (step || j == i) at += at_s[k][j];
      if (one_s > 0.0 && at > 0.0)
        std::printf(" %5.1fx", one_s * pace(k) / at);
      else
        std::printf(" %6s", "-");  // the phase did not run (the reorder in a few steps)
    }
    std::printf("\n");
  }
  std::printf("(seconds, serial and tasks/region: the one-thread split; on T threads the grid update adds a band\n"
              "of cell_fraction's sums per thread, up to one per 4 node lines of a body's box)\n");
}

// `--threads LIST`: where a step stops scaling. The bench scene (quadratic NDPM) for a fixed number of
// steps on each thread count, best of `repeats` runs by total time; prints each phase's seconds and
// its speedup over the first count. Writes no calibration.
int bench_scaling(const std::vector<int>& thread_counts, double dx_m, int steps, int repeats, bool ceiling) {
  struct Row {
    int threads;
    double rate;
    PhaseSeconds ph;
  };
  std::vector<Row> rows;
  size_t particles = 0;
  for (int threads : thread_counts) {
    Row best{threads, 0.0, {}};
    for (int r = 0; r < repeats; ++r) {
      Simulation sim(bench_scene(ShapeFunction::Quadratic, false, threads, dx_m));
      particles = sim.particles().size();
      PhaseSeconds ph;
      const double rate = measure_rate(sim, 0.0, &ph, steps);
      if (rate > best.rate) best = {threads, rate, ph};
    }
    rows.push_back(best);
  }
  std::printf("plate_intrusion at dx %.4g m, %zu particles, quadratic NDPM, %d steps after 10, best of %d\n", dx_m,
              particles, steps, repeats);
  std::printf("wall seconds per phase over the steps, and (in brackets) the speedup over %d thread%s\n",
              rows.front().threads, rows.front().threads == 1 ? "" : "s");
  std::printf("grid includes cell_fraction's band sums (run beside the columns); contact is their plan and the node pass\n");
  std::printf("%7s %19s", "threads", "M particle-steps/s");
  for (const char* n : kPhaseNames) std::printf(" %17s", n);
  std::printf("\n");
  const auto base = bench_phases(rows.front().ph);
  for (const Row& row : rows) {
    std::printf("%7d %19.2f", row.threads, row.rate / 1e6);
    const auto now = bench_phases(row.ph);
    for (size_t k = 0; k < now.size(); ++k) {
      char cell[32];
      if (now[k] > 0.0 && base[k] > 0.0)
        std::snprintf(cell, sizeof cell, "%.4f (%.2fx)", now[k], base[k] / now[k]);
      else
        std::snprintf(cell, sizeof cell, "%.4f (-)", now[k]);  // a phase that did not run (reorder in few steps)
      std::printf(" %17s", cell);
    }
    std::printf("\n");
  }
  std::printf("share of a %d-thread step:", rows.front().threads);
  for (size_t k = 0; k + 1 < base.size(); ++k) std::printf(" %s %.1f%%", kPhaseNames[k], 100.0 * base[k] / base.back());
  std::printf("\n");
  if (ceiling) print_task_ceiling(dx_m, steps);
  return 0;
}

int bench_main(const Parsed& p) {
  char* end = nullptr;
  if (p.has("--threads")) {
    const std::vector<int> counts = parse_thread_list(p.get("--threads"));
    const std::string dx_text = p.get("--dx", "0.005"), steps_text = p.get("--steps", "300");
    const double dx_m = std::strtod(dx_text.c_str(), &end);
    if (dx_text.empty() || *end != '\0' || !(dx_m >= 0.0005) || dx_m > 0.02)
      throw UsageError("--dx " + dx_text + ": expected a grid spacing in metres in [0.0005, 0.02]");
    const long steps = std::strtol(steps_text.c_str(), &end, 10);
    if (steps_text.empty() || *end != '\0' || steps < 1 || steps > 1000000)
      throw UsageError("--steps " + steps_text + ": expected a number of steps from 1 to 1000000");
    return bench_scaling(counts, dx_m, int(steps), 2, p.has("--ceiling"));
  }
  if (p.has("--dx") || p.has("--steps") || p.has("--ceiling"))
    throw UsageError("--dx, --steps and --ceiling go with --threads (the scaling table)");
  const std::string sec_text = p.get("--seconds", "2");
  const double seconds = std::strtod(sec_text.c_str(), &end);
  if (sec_text.empty() || *end != '\0' || !(seconds > 0.0) || seconds > 600.0)
    throw UsageError("--seconds " + sec_text + ": expected a number of seconds per measurement in (0, 600]");
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<int> thread_counts = {1};
  if (cores > 1) thread_counts.push_back(cores);

  Calibration c;
  c.path = p.get("--out", calibration_path());
  char host[256] = "";
  ::gethostname(host, sizeof host - 1);
  c.host = host;
  c.cpu = cpu_model();
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M", std::localtime(&now));
  c.date = date;

  const bool quiet = p.has("--quiet");
  double reference_rate = 0.0;  // quadratic NDPM on all threads at the bench size
  if (!quiet)
    std::fprintf(stderr, "furrow bench: %s, %d core%s; %.3g s per measurement\n", c.cpu.c_str(), cores,
                 cores == 1 ? "" : "s", seconds);
  const char* shape_names[] = {"linear", "quadratic", "cubic"};
  // G2P and the constitutive update run as one pass over the particles (one column)
  std::printf("%-10s %-5s %7s %19s   share of a step (%%): %5s %5s %7s %9s %7s\n", "shape", "model", "threads",
              "M particle-steps/s", "p2g", "grid", "contact", "g2p+const", "reorder");
  for (ShapeFunction shape : {ShapeFunction::Linear, ShapeFunction::Quadratic, ShapeFunction::Cubic})
    for (bool dpm : {false, true})
      for (int threads : thread_counts) {
        Simulation sim(bench_scene(shape, dpm, threads));
        c.particles = sim.particles().size();
        PhaseSeconds ph;
        const double rate = measure_rate(sim, seconds, &ph);
        c.entries.push_back({shape_names[int(shape)], dpm ? "dpm" : "ndpm", threads, rate});
        if (shape == ShapeFunction::Quadratic && !dpm && threads == thread_counts.back()) reference_rate = rate;
        const auto phase = bench_phases(ph);
        auto share = [&](StepPhase p) { return 100.0 * phase[size_t(p)] / phase.back(); };
        std::printf("%-10s %-5s %7d %19.2f   %21s %5.1f %5.1f %7.1f %9.1f %7.1f\n", shape_names[int(shape)],
                    dpm ? "dpm" : "ndpm", threads, rate / 1e6, "", share(StepPhase::P2G), share(StepPhase::Grid),
                    share(StepPhase::Contact), share(StepPhase::G2PConstitutive), share(StepPhase::Reorder));
        std::fflush(stdout);
      }
  // the same at the paper's dx 1.25 mm (16 times the points, 1.84M): how the rate falls with the
  // bed's size (at 4 times the points it had not fallen measurably; engine/README.md, Performance)
  {
    Simulation sim(bench_scene(ShapeFunction::Quadratic, false, thread_counts.back(), 0.00125));
    const double rate = measure_rate(sim, seconds, nullptr);
    const double ratio = double(sim.particles().size()) / double(c.particles);
    c.large_particles = sim.particles().size();
    c.large_particle_steps_per_s = rate;
    c.size_exponent = std::log(rate / reference_rate) / std::log(ratio);  // as measured; predictions clamp it
    std::printf("%-10s %-5s %7d %19.2f   at %zu particles: rate ~ particles^%.3f above %zu\n", "quadratic", "ndpm",
                thread_counts.back(), rate / 1e6, sim.particles().size(), c.size_exponent, c.particles);
  }
  save_calibration(c);
  std::printf("calibration (%zu particles, plate_intrusion at dx 5 mm) saved to %s\n", c.particles, c.path.c_str());
  return 0;
}

}  // namespace

Command command_bench() {
  return {"bench",
          "measure this machine's solver speed so validate, run and study can predict wall times",
          "furrow bench [--seconds S] [--out FILE]\n       furrow bench --threads 1,2,4,... [--dx M] [--steps N] [--ceiling]",
          "Runs the single-plate scene (plate_intrusion at dx 5 mm, about 115k particles, the plate in the\n"
          "bed) for S seconds with each shape function (linear, quadratic, cubic), each model (NDPM; DPM\n"
          "with dilatancy) on one thread and on all cores, prints the particle-steps per second and the\n"
          "share of a step each phase takes (P2G, which zeroes the grid as it goes; grid update; body and\n"
          "wall contact; G2P with the constitutive update, one pass; particle reorder); then quadratic\n"
          "NDPM on all cores at dx 1.25 mm (16 times the points) for how the rate falls on larger beds; and\n"
          "stores them in FILE (default $FURROW_CALIBRATION, else $XDG_CONFIG_HOME/furrow/calibration.json,\n"
          "else ~/.config/furrow/calibration.json). `furrow validate` then prints a scene's predicted\n"
          "solver time, `furrow run` compares against it, and `furrow study` predicts its first rung.\n"
          "About 13 x (S + setup) seconds (under a minute at the default S); the machine should be\n"
          "otherwise idle for figures that hold.\n\n"
          "With --threads LIST it measures where a step stops scaling instead: quadratic NDPM on the same\n"
          "scene (dx M, default 0.005 m) for N steps (default 300) after 10 of warm-up on each thread count,\n"
          "best of two runs each, and prints the wall seconds of each phase with its speedup over the\n"
          "first count. With --ceiling it then runs the steps on one thread once for each T in 1, 2, 4, ...\n"
          "64 with every parallel task timed and the work split as on T threads, and prints the speedup\n"
          "each phase's serial part and tasks allow on T threads over one thread's split: where a step\n"
          "would stop scaling on a machine with more cores than this one, short of work to share\n"
          "(wake-ups and memory bandwidth aside). Nothing is stored.",
          {{"--seconds", true, false, "seconds per measurement (default 2)", "S"},
           {"--out", true, false, "calibration file to write (replaced)", "FILE"},
           {"--quiet", false, false, "no header line on stderr"},
           {"--threads", true, false, "per-phase scaling over these thread counts (e.g. 1,2,4); stores nothing", "LIST"},
           {"--dx", true, false, "with --threads: grid spacing of the scene in m (default 0.005)", "M"},
           {"--steps", true, false, "with --threads: steps measured per run (default 300)", "N"},
           {"--ceiling", false, false, "with --threads: also the speedups the tasks allow on 2 to 64 threads"}},
          0,
          0,
          bench_main};
}

}  // namespace furrow::cli
