#include "engine/bodies.hpp"
#include "engine/scene/scene_io.hpp"

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
      const auto [lo, hi] = shape_bounds_m(s);
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

ShapeMass shape_mass_properties(const Shape& s) {
  const auto [lo, hi] = shape_bounds_m(s);
  constexpr int kN = 512;
  const Vec2 h = (hi - lo) / kN;
  ShapeMass m;
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i) {
      const Vec2 q = lo + Vec2((i + 0.5) * h.x(), (j + 0.5) * h.y());
      if (shape_sdf(s, q) >= 0.0) continue;
      m.area_m2 += h.x() * h.y();
      m.second_moment_m4 += q.squaredNorm() * h.x() * h.y();
    }
  return m;
}

}  // namespace furrow
