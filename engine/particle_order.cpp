// The particles' memory order: sorted by P2G strip, then by stencil, every kReorderSteps steps or
// when a point strays from its strip.
#include <algorithm>
#include <cstddef>
#include <numeric>
#include <type_traits>
#include <vector>

#include "engine/shape_functions.hpp"
#include "engine/simulation.hpp"
#include "engine/simulation_detail.hpp"

namespace furrow {

// Physically reorder particle arrays by strip, then by stencil row and column within it, so P2G and
// G2P walk memory in order, each strip's points are one range (strip_start_) and points with the
// same stencil are consecutive (P2G's StencilRun).
template <class K>
void Simulation::reorder_particles() {
  using W = StripWindow<K>;
  const bool homes_known = !homes_stale_;
  homes_stale_ = strayed_ = false;
  const size_t n = p_.size();
  const double inv = 1.0 / g_.dx;
  const int strips = W::count(g_.nx), rows = g_.ny + 2 * Grid::kPad + 1;
  const size_t strip_keys = size_t(rows) * W::width;
  std::vector<uint32_t> key(n), start(size_t(strips) * strip_keys + 1, 0), perm(n);
  // the parallel passes in fixed chunks of points
  constexpr size_t kChunk = size_t(1) << 12;
  const size_t chunks = (n + kChunk - 1) / kChunk;
  auto in_chunks = [&](const auto& pass) {
    for_tasks(task_log_, StepPhase::Reorder, chunks, [&](size_t c) { pass(c * kChunk, std::min(n, c * kChunk + kChunk)); });
  };
  in_chunks([&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const int base = K::base(p_.x[i] * inv), strip = W::of_base(base, strips);
      const int column = std::clamp(base - W::width * (strip - 1), 0, W::width - 1);
      const int cy = std::clamp(K::base(p_.y[i] * inv) + Grid::kPad, 0, rows - 1);
      key[i] = uint32_t((size_t(strip) * rows + cy) * W::width + column);
    }
  });
  // A stable counting sort by key. On more than one thread, by groups of strips: a point kept its
  // stencil within its home strip's window, so its strip now is its home strip or one beside it,
  // and the points of strips a..b lie in the home ranges of strips a - 1 .. b + 1. Each group
  // counts and places its own keys walking those ranges in memory order, as one pass would: the
  // same permutation. If a point strayed further, the groups miss it and one pass does it all.
  const int threads = split_threads(task_log_);
  const int groups = threads > 1 && homes_known && strip_start_.size() == size_t(strips) + 1
                         ? std::clamp(strips / 8, 1, 4 * threads)
                         : 0;
  const std::vector<uint32_t> home_start = strip_start_;
  // group g: strips a .. b - 1, so keys a strip_keys .. b strip_keys - 1
  auto group_strips = [&](size_t g) {
    return std::pair(g * size_t(strips) / size_t(groups), (g + 1) * size_t(strips) / size_t(groups));
  };
  auto group_keys = [&](size_t g) {
    const auto [a, b] = group_strips(g);
    return std::pair(uint32_t(a * strip_keys), uint32_t(b * strip_keys));
  };
  // each point of group g's keys, in memory order, from the home ranges of strips a - 1 .. b
  auto each_point_of_group = [&](size_t g, const auto& point) {
    const auto [a, b] = group_strips(g);
    const auto [lo, hi] = group_keys(g);
    const uint32_t end = home_start[std::min(b + 1, size_t(strips))];
    for (uint32_t i = home_start[a > 0 ? a - 1 : 0]; i < end; ++i)
      if (key[i] - lo < hi - lo) point(i);
  };
  std::vector<uint32_t> group_total(size_t(groups), 0);
  for_tasks(task_log_, StepPhase::Reorder, size_t(groups), [&](size_t g) {
    each_point_of_group(g, [&](uint32_t i) { ++start[key[i] + 1]; });
    const auto [lo, hi] = group_keys(g);
    for (uint32_t k = lo + 1; k < hi; ++k) start[k + 1] += start[k];
    group_total[g] = start[hi];
  });
  uint32_t found = 0;
  for (uint32_t t : group_total) found += t;
  const bool grouped = groups > 0 && found == n;
  reorders_.by_groups += grouped;
  if (grouped) {
    // each group's counts from its first point's place
    std::vector<uint32_t> offset(size_t(groups), 0);
    for (size_t g = 1; g < size_t(groups); ++g) offset[g] = offset[g - 1] + group_total[g - 1];
    for_tasks(task_log_, StepPhase::Reorder, size_t(groups), [&](size_t g) {
      const auto [lo, hi] = group_keys(g);
      for (uint32_t k = lo + 1; k <= hi; ++k) start[k] += offset[g];
    });
  } else {
    if (groups > 0) std::fill(start.begin(), start.end(), 0);  // the groups' counts, which missed a point
    for (size_t i = 0; i < n; ++i) ++start[key[i] + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
  }
  strip_start_.resize(size_t(strips) + 1);
  for (int s = 0; s <= strips; ++s) strip_start_[size_t(s)] = start[size_t(s) * strip_keys];
  // where each row of each strip starts, for searches bounded in y (strip_rows_of_bases)
  strip_rows_ = rows;
  strip_row_start_.resize(size_t(strips) * size_t(rows) + 1);
  for (size_t r = 0; r < strip_row_start_.size(); ++r) strip_row_start_[r] = start[r * W::width];
  drift_y_m_ = 0.0;
  set_home_strips();
  if (grouped) {
    for_tasks(task_log_, StepPhase::Reorder, size_t(groups), [&](size_t g) {
      each_point_of_group(g, [&](uint32_t i) { perm[start[key[i]]++] = i; });
    });
  } else {
    for (size_t i = 0; i < n; ++i) perm[start[key[i]]++] = uint32_t(i);
  }
  // the contact list (kept for the next step's warm start) follows its particles
  if (!contacts_.empty()) {
    for (size_t i = 0; i < n; ++i) key[perm[i]] = uint32_t(i);
    for (auto& c : contacts_) c.particle = key[c.particle];
    std::sort(contacts_.begin(), contacts_.end(), [](const ContactPoint& a, const ContactPoint& b) {
      return a.particle != b.particle ? a.particle < b.particle : a.body < b.body;
    });
  }
  // One gather buffer per element type: each array swaps its storage into it and the old storage
  // takes the next array. A fresh buffer per array page-faulted ~15 MB each at 1.84M points.
  std::vector<double> buffer_f64;
  std::vector<float> buffer_f32;
  std::vector<uint8_t> buffer_u8;
  p_.for_each_array([&](const char*, auto& a) {
    using T = typename std::decay_t<decltype(a)>::value_type;
    if (a.empty()) return;
    auto& buffer = [&]() -> std::vector<T>& {
      if constexpr (std::is_same_v<T, double>) return buffer_f64;
      else if constexpr (std::is_same_v<T, float>) return buffer_f32;
      else return buffer_u8;
    }();
    buffer.resize(n);
    in_chunks([&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) buffer[i] = a[perm[i]];
    });
    a.swap(buffer);
  });
}

