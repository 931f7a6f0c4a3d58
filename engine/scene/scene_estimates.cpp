// Cost estimates and prescribed body kinematics, shared by scene validation and the solver.
#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/scene/scene_io.hpp"

namespace furrow {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}

double wave_speed_m_s(const Material& m) {
  const double E = m.youngs_modulus_Pa, nu = m.poisson_ratio;
  const double K = E / (3.0 * (1.0 - 2.0 * nu));
  const double G = E / (2.0 * (1.0 + nu));
  // dense DPM material can be as loose as phi_min: lighter, hence faster waves
  const double phi = m.model == MaterialModel::DPM ? std::min(m.phi_c, m.phi_min) : m.phi_c;
  return std::sqrt((K + 4.0 * G / 3.0) / (m.grain_density_kg_m3 * phi));
}

double estimate_time_step_s(const Scene& scene) {
  double c_max = 0.0;
  for (const auto& m : scene.materials) c_max = std::max(c_max, wave_speed_m_s(m));
  double v_max = 0.0;
  for (const auto& b : scene.bodies) {
    // a turning body's surface moves faster than its origin, by up to omega x its reach
    const auto [lo, hi] = shape_bounds_m(b.shape);
    const double reach = lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).norm();
    v_max = std::max(v_max, motion_max_speed_m_s(b.motion) + motion_max_angular_speed_rad_s(b.motion) * reach);
  }
  const double speed = c_max + v_max;
  // the fastest material bounds dt, i.e. dt minimised over materials
  return speed > 0.0 ? scene.solver.cfl * scene.domain.dx_m / speed : kInf;
}

size_t estimate_particle_count(const Scene& scene) {
  const double dx = scene.domain.dx_m;
  const double ppc = scene.solver.particles_per_cell_1d;
  double n = 0.0;
  for (const auto& bed : scene.beds) {
    const Vec2 extent = (bed.max_m - bed.min_m).cwiseMax(0.0);
    n += extent.x() * extent.y() / (dx * dx) * ppc * ppc;
  }
  // clamp before converting: a wild dx must not make the cast undefined
  if (!(n < 1e18)) return size_t(1e18);
  return size_t(std::llround(n));
}

double estimate_end_time_s(const Scene& scene) {
  double t = scene.solver.end_time_s;
  const int ref = reference_body_index(scene);
  if (scene.solver.end_displacement_m > 0.0 && ref >= 0)
    t = std::min(t, time_to_displacement_s(scene.bodies[size_t(ref)].motion,
                                           scene.solver.end_displacement_m, t));
  return t;
}

int64_t estimate_step_count(const Scene& scene) {
  const double dt = estimate_time_step_s(scene);
  const double steps = std::ceil(estimate_end_time_s(scene) / dt);
  if (!(steps < 9e18)) return std::numeric_limits<int64_t>::max();
  return int64_t(std::max(steps, 0.0));
}

double estimate_particle_steps(const Scene& scene) {
  return double(estimate_particle_count(scene)) * double(std::min<int64_t>(estimate_step_count(scene), scene.solver.max_steps));
}

