// Contact of the grid with bodies and walls: node and cell_fraction contact (with the body's mass
// field), a free body's response, the domain walls and the front/back walls' friction. Particle
// contact is in contact_particles.cpp.
#include <Eigen/Dense>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <utility>
#include <vector>

#include "engine/bodies.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/shape_functions.hpp"
#include "engine/simulation.hpp"
#include "engine/simulation_detail.hpp"

namespace furrow {

namespace {

// cell-fraction contact: the body as its own mass field (see contact_nodes). Its sample points
// fill the body deeper than kBodyFieldInset cells, and deeper than kBodyFieldSideInset cells
// across the body's motion (its faces along the motion, which never cross node lines, need no
// smooth reach, and a field reaching past them made the body act wider: README, "Body
// contact"), kBodySamplesPerCell per cell and axis, each with kBodyDensityRatio times the bed's
// mean density. All four were chosen by measurement.
constexpr double kBodyFieldInset = 0.5;
constexpr double kBodyFieldSideInset = 1.0;
constexpr int kBodySamplesPerCell = 4;
constexpr double kBodyDensityRatio = 20.0;
// cell-fraction contact starts where a point's surface comes this close to a body, in cells (the
// onset target: nothing until the surfaces are within a quarter cell)
constexpr double kTouchCells = 0.2;

// Coulomb contact of a node velocity against a surface with outward normal n moving at vb.
// Returns true if the node was in approaching contact and its velocity was changed.
inline bool contact(Vec2& v, const Vec2& vb, const Vec2& n, double mu) {
  const Vec2 rel = v - vb;
  const double vn = rel.dot(n);
  if (vn >= 0.0) return false;
  Vec2 vt = rel - vn * n;
  const double t = vt.norm();
  if (t > 0.0) vt *= std::max(0.0, t + mu * vn) / t;  // vn < 0: friction removes up to mu|vn|
  v = vb + vt;
  return true;
}

}  // namespace

// Sample points of each body's mass field (cell-fraction contact), fixed in the body's frame so
// the field moves smoothly with it. The inset keeps the field's reach (the B-spline support of its
// outermost points) near the surface; a body thinner than two insets keeps its inner half.
void Simulation::sample_body_fields() {
  const double dx = g_.dx, h = dx / kBodySamplesPerCell;
  double mass = 0.0, volume = 0.0;
  for (size_t p = 0; p < p_.size(); ++p) mass += p_.mass[p], volume += p_.volume[p];
  const double density = volume > 0.0 ? kBodyDensityRatio * mass / volume : 0.0;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const auto [frame_lo, frame_hi] = shape_bounds_m(scene_.bodies[b].shape);  // in the body's frame
    std::vector<std::pair<Vec2, double>> inside;  // point, depth below the surface (m)
    std::vector<std::pair<uint32_t, uint32_t>> lattice;  // its column and row
    BodySamples field;
    double deepest = 0.0;
    for (double y = frame_lo.y() + 0.5 * h; y < frame_hi.y(); y += h) {
      field.row_y_m.push_back(y);
      uint32_t column = 0;
      for (double x = frame_lo.x() + 0.5 * h; x < frame_hi.x(); x += h, ++column) {
        if (field.row_y_m.size() == 1) field.column_x_m.push_back(x);
        const double depth = -shape_sdf(scene_.bodies[b].shape, Vec2(x, y));
        if (depth <= 0.0) continue;
        inside.emplace_back(Vec2(x, y), depth);
        lattice.emplace_back(column, uint32_t(field.row_y_m.size() - 1));
        deepest = std::max(deepest, depth);
      }
    }
    const double inset = std::min(kBodyFieldInset * dx, 0.5 * deepest);
    const Shape& shape = scene_.bodies[b].shape;
    // across the body's travel (a path that turns keeps the direction of its middle), in the
    // body's frame. A body held at an angle keeps it (without, a plate tilted 0.001 degrees acted a
    // side inset wider: +15% force on plate_intrusion); a body that spins has no one direction
    // across its travel, so its rim's inset turns (below)
    const Body& body = scene_.bodies[b];
    const bool spins = body.dynamics.free_angle || motion_max_angular_speed_rad_s(body.motion) > 0.0;
    // so far only where the media turn it (a free angle): a driven spin (the wheel, the leg) keeps
    // no side inset, since what the turning inset does to the wheel's drawbar pull is not settled
    // (engine/README.md, "The side inset of a body that turns")
    const bool turning_inset = body.dynamics.free_angle;
    Vec2 travel = travel_direction(scene_, body);
    if (body.start_angle_rad != 0.0) {
      const double c = std::cos(body.start_angle_rad), s = std::sin(body.start_angle_rad);
      travel = Vec2(c * travel.x() + s * travel.y(), -s * travel.x() + c * travel.y());
    }
    // distances from q to the surface along -across and +across (bisection on the SDF; the body
    // is inside its box)
    auto reach_across = [&](const Vec2& q, const Vec2& across) {
      const double far = (frame_hi - frame_lo).norm();
      std::pair<double, double> reach;
      for (double sign : {-1.0, 1.0}) {
        double in = 0.0, out = far;
        for (int k = 0; k < 40; ++k) {
          const double mid = 0.5 * (in + out);
          (shape_sdf(shape, q + sign * mid * across) < 0.0 ? in : out) = mid;
        }
        (sign < 0 ? reach.first : reach.second) = out;
      }
      return reach;
    };
    auto depth_across = [&](const Vec2& q, const Vec2& across) {
      const auto [a, b] = reach_across(q, across);
      return std::min(a, b);
    };
    // as with the inset, a body too thin for the side inset keeps its middle
    auto side_inset_across = [&](const Vec2& across) {
      double widest = 0.0;
      for (size_t k = 0; k < inside.size() && widest < 2.0 * kBodyFieldSideInset * dx; ++k)
        widest = std::max(widest, depth_across(inside[k].first, across));
      return std::min(kBodyFieldSideInset * dx, 0.5 * widest);
    };
    if (!spins) {
      const Vec2 across(-travel.y(), travel.x());
      std::vector<double> across_m(inside.size(), 0.0);
      if (across.squaredNorm() > 0.0)
        for (size_t k = 0; k < inside.size(); ++k) across_m[k] = depth_across(inside[k].first, across);
      const double side_inset = across.squaredNorm() > 0.0 ? side_inset_across(across) : 0.0;
      for (size_t k = 0; k < inside.size(); ++k)
        if (inside[k].second >= inset && across_m[k] >= side_inset) {
          field.q_m.push_back(inside[k].first);
          field.column.push_back(lattice[k].first);
          field.row.push_back(lattice[k].second);
        }
    } else {
      // every sample deeper than the inset; with a turning inset, those within a side inset (and
      // the half sample of the weight's ramp) of the surface keep their depth and chord across each
      // direction. A body thin across a direction keeps the middle half of its chord there (for one
      // that does not spin, the thinnest part's: above): with one side inset for all its parts, a
      // thin curved leg slicing edge-on dropped out of its field
      field.rest_direction = travel;
      for (size_t k = 0; k < inside.size(); ++k) {
        if (inside[k].second < inset) continue;
        if (turning_inset && inside[k].second < kBodyFieldSideInset * dx + 0.5 * h) {
          field.rim.push_back(uint32_t(field.q_m.size()));
          for (int d = 0; d < kInsetDirections; ++d) {
            const double a = M_PI * d / kInsetDirections;
            const auto [minus, plus] = reach_across(inside[k].first, Vec2(-std::sin(a), std::cos(a)));
            field.rim_across_m.push_back(std::min(minus, plus));
            field.rim_chord_m.push_back(minus + plus);
          }
        }
        field.q_m.push_back(inside[k].first);
        field.column.push_back(lattice[k].first);
        field.row.push_back(lattice[k].second);
      }
      if (turning_inset) field.weight.assign(field.q_m.size(), 1.0);
    }
    field.row_start.assign(field.row_y_m.size() + 1, 0);
    for (uint32_t r : field.row) ++field.row_start[r + 1];
    std::partial_sum(field.row_start.begin(), field.row_start.end(), field.row_start.begin());
    body_samples_.push_back(std::move(field));
  }
  body_sample_mass_kg_ = density * h * h;
  body_node_full_kg_ = density * dx * dx;  // the field at a node whose whole stencil it fills
}

