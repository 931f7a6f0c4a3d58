// G2P: grid velocities and the affine matrix back to the particles, the FLIP blend, advection and
// the safety net that puts a point left inside a body back on its surface.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <immintrin.h>
#include <type_traits>

#include "engine/bodies.hpp"
#include "engine/shape_functions.hpp"
#include "engine/simd4.hpp"
#include "engine/simulation.hpp"
#include "engine/simulation_detail.hpp"

namespace furrow {

namespace {

// G2P's safety net: a point that still ended inside the body is moved back onto its surface. Its
// velocity is left as it is: next step's contact takes the approach out of it at the nodes, through
// the same smooth share as everything else, and counts it in the body's force there. Removing it
// here, in one step and one point at a time, put single-step ticks of up to 13% on the force each
// time a point first reached a face (tests/README.md, 2026-12-04). Whether it acted.
inline bool put_back_on_surface(const BodyState& s, const Shape& shape, double dx, Vec2& x) {
  const Vec2 r = x - s.position_m;
  if (r.x() < s.lo_m.x() || r.y() < s.lo_m.y() || r.x() > s.hi_m.x() || r.y() > s.hi_m.y()) return false;
  const Vec2 q = s.to_body(x);
  const double d = shape_sdf(shape, q);
  if (d >= 0.0) return false;
  x -= d * s.to_world(shape_normal(shape, q, 1e-4 * dx));
  return true;
}

}  // namespace

// The default G2P (quadratic B-splines, FLIP) four points at a time, a point per lane: the
// weights and everything after the gather (affine matrix, FLIP update, advection, the margins).
// Only the gather from each point's nine nodes runs a point at a time (4-wide over the node's
// fields, as in g2p_range). Every point of the range takes this path, a range's last group with
// its empty lanes filled by its last point, so a point's bits do not depend on how the range
// was split among threads. Returns `end`, or `begin` to leave the range to g2p_range's loop.
size_t Simulation::g2p_quadratic_by_four(size_t begin, size_t end, G2PLocal& loc) {
#if !defined(__AVX__)
  return begin;  // _mm256_floor_pd: built without AVX, g2p_range's loop does it all
#else
  using V = Vec4d;
  constexpr size_t kMaxBodies = 8;  // more bodies (rare): g2p_range's loop
  const size_t nb = bodies_.size();
  if (nb > kMaxBodies) return begin;
  const double dx = g_.dx, ih = 1.0 / dx, dt = dt_s_, alpha = scene_.solver.flip_blend;
  const double sc = QuadraticKernel::inv_D(ih);
  const size_t NY = size_t(g_.NY);
  const GridNode* const grid = g_.node.data();
  // each body's box in world coordinates, a little wider: only a lane inside one goes on to the
  // safety net's own test
  double box[kMaxBodies][4];
  for (size_t b = 0; b < nb; ++b) {
    const BodyState& s = bodies_[b];
    const double pad = 1e-6 * dx;
    box[b][0] = s.position_m.x() + s.lo_m.x() - pad, box[b][1] = s.position_m.y() + s.lo_m.y() - pad;
    box[b][2] = s.position_m.x() + s.hi_m.x() + pad, box[b][3] = s.position_m.y() + s.hi_m.y() + pad;
  }
  const V zero = {0, 0, 0, 0}, lo = zero - dx, hx = zero + (scene_.domain.width_m + dx),
          hy = zero + (scene_.domain.height_m + dx);
  auto& P = p_;
  double *const X = P.x.data(), *const Y = P.y.data(), *const VX = P.vx.data(), *const VY = P.vy.data();
  const uint16_t* const home = home_strip_.data();

  // count: a std::integral_constant 4 for a full group (compiled apart: no lane tests), a size_t
  // for the last
  auto group = [&](const size_t p, const auto count) {
    auto load = [&](const double* a) {
      if (count == 4) return load4(a + p);
      V v;
      for (size_t l = 0; l < 4; ++l) v[l] = a[p + std::min(l, size_t(count) - 1)];
      return v;
    };
    auto store = [&](auto* a, const V& v) {
      using T = std::remove_reference_t<decltype(*a)>;
      if (count == 4) return store4(a + p, v);
      for (size_t l = 0; l < count; ++l) a[p + l] = T(v[l]);
    };
    const V xp = load(X), yp = load(Y);
    V wx[3], wy[3], wxd[3], wyd[3];
    int bx[4], by[4];
    const V bxd = quadratic_weights_by_four(xp, ih, wx, bx), byd = quadratic_weights_by_four(yp, ih, wy, by);
    for (int a = 0; a < 3; ++a) {
      wxd[a] = wx[a] * ((bxd + double(a)) * dx - xp);
      wyd[a] = wy[a] * ((byd + double(a)) * dx - yp);
    }
    // the gather of [vx vy vx0 vy0], as in g2p_range: per row R = sum wx g, S = sum wx dxp g
    V vel[4], ax[4], ay[4];
    for (int l = 0; l < 4; ++l) {
      V vl = zero, axl = zero, ayl = zero;
      const GridNode* const column0 = grid + Grid::index(bx[l], by[l], NY);
      const GridNode* const column[3] = {column0, column0 + NY, column0 + 2 * NY};
      for (int b = 0; b < 3; ++b) {
        V R = zero, S = zero;
        for (int a = 0; a < 3; ++a) {
          const V g = four_at(&column[a][b].vx);
          R += lane(wx[a], l) * g;
          S += lane(wxd[a], l) * g;
        }
        vl += lane(wy[b], l) * R;
        axl += lane(wy[b], l) * S;
        ayl += lane(wyd[b], l) * R;
      }
      vel[l] = vl, ax[l] = axl, ay[l] = ayl;
    }
    // back to a point per lane
    const V vx = {vel[0][0], vel[1][0], vel[2][0], vel[3][0]}, vy = {vel[0][1], vel[1][1], vel[2][1], vel[3][1]};
    const V ox = {vel[0][2], vel[1][2], vel[2][2], vel[3][2]}, oy = {vel[0][3], vel[1][3], vel[2][3], vel[3][3]};
    store(P.c00.data(), V{ax[0][0], ax[1][0], ax[2][0], ax[3][0]} * sc);
    store(P.c10.data(), V{ax[0][1], ax[1][1], ax[2][1], ax[3][1]} * sc);
    store(P.c01.data(), V{ay[0][0], ay[1][0], ay[2][0], ay[3][0]} * sc);
    store(P.c11.data(), V{ay[0][1], ay[1][1], ay[2][1], ay[3][1]} * sc);
    V x = xp + dt * vx, y = yp + dt * vy;
    V ux = vx + alpha * (load(VX) - ox), uy = vy + alpha * (load(VY) - oy);
    // the safety net (g2p_range's), for the lanes in a body's box
    for (size_t b = 0; b < nb; ++b) {
      const auto in = (x >= box[b][0]) & (y >= box[b][1]) & (x <= box[b][2]) & (y <= box[b][3]);
      for (size_t l = 0; l < count; ++l) {
        if (!in[l]) continue;
        Vec2 xl(x[l], y[l]);
        if (!put_back_on_surface(bodies_[b], scene_.bodies[b].shape, dx, xl)) continue;
        ++loc.projected;
        x[l] = xl.x(), y[l] = xl.y();
      }
    }
    // the grid margin bounds where a point may go (g2p_range's std::max / std::min)
    auto out = x < lo;
    x = out ? lo : x, ux = out ? (ux < 0.0 ? zero : ux) : ux;
    out = x > hx;
    x = out ? hx : x, ux = out ? (0.0 < ux ? zero : ux) : ux;
    out = y < lo;
    y = out ? lo : y, uy = out ? (uy < 0.0 ? zero : uy) : uy;
    out = y > hy;
    y = out ? hy : y, uy = out ? (0.0 < uy ? zero : uy) : uy;
    const V dy = y - yp;  // strip_rows_of_bases' drift
    for (size_t l = 0; l < count; ++l) loc.dy_max_m = std::max(loc.dy_max_m, std::abs(dy[l]));
    store(X, x);
    store(Y, y);
    store(VX, ux);
    store(VY, uy);
    const V speed2 = fma4(ux, ux, uy * uy);  // as g2p_range's: the largest sets the next dt
    for (size_t l = 0; l < count; ++l) loc.vmax2 = std::max(loc.vmax2, speed2[l]);
    // the next P2G's stencil base, by its own arithmetic: still in the point's strip window?
    V wn[3];
    int unused[4];
    const __m128i base = _mm256_cvttpd_epi32((__m256d)quadratic_weights_by_four(x, ih, wn, unused));
    __m128i strip;
    if (count == 4) {
      strip = _mm_cvtepu16_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(home + p)));
    } else {
      int h[4];
      for (size_t l = 0; l < 4; ++l) h[l] = home[p + std::min(l, size_t(count) - 1)];
      strip = _mm_loadu_si128(reinterpret_cast<const __m128i*>(h));
    }
    loc.strayed |= !StripWindow<QuadraticKernel>::holds4(strip, base);
  };
  size_t p = begin;
  for (; p + 4 <= end; p += 4) group(p, std::integral_constant<size_t, 4>());
  if (p < end) group(p, end - p);
  return end;