namespace {

// A knot value (`get` of a knot) at t_s, linear between knots and held after the last; `constant`
// for a constant_velocity motion.
template <class T, class Get>
T knot_interpolate(const Motion& motion, double t_s, const T& constant, Get get) {
  if (motion.kind == Motion::Kind::ConstantVelocity || motion.path.empty()) return constant;
  const auto& k = motion.path;
  if (t_s <= k.front().t_s) return get(k.front());
  if (t_s >= k.back().t_s) return get(k.back());
  auto hi = std::upper_bound(k.begin(), k.end(), t_s,
                             [](double t, const Motion::Knot& knot) { return t < knot.t_s; });
  auto lo = hi - 1;
  const double a = (t_s - lo->t_s) / (hi->t_s - lo->t_s);
  return T((1.0 - a) * get(*lo) + a * get(*hi));
}

// Its integral from 0 to t_s: trapezoids are exact for a value linear between knots.
template <class T, class Get>
T knot_integral(const Motion& motion, double t_s, const T& constant, const T& zero, Get get) {
  if (t_s <= 0.0) return zero;
  if (motion.kind == Motion::Kind::ConstantVelocity || motion.path.empty()) return T(constant * t_s);
  T d = zero;
  double t_prev = 0.0;
  T v_prev = knot_interpolate(motion, 0.0, constant, get);
  for (const auto& knot : motion.path) {
    if (knot.t_s <= t_prev) continue;
    const double t_next = std::min(knot.t_s, t_s);
    const T v_next = knot_interpolate(motion, t_next, constant, get);
    d += 0.5 * (v_prev + v_next) * (t_next - t_prev);
    t_prev = t_next;
    v_prev = v_next;
    if (t_prev >= t_s) return d;
  }
  return T(d + get(motion.path.back()) * (t_s - t_prev));
}

Vec2 knot_velocity(const Motion::Knot& k) { return k.velocity_m_s; }
double knot_omega(const Motion::Knot& k) { return k.angular_velocity_rad_s; }

}  // namespace

Vec2 motion_velocity_m_s(const Motion& motion, double t_s) {
  return knot_interpolate(motion, t_s, motion.velocity_m_s, knot_velocity);
}

Vec2 motion_displacement_m(const Motion& motion, double t_s) {
  return knot_integral(motion, t_s, motion.velocity_m_s, Vec2(Vec2::Zero()), knot_velocity);
}

double motion_angular_velocity_rad_s(const Motion& motion, double t_s) {
  return knot_interpolate(motion, t_s, motion.angular_velocity_rad_s, knot_omega);
}

double motion_rotation_rad(const Motion& motion, double t_s) {
  return knot_integral(motion, t_s, motion.angular_velocity_rad_s, 0.0, knot_omega);
}

bool Body::rotates() const {
  if (start_angle_rad != 0.0 || dynamics.free_angle || motion.angular_velocity_rad_s != 0.0) return true;
  for (const auto& k : motion.path)
    if (k.angular_velocity_rad_s != 0.0) return true;
  return false;
}

double motion_max_angular_speed_rad_s(const Motion& motion) {
  double w = std::abs(motion.angular_velocity_rad_s);
  for (const auto& k : motion.path) w = std::max(w, std::abs(k.angular_velocity_rad_s));
  return w;
}

double motion_max_speed_m_s(const Motion& motion) {
  if (motion.kind == Motion::Kind::ConstantVelocity || motion.path.empty())
    return motion.velocity_m_s.norm();
  double v = 0.0;  // |v| of a linear interpolation peaks at a knot
  for (const auto& k : motion.path) v = std::max(v, k.velocity_m_s.norm());
  return v;
}

int reference_body_index(const Scene& scene) {
  for (size_t i = 0; i < scene.bodies.size(); ++i)
    if (motion_max_speed_m_s(scene.bodies[i].motion) > 0.0) return int(i);
  return -1;
}