// A spinning body's rim samples, this step: the direction of their own velocity (v + omega z x q,
// in the body's frame; at rest, the direction the body's load or motion gives) picks their depth
// and chord across it from the tables, interpolated between directions, and they weigh
// in over a ramp one sample spacing wide about the inset. The field then changes smoothly as the
// body turns; on a body moving straight the ramp keeps and drops the samples the fixed inset does.
void Simulation::weigh_rim(size_t b) {
  BodySamples& f = body_samples_[b];
  if (f.rim.empty()) return;
  const BodyState& s = bodies_[b];
  const double h = g_.dx / kBodySamplesPerCell;
  const Vec2 v(s.cos_a * s.velocity_m_s.x() + s.sin_a * s.velocity_m_s.y(),
               -s.sin_a * s.velocity_m_s.x() + s.cos_a * s.velocity_m_s.y());
  for (size_t r = 0; r < f.rim.size(); ++r) {
    const Vec2& q = f.q_m[f.rim[r]];
    Vec2 u = v + s.omega_rad_s * Vec2(-q.y(), q.x());
    if (u.squaredNorm() == 0.0) u = f.rest_direction;
    double w = 1.0;
    if (u.squaredNorm() > 0.0) {
      double t = std::atan2(u.y(), u.x()) / M_PI * kInsetDirections;  // in (-M, M]; a direction and
      if (t < 0.0) t += kInsetDirections;                               // its opposite share a row
      const int d0 = std::min(int(t), kInsetDirections - 1), d1 = (d0 + 1) % kInsetDirections;
      const double a = t - d0;
      const double *across = &f.rim_across_m[r * kInsetDirections], *chord = &f.rim_chord_m[r * kInsetDirections];
      const double depth = (1.0 - a) * across[d0] + a * across[d1];
      const double inset = std::min(kBodyFieldSideInset * g_.dx, 0.25 * ((1.0 - a) * chord[d0] + a * chord[d1]));
      w = std::clamp((depth - inset) / h + 0.5, 0.0, 1.0);
    }
    f.weight[f.rim[r]] = w;
  }
}

