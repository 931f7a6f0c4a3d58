// Particle contact (solver.contact "particle"): impulses on the material points that would reach a
// body, solved by Gauss-Seidel over the points.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "engine/bodies.hpp"
#include "engine/shape_functions.hpp"
#include "engine/simulation.hpp"
#include "engine/simulation_detail.hpp"

namespace furrow {

// Particle contact: the material points whose surface (centre + half their size) would reach a
// body within this step are held to its normal velocity (Coulomb slip along it) by impulses
// scattered onto the grid through their own weights, solved by Gauss-Seidel over the points.
// The constraint follows the points, not the node lines, so the force moves smoothly as a face
// crosses the grid, and it starts when the surfaces meet.
template <class K>
void Simulation::contact_particles() {
  find_contact_points<K>();
  solve_contact_points<K>();
}

// The points in (or about to be in) contact, with their stencils, normals and gaps; impulses
// start from the last step's (warm start).
template <class K>
void Simulation::find_contact_points() {
  const double dx = g_.dx, inv_dx = 1.0 / dx;
  const size_t nb = bodies_.size();
  const auto& P = p_;
  // candidates: points within two cells of a body's box (no point moves a cell in a step), found
  // in the strips and rows whose points may lie there (body_strip_span, strip_rows_of_bases), then put
  // in (particle, body) order so the list is the same for any thread count
  const double reach = 2.0 * dx;
  const int strips = int(strip_start_.size()) - 1;
  contact_chunks_.resize(size_t(strips) * nb);
  std::vector<std::pair<int, int>> spans(nb);
  for (size_t b = 0; b < nb; ++b) {
    const BodyState& s = bodies_[b];
    spans[b] = body_strip_span<K>(s, reach, inv_dx, strips);
  }
  for_tasks(task_log_, StepPhase::Contact, contact_chunks_.size(), [&](size_t k) {
    const size_t b = k / size_t(strips);
    const int strip = int(k % size_t(strips));
    auto& out = contact_chunks_[k];
    out.clear();
    if (strip < spans[b].first || strip > spans[b].second) return;
    const BodyState& s = bodies_[b];
    const double y_lo = s.position_m.y() + s.lo_m.y() - reach, y_hi = s.position_m.y() + s.hi_m.y() + reach;
    const auto [first, end] = strip_rows_of_bases(strip, K::base(y_lo * inv_dx), K::base(y_hi * inv_dx));
    for (uint32_t p = first; p < end; ++p) {
      const Vec2 q = Vec2(P.x[p], P.y[p]) - s.position_m;
      if (q.x() < s.lo_m.x() - reach || q.y() < s.lo_m.y() - reach || q.x() > s.hi_m.x() + reach ||
          q.y() > s.hi_m.y() + reach)
        continue;
      out.push_back(p);
    }
  });
  std::vector<uint64_t> keys;
  for (size_t k = 0; k < contact_chunks_.size(); ++k)
    for (uint32_t p : contact_chunks_[k]) keys.push_back(uint64_t(p) << 32 | uint64_t(k / size_t(strips)));
  std::sort(keys.begin(), keys.end());
  std::vector<uint32_t> cand(2 * keys.size());
  for (size_t k = 0; k < keys.size(); ++k) {
    cand[2 * k] = uint32_t(keys[k] >> 32);
    cand[2 * k + 1] = uint32_t(keys[k] & 0xffffffffu);
  }
  const size_t nc = keys.size();
  // the last step's impulses start the solve (warm start): a steady contact then needs few sweeps
  std::vector<ContactPoint> previous;
  previous.swap(contacts_);
  contacts_.resize(nc);
  std::vector<uint8_t> keep(nc, 0);
  const bool friction = scene_.effects.body_friction;
  for_tasks(task_log_, StepPhase::Contact, nc, [&](size_t k) {
    const uint32_t p = cand[2 * k], b = cand[2 * k + 1];
    const BodyState& s = bodies_[b];
    const Shape& shape = scene_.bodies[b].shape;
    const Vec2 q = s.to_body(Vec2(P.x[p], P.y[p]));
    const double half = 0.5 * std::sqrt(P.volume[p]);
    const double gap = shape_sdf(shape, q) - half;
    if (gap > dx) return;
    ContactPoint& c = contacts_[k];
    double wx[K::N], wy[K::N], dwx[K::N], dwy[K::N];
    const int bx = K::weights(P.x[p] * inv_dx, wx, dwx, inv_dx);
    const int by = K::weights(P.y[p] * inv_dx, wy, dwy, inv_dx);
    c.base = g_.index(bx, by);
    // the impulse goes to the nodes in proportion to the point's weights (the least mass-weighted
    // change of the node velocities that moves the point as required)
    double sum = 0.0;
    for (int j = 0; j < K::N; ++j)
      for (int i = 0; i < K::N; ++i) {
        const double w = wx[i] * wy[j];
        c.w[j * K::N + i] = w;
        const double m = g_.node[c.base + size_t(j) + size_t(i) * size_t(g_.NY)].m;
        if (m > 0.0) sum += w * w / m;
      }
    c.inv_meff = sum;
    c.n = s.to_world(shape_normal(shape, q, 1e-4 * dx));
    c.vb = s.velocity_at(Vec2(P.x[p], P.y[p]));
    c.gap_m = gap;
    c.mu = friction ? scene_.bodies[b].friction : 0.0;
    c.jn = c.jt = 0.0;
    c.particle = p;
    c.body = b;
    keep[k] = sum > 0.0;
  });
  // a point near two bodies whose faces point the same way (under the joint of touching plates)
  // is held by the nearer one only: two parallel constraints would split its impulse between the
  // bodies by the order of the sweep
  for (size_t k = 0; k + 1 < nc; ++k) {
    if (!keep[k] || !keep[k + 1] || cand[2 * k] != cand[2 * k + 2]) continue;
    const ContactPoint &a = contacts_[k], &b = contacts_[k + 1];
    if (a.n.dot(b.n) > 0.5) keep[b.gap_m < a.gap_m ? k : k + 1] = 0;
  }
  size_t m = 0;
  for (size_t k = 0; k < nc; ++k)
    if (keep[k]) contacts_[m++] = contacts_[k];
  contacts_.resize(m);
  // both lists are sorted by (particle, body)
  for (size_t k = 0, o = 0; k < contacts_.size() && o < previous.size();) {
    ContactPoint& c = contacts_[k];
    const ContactPoint& q = previous[o];
    if (q.particle < c.particle || (q.particle == c.particle && q.body < c.body)) {
      ++o;
    } else if (q.particle == c.particle && q.body == c.body) {
      c.jn = q.jn;
      c.jt = std::clamp(q.jt, -c.mu * c.jn, c.mu * c.jn);
      apply_contact_impulse<K>(c, c.impulse());
      ++k, ++o;
    } else {
      ++k;
    }
  }
}

// Adds impulse J (N s per metre) at point c to the node velocities, shared by its weights.
template <class K>
void Simulation::apply_contact_impulse(const ContactPoint& c, const Vec2& J) {
  GridNode* grid = g_.node.data();
  for (int j = 0; j < K::N; ++j)
    for (int i = 0; i < K::N; ++i) {
      GridNode& nd = grid[c.base + size_t(j) + size_t(i) * size_t(g_.NY)];
      if (nd.m <= 0.0) continue;
      const double f = c.w[j * K::N + i] / nd.m;
      nd.vx += f * J.x();
      nd.vy += f * J.y();
    }
}

// Gauss-Seidel over the points until the largest velocity change of a sweep is below 1e-5 of the
// bodies' speed; the bodies' forces are minus the impulses they gave.
template <class K>
void Simulation::solve_contact_points() {
  const double dt = dt_s_;
  const size_t nb = bodies_.size();
  const GridNode* grid = g_.node.data();
  const size_t NY = size_t(g_.NY);
  double vscale = 1e-3;
  for (const auto& s : bodies_) vscale = std::max(vscale, s.velocity_m_s.norm());
  const double tol = 1e-5 * vscale;
  constexpr int kMaxSweeps = 200;
  int sweep = 0;
  double residual = 0.0;
  for (; sweep < kMaxSweeps; ++sweep) {
    residual = 0.0;
    for (ContactPoint& c : contacts_) {
      double vx = 0.0, vy = 0.0;
      for (int j = 0; j < K::N; ++j)
        for (int i = 0; i < K::N; ++i) {
          const GridNode& nd = grid[c.base + size_t(j) + size_t(i) * NY];
          const double w = c.w[j * K::N + i];
          vx += w * nd.vx;
          vy += w * nd.vy;
        }
      const Vec2 rel = Vec2(vx, vy) - c.vb, t = c.tangent();
      const double meff = 1.0 / c.inv_meff;
      // normal: approach no faster than closes the gap in this step; impulses only push
      const double vn = rel.dot(c.n), target = -std::max(c.gap_m, 0.0) / dt;
      const double jn = std::max(0.0, c.jn + meff * (target - vn));
      // tangential: stop the slip, within the Coulomb cone of the normal impulse
      const double jt = std::clamp(c.jt - meff * rel.dot(t), -c.mu * jn, c.mu * jn);
      const Vec2 J = (jn - c.jn) * c.n + (jt - c.jt) * t;
      c.jn = jn;
      c.jt = jt;
      if (J.x() == 0.0 && J.y() == 0.0) continue;
      residual = std::max(residual, J.norm() * c.inv_meff);
      apply_contact_impulse<K>(c, J);
    }
    if (residual <= tol) break;
  }
  std::vector<Vec2> impulse(nb, Vec2(0.0, 0.0));
  std::vector<double> angular(nb, 0.0);
  for (const ContactPoint& c : contacts_) {
    impulse[c.body] += c.impulse();
    const Vec2 r = Vec2(p_.x[c.particle], p_.y[c.particle]) - bodies_[c.body].position_m, J = c.impulse();
    angular[c.body] += r.x() * J.y() - r.y() * J.x();
  }
  for (size_t b = 0; b < nb; ++b) {
    bodies_[b].force_N_per_m = -impulse[b] / dt;
    bodies_[b].torque_N = -angular[b] / dt;
  }
  stats_.contact_points = int64_t(contacts_.size());
  stats_.contact_sweeps = std::min(sweep + 1, kMaxSweeps);
  stats_.contact_residual_m_s = residual;
  stats_.contact_converged = residual <= tol;
}

// the instances Simulation's constructor picks from
template void Simulation::contact_particles<LinearKernel>();
template void Simulation::contact_particles<QuadraticKernel>();
template void Simulation::contact_particles<CubicKernel>();

}  // namespace furrow
