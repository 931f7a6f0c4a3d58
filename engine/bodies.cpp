#include "engine/bodies.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace furrow {

namespace {

double polygon_sdf(const std::vector<Vec2>& v, const Vec2& q) {
  // exact distance to the boundary, signed by containment (convex or not: winding test)
  double d2 = std::numeric_limits<double>::max();
  bool inside = false;
  for (size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    const Vec2 e = v[i] - v[j], w = q - v[j];
    const double t = std::clamp(w.dot(e) / e.squaredNorm(), 0.0, 1.0);
    d2 = std::min(d2, (w - e * t).squaredNorm());
    if ((v[i].y() > q.y()) != (v[j].y() > q.y()) &&
        q.x() < (v[j].x() - v[i].x()) * (q.y() - v[i].y()) / (v[j].y() - v[i].y()) + v[i].x())
      inside = !inside;
  }
  return inside ? -std::sqrt(d2) : std::sqrt(d2);
}

}  // namespace

double shape_sdf(const Shape& s, const Vec2& q_parent) {
  const Vec2 q = q_parent - s.offset_m;
  switch (s.kind) {
    case Shape::Kind::Circle:
      return q.norm() - s.radius_m;
    case Shape::Kind::Box: {
      const Vec2 d = q.cwiseAbs() - 0.5 * s.size_m;
      const double outside = d.cwiseMax(0.0).norm();
      return outside + std::min(std::max(d.x(), d.y()), 0.0);
    }
    case Shape::Kind::Polygon:
      return polygon_sdf(s.vertices_m, q);
    case Shape::Kind::Union: {
      double d = std::numeric_limits<double>::max();
      for (const auto& part : s.parts) d = std::min(d, shape_sdf(part, q));
      return d;
    }
  }
  return std::numeric_limits<double>::max();
}

Vec2 shape_normal(const Shape& s, const Vec2& q, double h) {
  const Vec2 ex(h, 0.0), ey(0.0, h);
  Vec2 g(shape_sdf(s, q + ex) - shape_sdf(s, q - ex), shape_sdf(s, q + ey) - shape_sdf(s, q - ey));
  const double n = g.norm();
  return n > 0.0 ? Vec2(g / n) : Vec2(0.0, 1.0);
}

void shape_bounds(const Shape& s, Vec2& lo, Vec2& hi) {
  switch (s.kind) {
    case Shape::Kind::Circle:
      lo = s.offset_m - Vec2::Constant(s.radius_m);
      hi = s.offset_m + Vec2::Constant(s.radius_m);
      return;
    case Shape::Kind::Box:
      lo = s.offset_m - 0.5 * s.size_m;
      hi = s.offset_m + 0.5 * s.size_m;
      return;
    case Shape::Kind::Polygon:
      lo = hi = s.offset_m + s.vertices_m.front();
      for (const auto& v : s.vertices_m) {
        lo = lo.cwiseMin(s.offset_m + v);
        hi = hi.cwiseMax(s.offset_m + v);
      }
      return;
    case Shape::Kind::Union: {
      lo = Vec2::Constant(std::numeric_limits<double>::max());
      hi = -lo;
      for (const auto& part : s.parts) {
        Vec2 a, b;
        shape_bounds(part, a, b);
        lo = lo.cwiseMin(a + s.offset_m);
        hi = hi.cwiseMax(b + s.offset_m);
      }
      return;
    }
  }
}

std::vector<std::vector<Vec2>> shape_outline(const Shape& s, int circle_segments) {
  std::vector<std::vector<Vec2>> loops;
  switch (s.kind) {
    case Shape::Kind::Circle: {
      std::vector<Vec2> loop;
      for (int k = 0; k < circle_segments; ++k) {
        const double a = 2.0 * M_PI * k / circle_segments;
        loop.push_back(s.offset_m + s.radius_m * Vec2(std::cos(a), std::sin(a)));
      }
      loops.push_back(loop);
      break;
    }
    case Shape::Kind::Box: {
      const Vec2 h = 0.5 * s.size_m;
      loops.push_back({s.offset_m + Vec2(-h.x(), -h.y()), s.offset_m + Vec2(h.x(), -h.y()),
                       s.offset_m + Vec2(h.x(), h.y()), s.offset_m + Vec2(-h.x(), h.y())});
      break;
    }
    case Shape::Kind::Polygon: {
      std::vector<Vec2> loop;
      for (const auto& v : s.vertices_m) loop.push_back(s.offset_m + v);
      loops.push_back(loop);
      break;
    }
    case Shape::Kind::Union:
      for (const auto& part : s.parts)
        for (auto loop : shape_outline(part, circle_segments)) {
          for (auto& v : loop) v += s.offset_m;
          loops.push_back(loop);
        }
      break;
  }
  return loops;
}

double shape_min_size(const Shape& s) {
  switch (s.kind) {
    case Shape::Kind::Circle:
      return 2.0 * s.radius_m;
    case Shape::Kind::Box:
      return s.size_m.minCoeff();
    case Shape::Kind::Polygon: {
      Vec2 lo, hi;
      shape_bounds(s, lo, hi);
      return (hi - lo).minCoeff();
    }
    case Shape::Kind::Union: {
      double m = std::numeric_limits<double>::max();
      for (const auto& part : s.parts) m = std::min(m, shape_min_size(part));
      return m;
    }
  }
  return 0.0;
}

Vec2 body_velocity(const Motion& m, double t) {
  if (m.kind == Motion::Kind::ConstantVelocity || m.path.empty()) return m.velocity_m_s;
  const auto& k = m.path;
  if (t <= k.front().t_s) return k.front().velocity_m_s;
  for (size_t i = 1; i < k.size(); ++i)
    if (t < k[i].t_s) {
      const double a = (t - k[i - 1].t_s) / (k[i].t_s - k[i - 1].t_s);
      return (1.0 - a) * k[i - 1].velocity_m_s + a * k[i].velocity_m_s;
    }
  return k.back().velocity_m_s;
}

Vec2 body_displacement(const Motion& m, double t) {
  if (m.kind == Motion::Kind::ConstantVelocity || m.path.empty()) return m.velocity_m_s * t;
  // integrate the piecewise-linear velocity exactly (trapezoids), constant outside the knots
  const auto& k = m.path;
  Vec2 d = k.front().velocity_m_s * std::min(t, k.front().t_s);
  for (size_t i = 1; i < k.size() && k[i - 1].t_s < t; ++i) {
    const double t1 = std::min(t, k[i].t_s);
    const Vec2 v1 = body_velocity(m, t1);
    d += 0.5 * (k[i - 1].velocity_m_s + v1) * (t1 - k[i - 1].t_s);
  }
  if (t > k.back().t_s) d += k.back().velocity_m_s * (t - k.back().t_s);
  return d;
}

}  // namespace furrow