// The walls and the bodies act on the same nodes only where a body's node box reaches a boundary
// line. Elsewhere the walls (a few thousand nodes) act in the grid update, each column of nodes as
// it is updated (in cache, in parallel), before the bodies act on theirs. Node and cell_fraction
// contact touch only their box's nodes; particle contact scatters a cell or more beyond it, so it
// keeps the order bodies, then walls. Either way a node meets the same walls in the same order,
// and the walls' forces are summed in the same order: the same bits.
bool Simulation::walls_apart_from_bodies() const {
  if (bodies_.empty()) return true;
  if (scene_.solver.contact == ContactMethod::Particle) return false;
  for (const BodyState& s : bodies_) {
    const auto [i0, i1, j0, j1] = body_node_box(s, g_);
    if (i0 <= 0 || i1 >= g_.nx || j0 <= 0 || j1 >= g_.ny) return false;
  }
  return true;
}

void Simulation::bodies_and_walls(bool walls_done) {
  if (!bodies_.empty()) (this->*contact_)();
  if (!walls_done) contact_walls();
}

// Node contact: every grid node inside a body takes the body's normal velocity (Coulomb slip
// along it). The constrained set grows by a node row each time a face crosses a node line, so
// the force steps with a period of one cell.
//
// Cell-fraction contact (Fraction): the body is also a mass field on the grid, scattered from
// sample points fixed in its frame (cell_fraction_band), and a node takes the share
// m_body / (m_body + m_media) of the correction, as multi-field contact of the media against a
// body of finite mass would (Bardenhagen et al. 2001), scaled up to reach 1 where the field
// covers the node fully, since a driven body has no finite mass. The share is a smooth function
// of the body's position, so no node switches on at once as a face crosses a node line. The correction
// itself is the mass-weighted mean of what each media point in the node's stencil asks of it: the
// node's velocity held against the body along that point's own face normal (Coulomb slip along
// it). One normal per node flips where the node crosses a thin body's medial axis (a node row of
// a plate two cells thick, which then stopped holding the material below it: the larger part of
// the node method's comb, and of a mass-gradient normal's); the points' normals do not, since
// each point stays on its own side. Nodes act only once touched (cell_fraction_band).
template <bool Fraction>
void Simulation::contact_nodes() {
  const double dt = dt_s_, dx = g_.dx;
  held_.resize(bodies_.size());
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const Body& body = scene_.bodies[b];
    BodyState& s = bodies_[b];
    const double mu = scene_.effects.body_friction ? body.friction : 0.0;
    const auto [i0, i1, j0, j1] = body_node_box(s, g_);
    Vec2 impulse(0.0, 0.0);
    double angular = 0.0;  // angular momentum the media gained about the body's origin
    const bool free = body.dynamics.any_free();
    // a free body: what each node's correction depends on the body's velocity (its projector)
    if (free) held_[b].assign(size_t(i1 - i0 + 1) * size_t(j1 - j0 + 1), Vec3(0.0, 0.0, 0.0));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const size_t k = g_.index(i, j);
        GridNode& n = g_.node[k];
        const Vec2 xn(i * dx, j * dx), q = s.to_body(xn);
        double share = 1.0;
        const size_t c = size_t(j - j0) * size_t(i1 - i0 + 1) + size_t(i - i0);  // index in the body's box
        if constexpr (Fraction) {
          const double m_body = body_node_mass_kg_[b][c];
          if (n.m <= 0.0 || m_body <= 0.0) {
            touched_[b][k] = 0;  // out of the body's reach: must be touched again
            continue;
          }
          if (!touched_[b][k]) continue;
          // the multi-field share m_body / (m_body + m), scaled to reach 1 where the body's field
          // covers the node fully (m_body = body_node_full_kg_): a driven body has no finite mass,
          // and a share below 1 inside it let the material under it lag it (README, "Body contact")
          share = std::min(1.0, m_body * (body_node_full_kg_ + n.m) / ((m_body + n.m) * body_node_full_kg_));
        } else if (n.m <= 0.0 || shape_sdf(body.shape, q) >= 0.0) {
          continue;
        }
        Vec2 v(n.vx, n.vy);
        const Vec2 before = v;
        if constexpr (Fraction) {
          const double m_points = stencil_mass_kg_[b][c];
          if (m_points <= 0.0) continue;
          v += share * (stencil_dv_kg_m_s_[b][c] / m_points);
        } else {
          const Vec2 normal = s.to_world(shape_normal(body.shape, q, 1e-4 * dx));
          if (!contact(v, s.velocity_at(xn), normal, mu)) continue;
          if (free) held_[b][c] = Vec3(normal.x() * normal.x(), normal.x() * normal.y(), normal.y() * normal.y());
        }
        if constexpr (Fraction)
          if (free) held_[b][c] = share * stencil_nn_[b][c] / stencil_mass_kg_[b][c];
        const Vec2 dp = n.m * (v - before);
        impulse += dp;
        if (s.turns || free) angular += (xn - s.position_m).x() * dp.y() - (xn - s.position_m).y() * dp.x();
        n.vx = v.x();
        n.vy = v.y();
      }
    if (free) respond_free_body(b, impulse, angular);
    s.force_N_per_m = -impulse / dt;
    s.torque_N = -angular / dt;
  }
}

