// P2G: particles to grid (mass, momentum, stress and the affine terms), the default path four
// points at a time.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <immintrin.h>
#include <type_traits>

#include "engine/shape_functions.hpp"
#include "engine/simd4.hpp"
#include "engine/simulation.hpp"
#include "engine/simulation_detail.hpp"

namespace furrow {

namespace {

// P2G's sum over a run of consecutive points with the same stencil (the reorder sorts them
// together, ~4 a run): the run's points add into registers and the grid takes the sum once, not a
// read-modify-write of every node for every point. Pays only with AVX-512's 32 vector registers
// (-15% P2G time); AVX2's 16 spill the twelve sums and it breaks even (README, Performance).
template <int N> struct StencilRun {
  static_assert(N <= 4, "a stencil row's vy0 is one Vec4d");
  Vec4d four[N][N];  // node (a, b)'s [m vx vy vx0]
  Vec4d fifth[N];    // row b's vy0, node a in lane a
  GridNode* column0 = nullptr;  // the stencil's first node
  size_t NY;
  explicit StencilRun(size_t ny) : NY(ny) {}
  // the point's stencil starts at `first`: a new stencil first hands the old run to the grid
  void start(GridNode* first) __attribute__((always_inline)) {
    if (first == column0) return;
    flush();
    column0 = first;
    for (int a = 0; a < N; ++a) {
      fifth[a] = Vec4d{0, 0, 0, 0};
      for (int b = 0; b < N; ++b) four[a][b] = Vec4d{0, 0, 0, 0};
    }
  }
  void flush() __attribute__((always_inline)) {
    if (!column0) return;
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b) {
        GridNode& n = column0[size_t(a) * NY + size_t(b)];
        four_at(&n.m) += four[a][b];
        n.vy0 += fifth[b][a];
      }
  }
};

#if defined(__AVX__)
// out[l] = {a[l], b[l], c[l], d[l]}: four lane vectors to four per-lane vectors
inline void transpose4(const Vec4d& a, const Vec4d& b, const Vec4d& c, const Vec4d& d, Vec4d out[4]) {
  const __m256d ab_lo = _mm256_unpacklo_pd((__m256d)a, (__m256d)b), ab_hi = _mm256_unpackhi_pd((__m256d)a, (__m256d)b);
  const __m256d cd_lo = _mm256_unpacklo_pd((__m256d)c, (__m256d)d), cd_hi = _mm256_unpackhi_pd((__m256d)c, (__m256d)d);
  out[0] = (Vec4d)_mm256_permute2f128_pd(ab_lo, cd_lo, 0x20);
  out[1] = (Vec4d)_mm256_permute2f128_pd(ab_hi, cd_hi, 0x20);
  out[2] = (Vec4d)_mm256_permute2f128_pd(ab_lo, cd_lo, 0x31);
  out[3] = (Vec4d)_mm256_permute2f128_pd(ab_hi, cd_hi, 0x31);
}
#endif

}  // namespace