double time_to_displacement_s(const Motion& motion, double distance_m, double t_max_s) {
  if (distance_m <= 0.0) return 0.0;
  if (!(t_max_s > 0.0)) return kInf;
  if (motion.kind == Motion::Kind::ConstantVelocity || motion.path.empty()) {
    const double v = motion.velocity_m_s.norm();
    const double t = v > 0.0 ? distance_m / v : kInf;
    return t <= t_max_s ? t : kInf;
  }
  // Piecewise-quadratic position: one sweep over the knot intervals, sampling each and bisecting
  // the first crossing; the displacement at each interval start is carried along (O(knots)).
  std::vector<double> breaks{0.0};
  for (const auto& k : motion.path)
    if (k.t_s > 0.0 && k.t_s < t_max_s) breaks.push_back(k.t_s);
  breaks.push_back(t_max_s);
  Vec2 d0 = Vec2::Zero();
  constexpr int kSamples = 64;
  for (size_t s = 0; s + 1 < breaks.size(); ++s) {
    const double ta = breaks[s], tb = breaks[s + 1];
    const Vec2 va = motion_velocity_m_s(motion, ta), vb = motion_velocity_m_s(motion, tb);
    const Vec2 acc = (vb - va) / (tb - ta);  // velocity is linear inside an interval
    auto disp = [&](double t) { const double u = t - ta; return Vec2(d0 + va * u + 0.5 * acc * u * u); };
    double prev = ta;
    for (int i = 1; i <= kSamples; ++i) {
      const double t = ta + (tb - ta) * i / kSamples;
      if (disp(t).norm() >= distance_m) {
        double lo = prev, hi = t;
        for (int it = 0; it < 60; ++it) {
          const double mid = 0.5 * (lo + hi);
          (disp(mid).norm() >= distance_m ? hi : lo) = mid;
        }
        return hi;
      }
      prev = t;
    }
    d0 = disp(tb);
  }
  return kInf;
}

std::pair<Vec2, Vec2> shape_bounds_m(const Shape& shape) {
  Vec2 lo = Vec2::Constant(kInf), hi = Vec2::Constant(-kInf);
  switch (shape.kind) {
    case Shape::Kind::Circle:
      lo = Vec2::Constant(-shape.radius_m);
      hi = Vec2::Constant(shape.radius_m);
      break;
    case Shape::Kind::Box:
      lo = -0.5 * shape.size_m;
      hi = 0.5 * shape.size_m;
      break;
    case Shape::Kind::Polygon:
      for (const auto& v : shape.vertices_m) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
      }
      break;
    case Shape::Kind::Union:
      for (const auto& part : shape.parts) {
        auto [plo, phi] = shape_bounds_m(part);
        lo = lo.cwiseMin(plo);
        hi = hi.cwiseMax(phi);
      }
      break;
  }
  if (lo.x() > hi.x()) return {Vec2::Zero(), Vec2::Zero()};  // empty polygon / union
  return {lo + shape.offset_m, hi + shape.offset_m};
}

Vec2 travel_direction(const Scene& scene, const Body& body) {
  Vec2 v = motion_velocity_m_s(body.motion, 0.5 * estimate_end_time_s(scene));
  const BodyDynamics& d = body.dynamics;
  if (v.norm() == 0.0 && (d.free_x || d.free_y)) {
    // a free body set down at rest (the footing) travels where its load pushes it, along the
    // axes it is free in
    Vec2 load = d.applied_force_N_per_m;
    if (scene.effects.gravity) load += d.mass_kg_per_m * scene.effects.gravity_m_s2;
    v = Vec2(d.free_x ? load.x() : 0.0, d.free_y ? load.y() : 0.0);
  }
  return v.norm() > 0.0 ? Vec2(v / v.norm()) : Vec2(0.0, 0.0);
}

double body_cells_across(const Scene& scene, const Body& body) {
  const auto [lo, hi] = shape_bounds_m(body.shape);
  const Vec2 size = hi - lo;
  const Vec2 d = travel_direction(scene, body);
  const double across = d.squaredNorm() > 0.0 ? std::abs(size.x() * d.y()) + std::abs(size.y() * d.x())
                                              : std::min(size.x(), size.y());
  return across / scene.domain.dx_m;
}

double contact_size_bias(ContactMethod method, double cells_across) {
  // plate L 0.04 m against ~297 N/m (64 cells): node -16 / -7 / -3%, particle +33 / +22 / +8% at
  // 8 / 16 / 32 cells; cell_fraction (its share reaching 1 inside the body, 2026-12-02) 292 / 295 /
  // 308 N/m in a bed where node gave 248 / 263 / 279: a few % low at 8 cells
  const double c = method == ContactMethod::Node ? -1.1 : method == ContactMethod::CellFraction ? -0.4 : 2.8;
  return cells_across > 0.0 ? c / cells_across : 0.0;
}

}  // namespace furrow