// Cell-fraction contact acts only at nodes a material point has touched: a point whose surface is
// within kTouchCells of the body marks the nodes of its stencil, and a node stays marked while both
// the media and the body's field reach it. Without this, the body's field acts on material up to
// a cell from the surface and the body feels the bed before it meets it.
//
// It runs in three parts: this step's plan (serial: each body's node box, its bands, its field's
// lattice weights), each band's sums (cell_fraction_band, in parallel), and the node pass
// (contact_nodes<true>). Both sums run over bands of the box's nodes, across its longer side (a
// sample or point whose stencil spans two bands is worked out in both, and fewer do so when the
// bands are wide). Each band visits every sample and point in the same order as one pass would
// and adds only to its own nodes, so each node's sum is the same whatever the bands: results are
// the same for any thread count. One band per thread, each at least four nodes across; on one
// thread, one band and no work twice. A band reads the grid only at its own nodes, so where the
// bodies' boxes are apart each band updates its own nodes itself and its sums run in the grid
// update's parallel region (grid_and_bands): the sums are tens of microseconds a step, and each
// region pays a wake-up of the other threads. Returns whether the boxes are apart.
template <class K>
bool Simulation::plan_cell_fraction() {
  const double inv_dx = 1.0 / g_.dx;
  touched_.resize(bodies_.size());
  body_node_mass_kg_.resize(bodies_.size());
  stencil_dv_kg_m_s_.resize(bodies_.size());
  stencil_mass_kg_.resize(bodies_.size());
  stencil_nn_.resize(bodies_.size());
  field_plans_.resize(bodies_.size());
  band_tasks_.clear();
  const int threads = split_threads(task_log_);
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const BodyState& s = bodies_[b];
    FieldPlan& plan = field_plans_[b];
    // only nodes contact_nodes() visits are marked, so it also clears every mark it leaves behind
    touched_[b].resize(g_.node.size(), 0);
    const auto [i0, i1, j0, j1] = body_node_box(s, g_);
    plan.i0 = i0, plan.i1 = i1, plan.j0 = j0, plan.j1 = j1;
    const size_t box_nodes = size_t(i1 - i0 + 1) * size_t(j1 - j0 + 1);
    stencil_dv_kg_m_s_[b].assign(box_nodes, Vec2(0.0, 0.0));
    stencil_mass_kg_[b].assign(box_nodes, 0.0);
    if (scene_.bodies[b].dynamics.any_free()) stencil_nn_[b].assign(box_nodes, Vec3(0.0, 0.0, 0.0));
    body_node_mass_kg_[b].assign(box_nodes, 0.0);
    const bool by_columns = i1 - i0 > j1 - j0;
    const int across = by_columns ? i1 - i0 + 1 : j1 - j0 + 1, first_line = by_columns ? i0 : j0;
    plan.bands = threads == 1 ? 1 : std::clamp(std::min(across / 4, threads), 1, across);
    for (int band = 0; band < plan.bands; ++band) {
      const int a = first_line + int(int64_t(across) * band / plan.bands);
      const int z = first_line + int(int64_t(across) * (band + 1) / plan.bands) - 1;
      band_tasks_.push_back(by_columns ? BandTask{b, a, z, j0, j1} : BandTask{b, i0, i1, a, z});
    }
    // a body that never turns keeps its samples' lattice on the grid's axes: the weights of a
    // lattice column (row) are those of each of its samples, worked out once
    const BodySamples& samples = body_samples_[b];
    const size_t columns = s.turns ? 0 : samples.column_x_m.size(), rows = s.turns ? 0 : samples.row_y_m.size();
    plan.column_base.resize(columns), plan.row_base.resize(rows);
    plan.column_w.resize(columns * K::N), plan.row_w.resize(rows * K::N);
    double dw[K::N];
    for (size_t a = 0; a < columns; ++a)
      plan.column_base[a] = K::weights((s.position_m.x() + samples.column_x_m[a]) * inv_dx, &plan.column_w[a * K::N], dw, inv_dx);
    for (size_t a = 0; a < rows; ++a)
      plan.row_base[a] = K::weights((s.position_m.y() + samples.row_y_m[a]) * inv_dx, &plan.row_w[a * K::N], dw, inv_dx);
    if (s.turns) weigh_rim(b);
  }
  if (band_field_.size() < band_tasks_.size()) band_field_.resize(band_tasks_.size());
  for (size_t a = 0; a < field_plans_.size(); ++a)
    for (size_t b = a + 1; b < field_plans_.size(); ++b) {
      const FieldPlan &p = field_plans_[a], &q = field_plans_[b];
      if (p.i0 <= q.i1 && q.i0 <= p.i1 && p.j0 <= q.j1 && q.j0 <= p.j1) return false;
    }
  return true;
}