template <class K, bool Flip>
void Simulation::particles_to_grid() {
  const double dx = g_.dx, inv_dx = 1.0 / dx, dt = dt_s_;
  const double Dinv = K::inv_D(inv_dx);
  GridNode* grid = g_.node.data();
  const auto& P = p_;
  auto scatter_strip = [&](int s) {
    // locals, not captures: the grid stores below cannot change them, so they stay in registers
    GridNode* const nodes = grid;
    const size_t NY = size_t(g_.NY);
    const double *const X = P.x.data(), *const Y = P.y.data(), *const VX = P.vx.data(), *const VY = P.vy.data();
    const auto *const C00 = P.c00.data(), *const C01 = P.c01.data(), *const C10 = P.c10.data(), *const C11 = P.c11.data();
    const auto *const M = P.mass.data(), *const SXX = P.sxx.data(), *const SYY = P.syy.data(), *const SXY = P.sxy.data();
    const auto *const PRESSURE = P.pressure.data();
    const double* const VOL = P.volume.data();
    const double h = dx, ih = inv_dx, dt_ = dt, Dinv_ = Dinv;
    StencilRun<K::N> run(NY);
    for (uint32_t p = strip_start_[s], p_end = strip_start_[s + 1]; p < p_end; ++p) {
      double wx[K::N], wy[K::N], dwx[K::N], dwy[K::N];
      const double xp = X[p], yp = Y[p];
      const int bx = K::weights(xp * ih, wx, dwx, ih);
      const int by = K::weights(yp * ih, wy, dwy, ih);
      const double m = M[p], V = VOL[p];
      const double pressure = PRESSURE[p];
      const double sxx = SXX[p] - pressure, syy = SYY[p] - pressure, sxy = SXY[p];
      const double mvx = m * VX[p], mvy = m * VY[p];
      // momentum affine Q = m C; MLS force affine S = -dt V D^-1 sigma (grad w ~ w D^-1 (x_i - x_p)).
      // Without FLIP both act on the same momentum and fold into one matrix.
      const double ks = K::mls ? -dt_ * V * Dinv_ : 0.0;
      const double s00 = ks * sxx, s01 = ks * sxy, s11 = ks * syy;
      double q00 = m * C00[p], q01 = m * C01[p], q10 = m * C10[p], q11 = m * C11[p];
      if constexpr (K::mls && !Flip) {
        q00 += s00;
        q01 += s01;
        q10 += s01;
        q11 += s11;
      }
      const double dx0 = bx * h - xp, dy0 = by * h - yp;
      if constexpr (K::mls && Flip) {
        // The default path (FLIP, MLS kernels). A node's first four fields (m, momentum, force
        // impulse x) take w (base + dxp colA + dyp colB) in one 4-wide update, w = wx wy. dxp varies
        // along a row only and dyp down a column only, so the column factors are formed once per
        // particle, U_a = wx_a (base + dxp_a colA) and V_a = wx_a colB, and each node takes
        // wy_b U_a + (wy_b dyp_b) V_a: two FMAs. The fifth field (force impulse y) the same way.
        // Consecutive points with the same stencil (the reorder sorts them together) sum into
        // `run`, which the grid takes once (StencilRun). Same sums as the scalar path, associated
        // differently (round-off; README, Performance).
        const Vec4d base = {m, mvx, mvy, 0.0}, colA = {0.0, q00, q10, s00}, colB = {0.0, q01, q11, s01};
        Vec4d Ua[K::N], Va[K::N];
        double u[K::N], v[K::N];
        for (int a = 0; a < K::N; ++a) {
          const double dxp = dx0 + a * h;
          Ua[a] = wx[a] * fma4(splat(dxp), colA, base);
          Va[a] = wx[a] * colB;
          u[a] = wx[a] * dxp * s01;
          v[a] = wx[a] * s11;
        }
        run.start(nodes + Grid::index(bx, by, NY));
        for (int b = 0; b < K::N; ++b) {
          const double wb = wy[b], wdb = wy[b] * (dy0 + b * h);
          for (int a = 0; a < K::N; ++a) {
            run.four[a][b] += fma4(splat(wb), Ua[a], wdb * Va[a]);
            run.fifth[b][a] += fma1(wb, u[a], wdb * v[a]);
          }
        }
        continue;
      }
      for (int b = 0; b < K::N; ++b) {
        GridNode* row = grid + g_.index(bx, by + b);
        const double dyp = dy0 + b * dx;
        for (int a = 0; a < K::N; ++a) {
          const double dxp = dx0 + a * dx;
          const double w = wx[a] * wy[b];
          GridNode& n = row[a * NY];
          n.m += w * m;
          n.vx += w * (mvx + q00 * dxp + q01 * dyp);
          n.vy += w * (mvy + q10 * dxp + q11 * dyp);
          if constexpr (!K::mls) {
            // true B-spline gradients for the internal force
            const double gxw = dwx[a] * wy[b], gyw = wx[a] * dwy[b];
            const double fx = -dt * V * (sxx * gxw + sxy * gyw), fy = -dt * V * (sxy * gxw + syy * gyw);
            if constexpr (Flip) {
              n.vx0 += fx;
              n.vy0 += fy;
            } else {
              n.vx += fx;
              n.vy += fy;
            }
          } else if constexpr (Flip) {
            // FLIP keeps the internal-force impulse apart so the pre-force velocity is known
            n.vx0 += w * (s00 * dxp + s01 * dyp);
            n.vy0 += w * (s01 * dxp + s11 * dyp);
          }
        }
      }
    }
    run.flush();
  };
  const int strips = int(strip_start_.size()) - 1;
  // P2G zeroes the grid as it goes, no pass of its own: colour 0's strip 2k owns the node columns
  // from its first, W (2k - 1) - 1, to the next even strip's first (the first and last tiles reach
  // the grid's edges). That tile holds every node the strip writes (W >= N + 1), the tiles cover
  // the grid, and an odd strip, whose nodes lie in the tiles of the even strips beside it, starts
  // after both end, so every node is zero before its first sum.
  // A tile is zeroed just before its strip scatters into it, so it is in cache for the sums, and the
  // zeroing scales with P2G (as a pass of its own it was 1% of a step and 1.0-1.6x on two threads:
  // memory and a thread wake-up; README, Performance).
  using W = StripWindow<K>;
  static_assert(K::N + 1 <= W::width, "a strip's nodes must lie in its tile");
  const int pairs = (strips + 1) / 2;
  auto zero_tile = [&, pairs](int k) {
    const long NX = g_.NX, NY = g_.NY;
    const long first = k == 0 ? 0 : std::clamp(long(W::width) * (2 * k - 1) - 1 + Grid::kPad, 0L, NX);
    const long last = k == pairs - 1 ? NX : std::clamp(long(W::width) * (2 * k + 1) - 1 + Grid::kPad, first, NX);
    std::fill(grid + first * NY, grid + last * NY, GridNode{});
  };
  // Both colours of strips in one parallel region, each strip scattered by `scatter`: an odd strip
  // shares nodes only with the even strips beside it, so it runs as soon as both are done, on the
  // thread that finished the second (no barrier between the colours). Each node still gets its
  // even strip's sums, then its odd strip's, as with a colour at a time: the same bits.
  auto in_colours = [&](const auto& scatter) {
    std::vector<std::atomic<int>> waiting(size_t(strips) / 2);  // odd strip 2k + 1's even neighbours
    for (int k = 0; k < strips / 2; ++k) waiting[size_t(k)].store(2 * k + 2 < strips ? 2 : 1, std::memory_order_relaxed);
    for_tasks(task_log_, StepPhase::P2G, size_t(pairs), [&](size_t task) {
      const int k = int(task);
      zero_tile(k);
      scatter(2 * k);
      for (int odd : {2 * k - 1, 2 * k + 1})  // acquire-release: the other neighbour's sums are seen
        if (odd > 0 && odd < strips && waiting[size_t(odd / 2)].fetch_sub(1, std::memory_order_acq_rel) == 1)
          scatter(odd);
    });
  };
#if defined(__AVX__)
  if constexpr (std::is_same_v<K, QuadraticKernel> && Flip) {
    if (by_four_) return in_colours([&](int strip) { p2g_strip_quadratic_by_four(strip); });
  }
#endif
  in_colours(scatter_strip);
}

