// What the step's phase files share: the particle passes' task size, P2G's strips, a body's node
// box. Internal to the engine; an unnamed namespace as simd4.hpp's, for the same reason.
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <immintrin.h>
#include <utility>
#include <vector>

#include "engine/simulation.hpp"

namespace furrow {
namespace {

constexpr size_t kGrain = 4096;  // particles per TBB task

// A parallel region of `n` tasks, task(k) for k in [0, n). With a log, each task's wall seconds go
// to it under `phase` (task_log.hpp); the tasks and what they do are the same either way.
template <class F> void for_tasks(TaskLog* log, StepPhase phase, size_t n, const F& task) {
  if (!log) {
    tbb::parallel_for(size_t(0), n, [&](size_t k) { task(k); });
    return;
  }
  using clock = std::chrono::steady_clock;
  const auto enter = clock::now();
  std::vector<double> task_s(n, 0.0);
  const auto start = clock::now();
  tbb::parallel_for(size_t(0), n, [&](size_t k) {
    const auto t0 = clock::now();
    task(k);
    task_s[k] = std::chrono::duration<double>(clock::now() - t0).count();
  });
  const auto end = clock::now();
  log->add(phase, std::chrono::duration<double>(end - start).count(), task_s);
  // the log's own time, which the phase's timer also counted
  log->phases[size_t(phase)].log_s += std::chrono::duration<double>(clock::now() - end + (start - enter)).count();
}

// The thread count that work split by threads is split for (cell_fraction's bands, the reorder's
// groups): the arena's, or the log's plan_threads, so a one-thread run times a larger run's tasks.
inline int split_threads(const TaskLog* log) {
  return log && log->plan_threads > 0 ? log->plan_threads : tbb::this_task_arena::max_concurrency();
}

// P2G's strips. A point whose stencil starts at node column `base` (the kernel's) belongs, when the
// points are reordered, to strip s = floor(base / width) + 1: its nominal bases are
// [width (s - 1), width s - 1]. Until the next reorder it may stray one column either way: its
// window of bases [width (s - 1) - 1, width s] writes node columns up to width s + N - 1, which stay
// left of what strip s + 2's window writes (width (s + 1) - 1) for width > N. So strips of one
// colour never share a node, and P2G scatters a colour's strips in parallel without sorting.
template <class K> struct StripWindow {
  static constexpr int width = K::N + 1 > 4 ? K::N + 1 : 4;  // 4 node columns, 5 for cubic
  static int count(int nx) { return nx / width + 3; }
  static int of_base(int base, int strips) { return std::clamp((base + width) / width, 0, strips - 1); }  // base >= -2
  static bool holds(int strip, int base) { return unsigned(base - (width * (strip - 1) - 1)) <= unsigned(width + 1); }
#if defined(__AVX__)
  // holds() for four points at once (strips and bases as 32-bit lanes): true when all four hold
  static bool holds4(__m128i strip, __m128i base) {
    const __m128i first = _mm_sub_epi32(_mm_mullo_epi32(strip, _mm_set1_epi32(width)), _mm_set1_epi32(width + 1));
    const __m128i offset = _mm_sub_epi32(base, first), last = _mm_set1_epi32(width + 1);
    return _mm_movemask_epi8(_mm_cmpeq_epi32(_mm_max_epu32(offset, last), last)) == 0xffff;
  }
#endif
};

// The grid nodes a body's box covers, one node of margin, clipped to the padded grid. One
// function for every contact pass, so a node one pass marks is a node another pass visits.
struct NodeBox {
  int i0, i1, j0, j1;
};
inline NodeBox body_node_box(const BodyState& s, const Grid& g) {
  const double inv_dx = 1.0 / g.dx;
  const Vec2 lo = (s.position_m + s.lo_m) * inv_dx, hi = (s.position_m + s.hi_m) * inv_dx;
  return {std::max(-Grid::kPad, int(std::floor(lo.x())) - 1), std::min(g.nx + Grid::kPad, int(std::ceil(hi.x())) + 1),
          std::max(-Grid::kPad, int(std::floor(lo.y())) - 1), std::min(g.ny + Grid::kPad, int(std::ceil(hi.y())) + 1)};
}

// The grid update of nodes [first, end) of a column: momentum to velocity, plus gravity (FLIP: vx0
// held the force impulse and becomes the pre-force velocity). Node by node, so the bits do not
// depend on which task updates which nodes (grid_and_bands).
inline void update_nodes(GridNode* first, GridNode* end, double gx, double gy, bool flip) {
  for (GridNode* n = first; n < end; ++n) {
    if (n->m <= 0.0) continue;
    const double inv_m = 1.0 / n->m;
    if (flip) {
      const double v0x = n->vx * inv_m, v0y = n->vy * inv_m;
      n->vx = v0x + n->vx0 * inv_m + gx;
      n->vy = v0y + n->vy0 * inv_m + gy;
      n->vx0 = v0x;
      n->vy0 = v0y;
    } else {
      n->vx = n->vx * inv_m + gx;
      n->vy = n->vy * inv_m + gy;
    }
  }
}

// The first and last P2G strips that may hold points whose stencil starts at node columns
// base_lo .. base_hi. Until the next reorder a point's base lies within its strip's window (one
// column beyond its nominal bases either way; G2P reorders as soon as one strays further), so
// strips holding base b are those from of_base(b - 1) to of_base(b + 1).
template <class K> inline std::pair<int, int> strips_of_bases(int base_lo, int base_hi, int strips) {
  using W = StripWindow<K>;
  return {W::of_base(base_lo - 1, strips), W::of_base(base_hi + 1, strips)};
}

// The strips whose points may lie between x_lo_m and x_hi_m.
template <class K> inline std::pair<int, int> strip_span(double x_lo_m, double x_hi_m, double inv_dx, int strips) {
  return strips_of_bases<K>(K::base(x_lo_m * inv_dx), K::base(x_hi_m * inv_dx), strips);
}

// The strips whose points may lie within `reach_m` of a body's box.
template <class K> inline std::pair<int, int> body_strip_span(const BodyState& s, double reach_m, double inv_dx, int strips) {
  return strip_span<K>(s.position_m.x() + s.lo_m.x() - reach_m, s.position_m.x() + s.hi_m.x() + reach_m, inv_dx, strips);
}

}  // namespace
}  // namespace furrow