// One band's sums: the body's field over its nodes, then each point in reach, which marks its
// stencil if it touches the body and adds to each node of its stencil (weight x mass) the change
// that holds the node against the body along the point's own face normal; points in strip order.
// Only nodes the body's field reaches: contact_nodes() acts on no other (and clears their marks).
// With `update_nodes` the band first does the grid update of its own nodes (grid_and_bands).
template <class K>
void Simulation::cell_fraction_band(size_t task, bool update_nodes) {
  const BandTask& n = band_tasks_[task];
  const size_t b = n.body;
  const FieldPlan& plan = field_plans_[b];
  if (update_nodes) {
    const double gx = gravity_.x() * dt_s_, gy = gravity_.y() * dt_s_;
    for (int i = n.i0; i <= n.i1; ++i) {
      GridNode* const first = g_.node.data() + g_.index(i, n.j0);
      furrow::update_nodes(first, first + (n.j1 - n.j0 + 1), gx, gy, flip_);
    }
  }
  const double dx = g_.dx, inv_dx = 1.0 / dx;
  // a point reaches the nodes of the body's box (the body's box and two cells) from 1.5 cells out
  const double reach = 3.5 * dx;
  const int strips = int(strip_start_.size()) - 1;
  const BodyState& s = bodies_[b];
  const Shape& shape = scene_.bodies[b].shape;
  const double mu = scene_.effects.body_friction ? scene_.bodies[b].friction : 0.0;
  const bool free = scene_.bodies[b].dynamics.any_free();
  auto& touched = touched_[b];
  auto& dv = stencil_dv_kg_m_s_[b];
  auto& m_points = stencil_mass_kg_[b];
  const int i0 = plan.i0, i1 = plan.i1, j0 = plan.j0, j1 = plan.j1;
  const size_t width = size_t(i1 - i0 + 1), box_nodes = width * size_t(j1 - j0 + 1);
  const BodySamples& samples = body_samples_[b];
  auto add_sample = [&](double* out, const BandTask& r, int bx, int by, const double* wx, const double* wy, double m) {
    if (by >= r.j0 && by + K::N - 1 <= r.j1 && bx >= r.i0 && bx + K::N - 1 <= r.i1) {
      // the whole stencil in the band (most samples): fixed trip counts, the same sums
      double* const row0 = out + size_t(by - j0) * width + size_t(bx - i0);
      for (int j = 0; j < K::N; ++j)
        for (int i = 0; i < K::N; ++i) row0[size_t(j) * width + size_t(i)] += wx[i] * wy[j] * m;
      return;
    }
    if (by > r.j1 || by + K::N - 1 < r.j0 || bx > r.i1 || bx + K::N - 1 < r.i0) return;
    for (int j = std::max(by, r.j0); j <= std::min(by + K::N - 1, r.j1); ++j)
      for (int i = std::max(bx, r.i0); i <= std::min(bx + K::N - 1, r.i1); ++i)
        out[size_t(j - j0) * width + size_t(i - i0)] += wx[i - bx] * wy[j - by] * m;
  };
  // the samples lie in rows from the bottom, each row by column, and the lattice weights' bases
  // ascend with the column (row), so the samples whose stencil meets a band's nodes are a run of
  // rows and, in each, a run of columns: a band walks only those, in the one pass's order
  auto add_field = [&](double* out, const BandTask& r) {
    if (s.turns) {
      for (size_t k = 0; k < samples.q_m.size(); ++k) {
        const Vec2 x = s.position_m + s.to_world(samples.q_m[k]);
        double wx[K::N], wy[K::N], dw[K::N];
        const int bx = K::weights(x.x() * inv_dx, wx, dw, inv_dx);
        const int by = K::weights(x.y() * inv_dx, wy, dw, inv_dx);
        add_sample(out, r, bx, by, wx, wy, samples.weight.empty() ? body_sample_mass_kg_ : samples.weight[k] * body_sample_mass_kg_);
      }
      return;
    }
    // lattice lines whose stencil (base .. base + N - 1) meets the band's lo .. hi
    auto meeting = [](const std::vector<int>& base, int lo, int hi) {
      return std::pair(uint32_t(std::lower_bound(base.begin(), base.end(), lo - (K::N - 1)) - base.begin()),
                       uint32_t(std::upper_bound(base.begin(), base.end(), hi) - base.begin()));
    };
    const auto [a0, a1] = meeting(plan.column_base, r.i0, r.i1);
    const auto [c0, c1] = meeting(plan.row_base, r.j0, r.j1);
    const uint32_t* const column = samples.column.data();
    for (uint32_t c = c0; c < c1; ++c) {
      const uint32_t *const row_first = column + samples.row_start[c], *const row_end = column + samples.row_start[c + 1];
      for (const uint32_t* k = std::lower_bound(row_first, row_end, a0); k < row_end && *k < a1; ++k)
        add_sample(out, r, plan.column_base[*k], plan.row_base[c], &plan.column_w[*k * K::N], &plan.row_w[c * K::N],
                   body_sample_mass_kg_);
    }
  };
  // the body's field over its node box; with several bands each adds up its own copy over its
  // nodes and N - 1 beyond (where its points' stencils reach) and writes its own nodes
  auto& field = body_node_mass_kg_[b];
  const double* f = field.data();
  if (plan.bands == 1) {
    add_field(field.data(), n);
  } else {
    std::vector<double>& own = band_field_[task];
    own.assign(box_nodes, 0.0);
    const int m = K::N - 1;
    add_field(own.data(), BandTask{b, std::max(n.i0 - m, i0), std::min(n.i1 + m, i1), std::max(n.j0 - m, j0), std::min(n.j1 + m, j1)});
    for (int j = n.j0; j <= n.j1; ++j)
      std::copy_n(own.data() + size_t(j - j0) * width + size_t(n.i0 - i0), n.i1 - n.i0 + 1,
                  field.data() + size_t(j - j0) * width + size_t(n.i0 - i0));
    f = own.data();
  }
  // a point whose stencil meets the band's nodes has its base within n.i0 - N + 1 .. n.i1 (and
  // n.j0 - N + 1 .. n.j1), and lies in the body's reach: only the strips and rows that could hold
  // such points are walked, in the order one walk would take
  const Vec2 lo = s.position_m + s.lo_m - Vec2(reach, reach), hi = s.position_m + s.hi_m + Vec2(reach, reach);
  const int bx_lo = std::max(K::base(lo.x() * inv_dx), n.i0 - K::N + 1), bx_hi = std::min(K::base(hi.x() * inv_dx), n.i1);
  const int by_lo = std::max(K::base(lo.y() * inv_dx), n.j0 - K::N + 1), by_hi = std::min(K::base(hi.y() * inv_dx), n.j1);
  if (bx_lo > bx_hi || by_lo > by_hi) return;
  const auto [first, last] = strips_of_bases<K>(bx_lo, bx_hi, strips);
  for (int strip = first; strip <= last; ++strip) {
    const auto [pa, pb] = strip_rows_of_bases(strip, by_lo, by_hi);
    for (uint32_t p = pa; p < pb; ++p) {
      const Vec2 r = Vec2(p_.x[p], p_.y[p]) - s.position_m;
      if (r.x() < s.lo_m.x() - reach || r.y() < s.lo_m.y() - reach || r.x() > s.hi_m.x() + reach ||
          r.y() > s.hi_m.y() + reach)
        continue;
      const int base_x = K::base(p_.x[p] * inv_dx), base_y = K::base(p_.y[p] * inv_dx);
      if (base_y > n.j1 || base_y + K::N - 1 < n.j0 || base_x > n.i1 || base_x + K::N - 1 < n.i0) continue;
      double wx[K::N], wy[K::N], dw[K::N];
      const int bx = K::weights(p_.x[p] * inv_dx, wx, dw, inv_dx);
      const int by = K::weights(p_.y[p] * inv_dx, wy, dw, inv_dx);
      const int ja = std::max(by, j0), jb = std::min(by + K::N - 1, j1);
      const int ia = std::max(bx, i0), ib = std::min(bx + K::N - 1, i1);
      bool reached = false;  // over the whole stencil, not only this band's nodes
      for (int j = ja; j <= jb; ++j)
        for (int i = ia; i <= ib; ++i) reached |= f[size_t(j - j0) * width + size_t(i - i0)] > 0.0;
      if (!reached) continue;
      const Vec2 q = s.to_body(Vec2(p_.x[p], p_.y[p]));
      const bool touching = shape_sdf(shape, q) - 0.5 * std::sqrt(p_.volume[p]) <= kTouchCells * dx;
      const Vec2 normal = s.to_world(shape_normal(shape, q, 1e-4 * dx));
      const Vec3 nn(normal.x() * normal.x(), normal.x() * normal.y(), normal.y() * normal.y());
      const double mass = double(p_.mass[p]);
      for (int j = std::max(ja, n.j0); j <= std::min(jb, n.j1); ++j)
        for (int i = std::max(ia, n.i0); i <= std::min(ib, n.i1); ++i) {
          const size_t k = g_.index(i, j), c = size_t(j - j0) * width + size_t(i - i0);
          if (f[c] <= 0.0) continue;
          if (touching) touched[k] = 1;
          const double wm = wx[i - bx] * wy[j - by] * mass;
          m_points[c] += wm;
          Vec2 v(g_.node[k].vx, g_.node[k].vy);
          const Vec2 v0 = v;
          if (!contact(v, s.velocity_at(Vec2(i * dx, j * dx)), normal, mu)) continue;
          dv[c] += wm * (v - v0);
          if (free) stencil_nn_[b][c] += wm * nn;
        }
    }
  }
}