#endif
}

template <class K, bool Flip>
void Simulation::g2p_range(size_t begin, size_t end, G2PLocal& loc) {
  const double dx = g_.dx, inv_dx = 1.0 / dx, dt = dt_s_, alpha = scene_.solver.flip_blend;
  const double Dinv = K::inv_D(inv_dx);
  const double xmax = scene_.domain.width_m, ymax = scene_.domain.height_m;
  const size_t nb = bodies_.size();
  auto& P = p_;
  if constexpr (std::is_same_v<K, QuadraticKernel> && Flip)
    if (by_four_) begin = g2p_quadratic_by_four(begin, end, loc);
  const size_t NY = size_t(g_.NY);
  for (size_t p = begin; p < end; ++p) {
    double wx[K::N], wy[K::N], dwx[K::N], dwy[K::N];
    const double xp = P.x[p], yp = P.y[p];
    const int bx = K::weights(xp * inv_dx, wx, dwx, inv_dx);
    const int by = K::weights(yp * inv_dx, wy, dwy, inv_dx);
    double vx = 0, vy = 0, b00 = 0, b01 = 0, b10 = 0, b11 = 0, ox = 0, oy = 0;
    if constexpr (K::mls && Flip) {
      // The default path (FLIP, MLS kernels): a node's last four fields g = [vx vy vx0 vy0] are
      // read 4-wide. dxp varies along a row only and dyp down a column only, so each row b sums
      // R_b = sum_a wx_a g and S_b = sum_a wx_a dxp_a g (two FMAs a node), and the particle takes
      // [vx vy ox oy] = sum_b wy_b R_b, [b00 b10] = sum_b wy_b S_b, [b01 b11] = sum_b wy_b dyp_b R_b.
      // Same sums as the scalar path, associated differently (round-off; README, Performance).
      double wxd[K::N];
      for (int a = 0; a < K::N; ++a) wxd[a] = wx[a] * ((bx + a) * dx - xp);
      Vec4d vel = {0, 0, 0, 0}, ax = {0, 0, 0, 0}, ay = {0, 0, 0, 0};
      for (int b = 0; b < K::N; ++b) {
        const GridNode* row = &g_.node[g_.index(bx, by + b)];
        Vec4d R = {0, 0, 0, 0}, S = {0, 0, 0, 0};
        for (int a = 0; a < K::N; ++a) {
          const Vec4d g = four_at(&row[a * NY].vx);
          R += wx[a] * g;
          S += wxd[a] * g;
        }
        vel += wy[b] * R;
        ax += wy[b] * S;
        ay += (wy[b] * ((by + b) * dx - yp)) * R;
      }
      vx = vel[0], vy = vel[1], ox = vel[2], oy = vel[3];
      b00 = ax[0], b10 = ax[1], b01 = ay[0], b11 = ay[1];
    } else {
      for (int b = 0; b < K::N; ++b) {
        const GridNode* row = &g_.node[g_.index(bx, by + b)];
        const double dyp = (by + b) * dx - yp;
        for (int a = 0; a < K::N; ++a) {
          const double w = wx[a] * wy[b];
          const GridNode& n = row[a * NY];
          const double gvx = n.vx, gvy = n.vy;
          vx += w * gvx;
          vy += w * gvy;
          if constexpr (Flip) {
            ox += w * n.vx0;
            oy += w * n.vy0;
          }
          if constexpr (K::mls) {
            const double dxp = (bx + a) * dx - xp;
            b00 += w * gvx * dxp;
            b01 += w * gvx * dyp;
            b10 += w * gvy * dxp;
            b11 += w * gvy * dyp;
          } else {
            const double gxw = dwx[a] * wy[b], gyw = wx[a] * dwy[b];
            b00 += gvx * gxw;
            b01 += gvx * gyw;
            b10 += gvy * gxw;
            b11 += gvy * gyw;
          }
        }
      }
    }
    if constexpr (!K::mls) {
      // The linear kernel's light-node guard. A hat's gradient does not vanish with its weight, so
      // a node this point barely reaches, and no other point does, takes a finite force impulse on
      // a vanishing mass: its velocity is unbounded and so was the gradient read from it (a column's
      // impact: |C| 1.1e5 1/s against ~200 with quadratic, then a volume overflowing to inf). Such a
      // node (mass under kLightNodeShare of the point's) enters the gradient with the point's own
      // interpolated velocity instead: sum_i grad w_i = 0, so it then adds nothing, and a node's
      // velocity error, m_p / m_i times a normal one, stays under 1 / kLightNodeShare. Where no node
      // is that light (a dense bed) nothing changes, bit for bit (tests/README.md, 2026-12-06).
      constexpr double kLightNodeShare = 0.05;
      const double light_kg = kLightNodeShare * double(P.mass[p]);
      for (int b = 0; b < K::N; ++b) {
        const GridNode* row = &g_.node[g_.index(bx, by + b)];
        for (int a = 0; a < K::N; ++a) {
          const GridNode& n = row[a * NY];
          if (!(n.m < light_kg)) continue;
          const double gxw = dwx[a] * wy[b], gyw = wx[a] * dwy[b];
          b00 -= (n.vx - vx) * gxw, b01 -= (n.vx - vx) * gyw;
          b10 -= (n.vy - vy) * gxw, b11 -= (n.vy - vy) * gyw;
        }
      }
    }
    const double sc = K::mls ? Dinv : 1.0;
    P.c00[p] = b00 * sc;
    P.c01[p] = b01 * sc;
    P.c10[p] = b10 * sc;
    P.c11[p] = b11 * sc;
    // positions move with the grid velocity; FLIP keeps part of the particle's own velocity
    Vec2 x(xp + dt * vx, yp + dt * vy), v(vx, vy);
    if constexpr (Flip) v += alpha * Vec2(P.vx[p] - ox, P.vy[p] - oy);
    // the safety net: a particle that still ended inside a body is put back on its surface
    for (size_t b = 0; b < nb; ++b)
      if (put_back_on_surface(bodies_[b], scene_.bodies[b].shape, dx, x)) ++loc.projected;
    // the grid margin bounds where a particle may go; walls normally stop it well before
    if (x.x() < -dx) { x.x() = -dx; v.x() = std::max(v.x(), 0.0); }
    if (x.x() > xmax + dx) { x.x() = xmax + dx; v.x() = std::min(v.x(), 0.0); }
    if (x.y() < -dx) { x.y() = -dx; v.y() = std::max(v.y(), 0.0); }
    if (x.y() > ymax + dx) { x.y() = ymax + dx; v.y() = std::min(v.y(), 0.0); }
    P.x[p] = x.x();
    P.y[p] = x.y();
    P.vx[p] = v.x();
    P.vy[p] = v.y();
    loc.vmax2 = std::max(loc.vmax2, fma1(v.x(), v.x(), v.y() * v.y()));  // as the four-wide path's
    loc.dy_max_m = std::max(loc.dy_max_m, std::abs(x.y() - yp));
    loc.strayed |= !StripWindow<K>::holds(home_strip_[p], K::base(x.x() * inv_dx));
  }
}

// the instances Simulation's constructor picks from
template void Simulation::g2p_range<LinearKernel, true>(size_t, size_t, G2PLocal&);
template void Simulation::g2p_range<LinearKernel, false>(size_t, size_t, G2PLocal&);
template void Simulation::g2p_range<QuadraticKernel, true>(size_t, size_t, G2PLocal&);
template void Simulation::g2p_range<QuadraticKernel, false>(size_t, size_t, G2PLocal&);
template void Simulation::g2p_range<CubicKernel, true>(size_t, size_t, G2PLocal&);
template void Simulation::g2p_range<CubicKernel, false>(size_t, size_t, G2PLocal&);

}  // namespace furrow
