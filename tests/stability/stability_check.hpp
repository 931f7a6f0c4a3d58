// One checker for every stability case: run a Simulation step by step and, after each step (or
// every few steps), assert that the state is finite, inside the domain and outside the bodies,
// that mass is conserved exactly and that the media never hold more kinetic energy than was put
// into them.
//
// The energy bound. For the continuum, over [0, t]:
//   KE(t) + E_el(t) + D(t) = KE(0) + E_el(0) + W_gravity(t) + W_bodies(t) + W_walls(t)
// with E_el >= 0 the stored elastic energy (volumetric K V_d (1 - (1 + e) e^-e), e = P / K, the
// integral of -P dV for P = K ln(phi / phi_d); deviatoric V s:s / 4G), D >= 0 the plastic
// dissipation and W_walls <= 0 (slip walls do no work, friction and sticky walls only take energy
// out). D >= 0 because the model is rate-independent with a radial return onto tau = mu P: its
// plastic power is s:D_p = tau dgamma >= 0, and opening (stress-free) only throws stored energy
// away. In the dilatant model the plastic volume change works against the pressure, but the
// friction it adds pays for it: sigma:D_p = s:D_p - P tr(D_p) = P dgamma (mu_c + chi (phi_d -
// phi_c)^2 / phi_d) >= 0 (tr D_p = chi phi_c (phi_d - phi_c) / phi_d dgamma from the phi_d law).
// Dropping E_el(t) >= 0, D and W_walls leaves
//   KE(t) <= KE(0) + E_el(0) + W_gravity(t) + W_bodies(t).
// (V s:s / 4G is the energy of the hypoelastic deviator only up to a term of relative size the
// volume strain, ~1e-3 here; the tolerance below is far larger.)
// W_gravity = g . sum_p m_p (x_p(t) - x_p(0)) is exactly minus the potential change; it is taken as
// g . (sum m x now - sum m x at 0), which needs no particle identity (the solver reorders its
// arrays). W_bodies = sum over steps of -F_body . v_body dt, the work the prescribed bodies did on
// the media (F_body the media's reaction on the body, v_body the velocity that step used).
//
// Tolerance of the explicit scheme. The solver advances velocities with the stress of the start of
// the step and positions with the new velocities (symplectic Euler). For that scheme the conserved
// energy of an elastic system is not KE + E_el but KE + E_el - dt/2 SP, SP = sum_p V_p sigma:L_p the
// stress power of the state at the end of the step (velocity and stress are half a step apart).
// So the kinetic energy after a step may exceed the continuum budget by dt/2 max(SP, 0), plus the
// same term of the initial state (zero at rest). Gravity and the bodies need nothing: their work is
// counted with the end-of-step velocities, which over-counts what the step gives (dKE = F.v_new dt
// - m |dv|^2 / 2). The transfers take kinetic energy out (PIC/APIC: a node's velocity is a mass
// average; the affine part APIC carries in C is left out of the KE measured here) or, FLIP, keep
// it to first order. Beyond that only round-off: the sums (long double over at
// most 1e6 terms or steps) are exact to far below 1e-10 of the energy scale
// KE(0) + E_el(0) + sum |dW_bodies| + M |g| (W + H).
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "engine/bodies.hpp"
#include "engine/materials.hpp"
#include "engine/simulation.hpp"