// Domain walls act on the nodes on and beyond each boundary line (walls lie on node lines, so
// node contact is exact for them): left, right, bottom, top, in that order at a corner node.
// wall_impulse_[c] holds what each wall gave column c, summed up the column.
void Simulation::walls_on_column(int i, std::array<Vec2, 4>& impulse) {
  const int P = Grid::kPad, nx = g_.nx, ny = g_.ny;
  const bool wall_friction = scene_.effects.wall_friction;
  GridNode* const column = g_.node.data() + g_.index(i, -P);
  auto wall = [&](const Wall& w, int side, int j0, int j1, const Vec2& n) {
    Vec2 sum(0.0, 0.0);
    if (w.kind != Wall::Kind::Open)
      for (int j = j0; j <= j1; ++j) {
        GridNode& node = column[j + P];
        if (node.m <= 0.0) continue;
        Vec2 v(node.vx, node.vy);
        const Vec2 before = v;
        if (w.kind == Wall::Kind::Sticky)
          v.setZero();
        else
          contact(v, Vec2(0.0, 0.0), n, w.kind == Wall::Kind::Friction && wall_friction ? w.friction : 0.0);
        sum += node.m * (v - before);
        node.vx = v.x();
        node.vy = v.y();
      }
    impulse[size_t(side)] = sum;
  };
  const Vec2 zero(0.0, 0.0);
  if (i <= 0) wall(scene_.walls.left, 0, -P, ny + P, Vec2(1, 0));
  else impulse[0] = zero;
  if (i >= nx) wall(scene_.walls.right, 1, -P, ny + P, Vec2(-1, 0));
  else impulse[1] = zero;
  wall(scene_.walls.bottom, 2, -P, 0, Vec2(0, 1));
  wall(scene_.walls.top, 3, ny, ny + P, Vec2(0, -1));
}

