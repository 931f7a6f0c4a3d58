#include "engine/task_log.hpp"

#include <algorithm>
#include <functional>
#include <queue>

namespace furrow {

double list_schedule_s(const std::vector<double>& task_s, int threads) {
  // the threads' finishing times, the earliest on top
  std::priority_queue<double, std::vector<double>, std::greater<>> free_at;
  for (int t = 0; t < std::max(1, threads); ++t) free_at.push(0.0);
  double end_s = 0.0;
  for (double s : task_s) {
    const double done = free_at.top() + s;
    free_at.pop();
    free_at.push(done);
    end_s = std::max(end_s, done);
  }
  return end_s;
}

void TaskLog::add(StepPhase phase, double region_wall_s, const std::vector<double>& task_s) {
  PhaseTasks& p = phases[size_t(phase)];
  p.region_wall_s += region_wall_s;
  for (size_t k = 0; k < kThreads.size(); ++k) p.shared_s[k] += list_schedule_s(task_s, kThreads[k]);
  ++p.regions;
  p.tasks += long(task_s.size());
}

}  // namespace furrow