namespace furrow::stability {

// Stored elastic energy (J per metre out of plane) of the material points.
inline double elastic_energy_J_per_m(const Simulation& sim) {
  const Scene& s = sim.scene();
  std::vector<MaterialParams> mats;
  for (const auto& m : s.materials) mats.push_back(MaterialParams::from(m, s.effects.separation));
  const Particles& p = sim.particles();
  long double e_sum = 0.0L;
  for (size_t i = 0; i < p.size(); ++i) {
    const MaterialParams& mp = mats[p.material[i]];
    const double phi_d = p.phi_d.empty() ? mp.phi_c : p.phi_d[i];
    // P = K ln(phi / phi_d) = K e; dE = -P dV gives K V_d (1 - (1 + e) e^-e), V_d = m / (rho_g phi_d)
    const double e = p.pressure[i] / mp.K;
    const double v_dense = p.mass[i] / (mp.rho_g * phi_d);
    const double vol = mp.K * v_dense * -std::expm1(-e) - mp.K * v_dense * e * std::exp(-e);
    const double ss = p.sxx[i] * p.sxx[i] + p.syy[i] * p.syy[i] + p.szz[i] * p.szz[i] + 2.0 * p.sxy[i] * p.sxy[i];
    e_sum += vol + p.volume[i] * ss / (4.0 * mp.G);
  }
  return double(e_sum);
}

// Stress power sum_p V sigma:L (W per metre); sigma_zz does no work in plane strain (L_zz = 0).
inline double stress_power_W_per_m(const Particles& p) {
  long double sp = 0.0L;
  for (size_t i = 0; i < p.size(); ++i) {
    const double sxx = p.sxx[i] - p.pressure[i], syy = p.syy[i] - p.pressure[i], sxy = p.sxy[i];
    sp += p.volume[i] * (sxx * p.c00[i] + sxy * (p.c01[i] + p.c10[i]) + syy * p.c11[i]);
  }
  return double(sp);
}

// sum_p m_p x_p (kg m per metre), long double so that differences of it are exact enough
inline std::array<long double, 2> mass_moment(const Particles& p) {
  long double sx = 0.0L, sy = 0.0L;
  for (size_t i = 0; i < p.size(); ++i) {
    sx += (long double)p.mass[i] * p.x[i];
    sy += (long double)p.mass[i] * p.y[i];
  }
  return {sx, sy};
}

// How much of its weight the material carries as stress, resting on the floor at y = 0: the
// vertical virial -sum_p V_p sigma_yy over the weight's moment about the floor g sum_p m_p y_p. At
// rest the two are equal in the continuum (the integral of sigma_yy is that of y times the body
// force; the floor's reaction acts at y = 0, free surfaces carry nothing), so this reads 1; a heap
// of stress-free points reads 0. On the grid the identity is exact (the B-splines reproduce y)
// except that nodes one cell below the floor line take part of the reaction too, which adds up to
// dx / y_m of it, y_m = sum m y / sum m (floor_reaction_excess_bound).
inline double weight_carried_fraction(const Particles& p, double g_m_s2) {
  long double virial = 0.0L, moment = 0.0L;
  for (size_t i = 0; i < p.size(); ++i) {
    virial += (long double)p.volume[i] * (double(p.pressure[i]) - double(p.syy[i]));
    moment += (long double)p.mass[i] * g_m_s2 * p.y[i];
  }
  return double(virial / moment);
}

inline double floor_reaction_excess_bound(const Particles& p, double dx_m) {
  long double my = 0.0L, m = 0.0L;
  for (size_t i = 0; i < p.size(); ++i) my += (long double)p.mass[i] * p.y[i], m += p.mass[i];
  return dx_m / double(my / m);
}

inline long double mass_sum(const Particles& p) {
  long double m = 0.0L;
  for (double mi : p.mass) m += mi;
  return m;
}

// Deepest particle centre inside any body (m; <= 0 when none is inside).
inline double max_penetration_m(const Simulation& sim) {
  double pen = 0.0;
  const Particles& p = sim.particles();
  for (size_t b = 0; b < sim.bodies().size(); ++b) {
    const BodyState& s = sim.bodies()[b];
    const Shape& shape = sim.scene().bodies[b].shape;
    for (size_t i = 0; i < p.size(); ++i) {
      const Vec2 q = Vec2(p.x[i], p.y[i]) - s.position_m;
      if (q.x() < s.lo_m.x() || q.y() < s.lo_m.y() || q.x() > s.hi_m.x() || q.y() > s.hi_m.y()) continue;
      pen = std::max(pen, -shape_sdf(shape, q));
    }
  }
  return pen;
}

class Checker {
 public:
  explicit Checker(const Simulation& sim)
      : n0_(sim.particles().size()),
        m0_(mass_sum(sim.particles())),
        ke0_(sim.kinetic_energy()),
        el0_(elastic_energy_J_per_m(sim)),
        mx0_(mass_moment(sim.particles())) {
    const Scene& s = sim.scene();
    g_ = s.effects.gravity ? s.effects.gravity_m_s2 : Vec2(0.0, 0.0);
    // start state: its half-step term (zero at rest) and the energy scale of the round-off
    slack0_J_ = 0.5 * sim.next_dt_s() * std::max(0.0, -stress_power_W_per_m(sim.particles()));
    scale_J_ = ke0_ + el0_ + double(m0_) * g_.norm() * (s.domain.width_m + s.domain.height_m);
    quarter_cell_m_ = 0.25 * s.domain.dx_m;
  }

