// What a step's parallel regions would allow on more threads than this machine has. With a log set
// (Simulation::set_task_log), every parallel region of the default path times each of its tasks;
// the log keeps, per phase, the regions' wall seconds and the seconds their tasks would take shared
// out on 2..64 threads (list scheduling: each task, in order, to the thread that is free first).
// Whatever else a phase's wall time holds ran on the calling thread alone: the serial part. An
// idealisation (no thread wake-ups, no memory-bandwidth limit, free stealing), so an upper bound on
// the speedup that tells which phases are short of work to share, measured on any machine.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace furrow {

// the phases of PhaseSeconds as the bench groups them (G2P and the constitutive update as one)
enum class StepPhase { P2G, Grid, Contact, G2PConstitutive, Reorder };
constexpr size_t kStepPhases = 5;

struct TaskLog {
  static constexpr std::array<int, 7> kThreads = {1, 2, 4, 8, 16, 32, 64};
  struct PhaseTasks {
    double region_wall_s = 0.0;                      // wall seconds inside the phase's regions
    std::array<double, kThreads.size()> shared_s{};  // their tasks shared out on kThreads[k]
    double log_s = 0.0;  // the log's own bookkeeping, inside the phase's time: not the step's
    long regions = 0, tasks = 0;
  };
  std::array<PhaseTasks, kStepPhases> phases{};
  // work that is split by the thread count (cell_fraction's bands) split as for this many threads
  // (0: the arena's), so a one-thread run times the tasks a run on more threads would have
  int plan_threads = 0;
  void add(StepPhase phase, double region_wall_s, const std::vector<double>& task_s);
};

// The wall seconds of `task_s` run on `threads` threads, each task in order to the thread free first.
double list_schedule_s(const std::vector<double>& task_s, int threads);

}  // namespace furrow