// The default P2G (quadratic B-splines, FLIP) of one strip, four points at a time: a point per
// lane for its weights, stress and affine terms and the per-column factors of scatter_strip's
// default path; the scatter itself stays a point at a time, in the strip's order (the same sums
// in the same order: the same bits as scatter_strip, tested).
void Simulation::p2g_strip_quadratic_by_four(int strip) {
#if defined(__AVX__)
  using V = Vec4d;
  const double h = g_.dx, ih = 1.0 / h, dt = dt_s_, Dinv = QuadraticKernel::inv_D(ih);
  GridNode* const nodes = g_.node.data();
  const size_t NY = size_t(g_.NY);
  const Particles& P = p_;
  const V zero = {0, 0, 0, 0};
  StencilRun<3> run(NY);
  // points k..k+3 of the strip; count: a std::integral_constant 4 for a full group (plain loads),
  // a size_t for the strip's last, whose empty lanes take its last point and scatter nothing.
  // Inlined, so the grid's address and stride stay in registers across the scatter's stores.
  auto group = [&](const uint32_t k, const auto count) __attribute__((always_inline)) {
    auto gather = [&](const auto& a) {
      if (count == 4) return load4(a.data() + k);
      V v;
      for (size_t l = 0; l < 4; ++l) v[l] = double(a[k + std::min(l, size_t(count) - 1)]);
      return v;
    };
    const V xp = gather(P.x), yp = gather(P.y);
    V wx[3], wy[3];
    int bx[4], by[4];
    const V bxd = quadratic_weights_by_four(xp, ih, wx, bx), byd = quadratic_weights_by_four(yp, ih, wy, by);
    const V m = gather(P.mass), vol = gather(P.volume), pressure = gather(P.pressure);
    const V sxx = gather(P.sxx) - pressure, syy = gather(P.syy) - pressure, sxy = gather(P.sxy);
    const V mvx = m * gather(P.vx), mvy = m * gather(P.vy);
    const V ks = -dt * vol * Dinv;
    const V s00 = ks * sxx, s01 = ks * sxy, s11 = ks * syy;
    const V q00 = m * gather(P.c00), q01 = m * gather(P.c01), q10 = m * gather(P.c10), q11 = m * gather(P.c11);
    const V dx0 = bxd * h - xp, dy0 = byd * h - yp;
    V dxp[3], u[3], v[3], wdy[3];
    for (int a = 0; a < 3; ++a) {
      dxp[a] = dx0 + a * h;
      u[a] = wx[a] * dxp[a] * s01;
      v[a] = wx[a] * s11;
      wdy[a] = wy[a] * (dy0 + a * h);
    }
    // scatter_strip's column factors U_a = wx_a (base + dxp_a colA), V_a = wx_a colB, field by field
    // for the four points, then turned into a [m vx vy vx0] vector per point (a 4x4 transpose); the
    // fifth field's u_a, v_a as a vector over a per point, for StencilRun's rows
    V Ua[3][4], Va[3][4], uT[4], vT[4];
    for (int a = 0; a < 3; ++a) {
      transpose4(wx[a] * fma4(dxp[a], zero, m), wx[a] * fma4(dxp[a], q00, mvx), wx[a] * fma4(dxp[a], q10, mvy),
                 wx[a] * fma4(dxp[a], s00, zero), Ua[a]);
      transpose4(wx[a] * zero, wx[a] * q01, wx[a] * q11, wx[a] * s01, Va[a]);
    }
    transpose4(u[0], u[1], u[2], zero, uT);
    transpose4(v[0], v[1], v[2], zero, vT);
    for (size_t l = 0; l < count; ++l) {
      run.start(nodes + Grid::index(bx[l], by[l], NY));
      for (int b = 0; b < 3; ++b) {
        const V wb = lane(wy[b], int(l)), wdb = lane(wdy[b], int(l));
        for (int a = 0; a < 3; ++a) run.four[a][b] += fma4(wb, Ua[a][l], wdb * Va[a][l]);
        run.fifth[b] += fma4(wb, uT[l], wdb * vT[l]);
      }
    }
  };
  const uint32_t k0 = strip_start_[size_t(strip)], k1 = strip_start_[size_t(strip) + 1];
  uint32_t k = k0;
  for (; k + 4 <= k1; k += 4) group(k, std::integral_constant<size_t, 4>());
  if (k < k1) group(k, size_t(k1 - k));
  run.flush();
#else
  (void)strip;
#endif
}

// the instances Simulation's constructor picks from
template void Simulation::particles_to_grid<LinearKernel, true>();
template void Simulation::particles_to_grid<LinearKernel, false>();
template void Simulation::particles_to_grid<QuadraticKernel, true>();
template void Simulation::particles_to_grid<QuadraticKernel, false>();
template void Simulation::particles_to_grid<CubicKernel, true>();
template void Simulation::particles_to_grid<CubicKernel, false>();

}  // namespace furrow