  // Call before each step: the body velocities the step will use.
  void before_step(const Simulation& sim) {
    v_body_.clear();
    for (const auto& b : sim.bodies()) v_body_.push_back(b.velocity_m_s);
  }

  // Call after each step; `full` runs the O(particles) checks, the work sum is kept every step.
  ::testing::AssertionResult after_step(const Simulation& sim, bool full) {
    const double dt = sim.last_dt_s();
    for (size_t b = 0; b < sim.bodies().size(); ++b) {
      const Vec2 f = sim.bodies()[b].force_N_per_m;
      if (!f.allFinite()) return fail(sim) << "body " << b << " force not finite: " << f.transpose();
      const double dw = -f.dot(v_body_[b]) * dt;
      w_bodies_J_ += dw;
      w_bodies_abs_J_ += std::abs(dw);
    }
    for (const Vec2& f : sim.wall_forces())
      if (!f.allFinite()) return fail(sim) << "wall force not finite: " << f.transpose();
    if (!full) return ::testing::AssertionSuccess();
    if (auto r = check_state(sim); !r) return r;
    return check_energy(sim);
  }

  double initial_elastic_energy_J() const { return el0_; }
  double bodies_work_J() const { return double(w_bodies_J_); }
  double max_penetration_seen_m() const { return max_pen_m_; }
  // largest KE / (energy budget + tolerance) seen: < 1 passes
  double max_energy_ratio() const { return max_ratio_; }
  double max_kinetic_energy_J() const { return max_ke_J_; }
  // largest share of the tolerance in budget + tolerance: how much the half-step term matters
  double max_tolerance_share() const { return max_tol_share_; }

 private:
  ::testing::AssertionResult fail(const Simulation& sim) const {
    return ::testing::AssertionFailure() << "step " << sim.step_count() << ", t = " << sim.time_s() << " s: ";
  }

  ::testing::AssertionResult check_state(const Simulation& sim) {
    const Particles& p = sim.particles();
    if (p.size() != n0_) return fail(sim) << "particle count " << p.size() << " != " << n0_;
    // masses never change, only their order: two long double sums of the same n positive terms
    // differ by at most 2 (n - 1) u of the total, u = eps / 2 (~1e-15 at 1e4 points)
    const long double m = mass_sum(p);
    if (std::abs(m - m0_) > 2.0L * (long double)n0_ * std::numeric_limits<long double>::epsilon() * m0_)
      return fail(sim) << "mass " << double(m) << " != initial " << double(m0_);
    // every per-point array, of either stored precision (float or double, engine/simulation.hpp)
    const char* bad = nullptr;
    size_t bad_i = 0;
    double bad_value = 0.0;
    p.for_each_array([&](const char* name, const auto& a) {
      for (size_t i = 0; i < a.size() && !bad; ++i)
        if (!std::isfinite(double(a[i]))) bad = name, bad_i = i, bad_value = double(a[i]);
    });
    if (bad) return fail(sim) << bad << " of particle " << bad_i << " is " << bad_value;
    for (size_t i = 0; i < p.size(); ++i)
      if (!(p.volume[i] > 0.0)) return fail(sim) << "volume of particle " << i << " is " << p.volume[i];
    for (size_t k = 0; k < sim.grid().node.size(); ++k) {
      const GridNode& n = sim.grid().node[k];
      if (!std::isfinite(n.m) || !std::isfinite(n.vx) || !std::isfinite(n.vy) || !std::isfinite(n.vx0) ||
          !std::isfinite(n.vy0) || n.m < 0.0)
        return fail(sim) << "grid node " << k << ": m " << n.m << ", v (" << n.vx << ", " << n.vy << ")";
    }
    // the domain: walls act on node lines like node contact on a body, so the same quarter cell
    // bounds how far a point may stand past one; no scene here lets material leave by an open side
    const Domain& d = sim.scene().domain;
    const double q = quarter_cell_m_;
    for (size_t i = 0; i < p.size(); ++i)
      if (p.x[i] < -q || p.x[i] > d.width_m + q || p.y[i] < -q || p.y[i] > d.height_m + q)
        return fail(sim) << "particle " << i << " at (" << p.x[i] << ", " << p.y[i] << ") is outside the domain";
    const double pen = max_penetration_m(sim);
    max_pen_m_ = std::max(max_pen_m_, pen);
    if (pen > q) return fail(sim) << "a particle is " << pen << " m inside a body (> dx/4 = " << q << ")";
    return ::testing::AssertionSuccess();
  }