// The walls' forces on the media from the columns' impulses, column by column
void Simulation::sum_wall_impulses() {
  std::array<Vec2, 4> sum{Vec2::Zero(), Vec2::Zero(), Vec2::Zero(), Vec2::Zero()};
  for (const auto& column : wall_impulse_)
    for (size_t side = 0; side < 4; ++side) sum[side] += column[side];
  for (size_t side = 0; side < 4; ++side) wall_forces_[side] = -sum[side] / dt_s_;
}

// The walls after the bodies (a body reaches a boundary line, or particle contact).
void Simulation::contact_walls() {
  wall_impulse_.resize(size_t(g_.NX));
  for (int c = 0; c < g_.NX; ++c) walls_on_column(c - Grid::kPad, wall_impulse_[size_t(c)]);
  sum_wall_impulses();
}

// Friction of the front and back walls of a quasi-2D channel (scene walls.front_back): a point
// pressing on them with sigma_zz < 0 loses up to dt 2 mu |sigma_zz| V / (gap m) of its in-plane
// speed, against its motion (Coulomb: it may stop, never reverse). Applied to the points' velocities
// after G2P, so the next P2G carries the loss and the FLIP update does not add it back.
void Simulation::front_back_friction() {
  const FrontBackWalls& w = scene_.walls.front_back;
  const double k = 2.0 * w.friction * dt_s_ / w.gap_m;
  auto& P = p_;
  const Vec2 impulse = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<size_t>(0, P.size(), kGrain), Vec2(0.0, 0.0),
      [&](const tbb::blocked_range<size_t>& r, Vec2 sum) {
        for (size_t p = r.begin(); p < r.end(); ++p) {
          const double sigma_zz = double(P.szz[p]) - P.pressure[p];
          const double speed = std::hypot(P.vx[p], P.vy[p]);
          if (sigma_zz >= 0.0 || speed == 0.0) continue;
          const double keep = 1.0 - std::min(speed, k * -sigma_zz * P.volume[p] / P.mass[p]) / speed;
          sum -= double(P.mass[p]) * (1.0 - keep) * Vec2(P.vx[p], P.vy[p]);
          P.vx[p] *= keep;
          P.vy[p] *= keep;
        }
        return sum;
      },
      [](const Vec2& a, const Vec2& b) { return Vec2(a + b); });
  stats_.front_back_impulse_N_s_per_m = impulse;
}

