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

std::vector<std::vector<Vec2>> shape_boundary(const Shape& s, int cells) {
  if (s.kind != Shape::Kind::Union) return shape_outline(s);
  // marching squares on the distance field: a crossing point on each lattice edge whose ends differ
  // in sign, joined within each cell; every crossing then has two neighbours and the segments chain
  // into loops
  auto [lo, hi] = shape_bounds_m(s);
  const double h = (hi - lo).maxCoeff() / cells;
  lo -= Vec2(2 * h, 2 * h), hi += Vec2(2 * h, 2 * h);
  const int nx = int(std::ceil((hi.x() - lo.x()) / h)), ny = int(std::ceil((hi.y() - lo.y()) / h));
  auto at = [&](int i, int j) { return Vec2(lo.x() + i * h, lo.y() + j * h); };
  std::vector<double> f(size_t(nx + 1) * size_t(ny + 1));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) f[size_t(j) * size_t(nx + 1) + size_t(i)] = shape_sdf(s, at(i, j));
  auto F = [&](int i, int j) { return f[size_t(j) * size_t(nx + 1) + size_t(i)]; };
  // crossing ids: 2 k for the edge from node k to its right, 2 k + 1 to the node above
  auto node = [&](int i, int j) { return int64_t(j) * (nx + 1) + i; };
  auto crossing = [&](int64_t id) {
    const int64_t k = id / 2;
    const int i = int(k % (nx + 1)), j = int(k / (nx + 1)), di = id % 2 ? 0 : 1, dj = 1 - di;
    const double a = F(i, j), b = F(i + di, j + dj), t = a / (a - b);
    return Vec2(at(i, j) + t * (at(i + di, j + dj) - at(i, j)));
  };
  std::vector<std::pair<int64_t, int64_t>> links;  // per crossing: its two neighbours (-1 unset)
  std::vector<int64_t> slot(size_t(2 * (nx + 1) * (ny + 1)), -1);
  auto join = [&](int64_t a, int64_t b) {
    for (int64_t c : {a, b}) {
      if (slot[size_t(c)] < 0) slot[size_t(c)] = int64_t(links.size()), links.emplace_back(-1, -1);
      auto& l = links[size_t(slot[size_t(c)])];
      (l.first < 0 ? l.first : l.second) = c == a ? b : a;
    }
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const bool a = F(i, j) < 0, b = F(i + 1, j) < 0, c = F(i + 1, j + 1) < 0, d = F(i, j + 1) < 0;
      const int64_t B = 2 * node(i, j), T = 2 * node(i, j + 1), L = 2 * node(i, j) + 1, R = 2 * node(i + 1, j) + 1;
      std::vector<int64_t> cut;
      if (a != b) cut.push_back(B);
      if (b != c) cut.push_back(R);
      if (c != d) cut.push_back(T);
      if (d != a) cut.push_back(L);
      if (cut.size() == 2) {
        join(cut[0], cut[1]);
      } else if (cut.size() == 4) {  // a saddle: the cell's centre decides which corners connect
        const bool centre = 0.25 * (F(i, j) + F(i + 1, j) + F(i + 1, j + 1) + F(i, j + 1)) < 0;
        if (centre == a) join(B, R), join(T, L);  // corners b and d cut off
        else join(L, B), join(R, T);              // corners a and c cut off
      }
    }
  std::vector<std::vector<Vec2>> loops;
  std::vector<char> used(slot.size(), 0);
  for (int64_t start = 0; start < int64_t(slot.size()); ++start) {
    if (slot[size_t(start)] < 0 || used[size_t(start)]) continue;
    std::vector<Vec2> loop;
    for (int64_t prev = -1, c = start; c >= 0 && !used[size_t(c)];) {
      used[size_t(c)] = 1;
      loop.push_back(crossing(c));
      const auto& l = links[size_t(slot[size_t(c)])];
      const int64_t next = l.first != prev ? l.first : l.second;
      prev = c, c = next;
    }
    // fewer points where the contour runs straight (within a tenth of the lattice spacing)
    std::vector<Vec2> kept;
    for (size_t k = 0; k < loop.size(); ++k) {
      const Vec2 &p = kept.empty() ? loop.back() : kept.back(), &q = loop[k], &r = loop[(k + 1) % loop.size()];
      const Vec2 e = r - p;
      const double off = e.norm() > 0 ? std::abs(e.x() * (q - p).y() - e.y() * (q - p).x()) / e.norm() : 0.0;
      if (off > 0.1 * h || k == 0) kept.push_back(q);
    }
    // the inside on the left: counter-clockwise around the body, clockwise around a hole
    if (kept.size() >= 3) {
      // probed off the longest segment: a short one may cut a corner, where half a lattice
      // spacing outwards is still inside
      size_t a = 0;
      for (size_t k = 1; k < kept.size(); ++k)
        if ((kept[(k + 1) % kept.size()] - kept[k]).norm() > (kept[(a + 1) % kept.size()] - kept[a]).norm()) a = k;
      const Vec2 &p = kept[a], &q = kept[(a + 1) % kept.size()];
      const Vec2 mid = 0.5 * (p + q), along = (q - p).normalized();
      if (shape_sdf(s, mid + 0.5 * h * Vec2(-along.y(), along.x())) > 0) std::reverse(kept.begin(), kept.end());
      loops.push_back(std::move(kept));
    }
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