  ::testing::AssertionResult check_energy(const Simulation& sim) {
    const Particles& p = sim.particles();
    const auto mx = mass_moment(p);
    const double w_gravity = double(g_.x() * (mx[0] - mx0_[0]) + g_.y() * (mx[1] - mx0_[1]));
    const double w_bodies = double(w_bodies_J_);
    const double budget = ke0_ + el0_ + w_gravity + w_bodies;
    const double h = std::max(sim.last_dt_s(), sim.next_dt_s());
    const double sp = stress_power_W_per_m(p);
    const double tol = 0.5 * h * std::max(sp, 0.0) + slack0_J_ + 1e-10 * (scale_J_ + double(w_bodies_abs_J_));
    const double ke = sim.kinetic_energy();
    max_ke_J_ = std::max(max_ke_J_, ke);
    if (budget + tol > 0.0) max_ratio_ = std::max(max_ratio_, ke / (budget + tol));
    max_tol_share_ = std::max(max_tol_share_, tol / (std::abs(budget) + tol));
    if (ke > budget + tol)
      return fail(sim) << "kinetic energy " << ke << " J/m exceeds the energy put in " << budget
                       << " J/m (KE0 " << ke0_ << ", E_el0 " << el0_ << ", W_gravity " << w_gravity
                       << ", W_bodies " << w_bodies << ") + tolerance " << tol << " (dt/2 SP = "
                       << 0.5 * h * std::max(sp, 0.0) << ")";
    return ::testing::AssertionSuccess();
  }

  size_t n0_;
  long double m0_;
  double ke0_, el0_;
  std::array<long double, 2> mx0_;
  Vec2 g_{0, 0};
  double slack0_J_ = 0.0, scale_J_ = 0.0, quarter_cell_m_ = 0.0;
  std::vector<Vec2> v_body_;
  long double w_bodies_J_ = 0.0L, w_bodies_abs_J_ = 0.0L;
  double max_pen_m_ = 0.0, max_ratio_ = 0.0, max_ke_J_ = 0.0, max_tol_share_ = 0.0;
};

// Runs sim to its end, checking every `every` steps and after the last; `each` sees the state after
// every step. Stops at the first failure.
struct RunResult {
  ::testing::AssertionResult ok = ::testing::AssertionSuccess();
  int64_t steps = 0;
  double wall_s = 0.0;
};

inline RunResult run_checked(Simulation& sim, Checker& check, int every = 1,
                             const std::function<void(const Simulation&)>& each = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  RunResult r;
  for (bool stop = sim.finished(); !stop;) {
    check.before_step(sim);
    sim.step();
    stop = sim.finished();
    r.ok = check.after_step(sim, stop || sim.step_count() % every == 0);
    if (each) each(sim);
    if (!r.ok) break;
  }
  r.steps = sim.step_count();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

// One line for the log: what the run measured against its bounds.
inline void print_summary(const char* name, const Simulation& sim, const Checker& c, const RunResult& r) {
  std::printf("[stability] %s: %zu particles, %lld steps, %.2f s wall (%d thread(s)); max KE %.4g J/m, "
              "KE/budget max %.3g (tolerance share <= %.2g), E_el0 %.4g J/m, W_bodies %.4g J/m, max penetration %.3g dx\n",
              name, sim.particles().size(), (long long)r.steps, r.wall_s, sim.scene().solver.threads,
              c.max_kinetic_energy_J(), c.max_energy_ratio(), c.max_tolerance_share(), c.initial_elastic_energy_J(), c.bodies_work_J(),
              c.max_penetration_seen_m() / sim.scene().domain.dx_m);
}

}  // namespace furrow::stability