// Two-way coupling of a body's free degrees of freedom u = (vx, vy, omega). The contact has just
// held each node against the body moving at u0 and given the media `impulse` (and `angular`, about
// the body's origin). Had the body moved at u0 + du, each held node would have changed by a further
// P G du (P its projector, G du the body's velocity change at the node), the media gaining K du
// with K = sum m G^T P G. The body's equation, M du = -impulse + dt F_applied + dt M g - K du, is
// solved for du over the free degrees of freedom, and each node takes its P G du: the media gain
// exactly what the body loses, so media + body change momentum only by gravity and the applied
// loads, and a body light against the media it holds moves with them instead of overshooting
// (K in the denominator), a heavy one barely responds (M).
void Simulation::respond_free_body(size_t b, Vec2& impulse, double& angular) {
  const BodyDynamics& d = scene_.bodies[b].dynamics;
  BodyState& s = bodies_[b];
  const double dt = dt_s_, dx = g_.dx;
  const auto [i0, i1, j0, j1] = body_node_box(s, g_);
  const size_t width = size_t(i1 - i0 + 1);
  const std::vector<Vec3>& held = held_[b];
  auto jacobian = [](const Vec2& r) {  // body velocity change at r per du
    Eigen::Matrix<double, 2, 3> G;
    G << 1.0, 0.0, -r.y(), 0.0, 1.0, r.x();
    return G;
  };
  auto projector = [](const Vec3& h) { return (Eigen::Matrix2d() << h.x(), h.y(), h.y(), h.z()).finished(); };
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const Vec3& h = held[size_t(j - j0) * width + size_t(i - i0)];
      if (h.isZero()) continue;
      const auto G = jacobian(Vec2(i * dx, j * dx) - s.position_m);
      A += g_.node[g_.index(i, j)].m * (G.transpose() * projector(h) * G);
    }
  A(0, 0) += d.mass_kg_per_m;
  A(1, 1) += d.mass_kg_per_m;
  A(2, 2) += d.inertia_kg_m;
  // the applied load at the step's end time, ramped (a footing set down gently); the weight at once
  const double ramp = d.load_ramp_s > 0.0 ? std::min(1.0, (t_s_ + dt) / d.load_ramp_s) : 1.0;
  const Vec2 load = ramp * d.applied_force_N_per_m + d.mass_kg_per_m * gravity_;
  const Vec3 rhs(dt * load.x() - impulse.x(), dt * load.y() - impulse.y(), dt * ramp * d.applied_torque_N - angular);
  // the free degrees of freedom only: a prescribed one does not change here
  const bool free[3] = {d.free_x, d.free_y, d.free_angle};
  int index[3], nf = 0;
  for (int k = 0; k < 3; ++k)
    if (free[k]) index[nf++] = k;
  Eigen::MatrixXd Af(nf, nf);
  Eigen::VectorXd bf(nf);
  for (int a = 0; a < nf; ++a) {
    bf[a] = rhs[index[a]];
    for (int c = 0; c < nf; ++c) Af(a, c) = A(index[a], index[c]);
  }
  const Eigen::VectorXd x = Af.ldlt().solve(bf);  // symmetric positive definite: mass > 0
  Vec3 du(0.0, 0.0, 0.0);
  for (int a = 0; a < nf; ++a) du[index[a]] = x[a];
  // the held nodes follow the body's change
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const Vec3& h = held[size_t(j - j0) * width + size_t(i - i0)];
      if (h.isZero()) continue;
      const Vec2 r = Vec2(i * dx, j * dx) - s.position_m;
      const Vec2 dv = projector(h) * (jacobian(r) * du);
      GridNode& n = g_.node[g_.index(i, j)];
      n.vx += dv.x();
      n.vy += dv.y();
      const Vec2 dp = n.m * dv;
      impulse += dp;
      angular += r.x() * dp.y() - r.y() * dp.x();
    }
  s.velocity_m_s += du.head<2>();
  s.omega_rad_s += du.z();
}

// the instances Simulation's constructor picks from
template void Simulation::contact_nodes<false>();
template void Simulation::contact_nodes<true>();
template bool Simulation::plan_cell_fraction<LinearKernel>();
template bool Simulation::plan_cell_fraction<QuadraticKernel>();
template bool Simulation::plan_cell_fraction<CubicKernel>();
template void Simulation::cell_fraction_band<LinearKernel>(size_t, bool);
template void Simulation::cell_fraction_band<QuadraticKernel>(size_t, bool);
template void Simulation::cell_fraction_band<CubicKernel>(size_t, bool);

}  // namespace furrow