// The points of `strip` whose stencil may now start at node rows base_lo .. base_hi, as one range
// in memory order: the rows they could have been sorted into at the reorder (a point that moved at
// most drift_y_m_ had its base within ceil(drift / dx) rows of its base now, and a row more for
// round-off). A superset: callers keep their own test.
std::pair<uint32_t, uint32_t> Simulation::strip_rows_of_bases(int strip, int base_lo, int base_hi) const {
  // resumed from a checkpoint without rows: the whole strip until the next reorder
  if (strip_row_start_.empty()) return {strip_start_[size_t(strip)], strip_start_[size_t(strip) + 1]};
  const int rows = int(std::ceil(drift_y_m_ / g_.dx)) + 1;
  const int r0 = std::clamp(base_lo - rows + Grid::kPad, 0, strip_rows_ - 1);
  const int r1 = std::clamp(base_hi + rows + Grid::kPad, 0, strip_rows_ - 1);
  const size_t at = size_t(strip) * size_t(strip_rows_);
  return {strip_row_start_[at + size_t(r0)], strip_row_start_[at + size_t(r1) + 1]};
}

template <class K>
bool Simulation::strips_hold_for() const {
  if (homes_stale_) return false;
  const double inv_dx = 1.0 / g_.dx;
  for (size_t p = 0; p < p_.size(); ++p)
    if (!StripWindow<K>::holds(home_strip_[p], K::base(p_.x[p] * inv_dx))) return false;
  return true;
}

void Simulation::set_home_strips() {
  home_strip_.resize(p_.size());
  for_tasks(task_log_, StepPhase::Reorder, strip_start_.empty() ? 0 : strip_start_.size() - 1, [&](size_t s) {
    std::fill(home_strip_.begin() + strip_start_[s], home_strip_.begin() + strip_start_[s + 1], uint16_t(s));
  });
}

// the instances Simulation's constructor picks from
template void Simulation::reorder_particles<LinearKernel>();
template void Simulation::reorder_particles<QuadraticKernel>();
template void Simulation::reorder_particles<CubicKernel>();
template bool Simulation::strips_hold_for<LinearKernel>() const;
template bool Simulation::strips_hold_for<QuadraticKernel>() const;
template bool Simulation::strips_hold_for<CubicKernel>() const;

}  // namespace furrow
