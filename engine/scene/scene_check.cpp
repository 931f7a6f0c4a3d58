// Checks across a scene's sections once every section is read: geometry (bodies, beds and walls
// in the domain, bodies against the grid) and cost.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "engine/bodies.hpp"
#include "engine/fields.hpp"
#include "engine/scene/scene_detail.hpp"
#include "engine/scene/scene_io.hpp"

namespace furrow::scene_detail {

std::string idx_path(const char* array, size_t i, const std::string& key) {
  return std::string("/") + array + "/" + std::to_string(i) + (key.empty() ? "" : "/" + key);
}

namespace {

// Smallest feature of a shape (circle diameter, box short side, polygon width) and its path.
void smallest_feature(const Shape& s, const std::string& path, double& size, std::string& where) {
  auto take = [&](double d, const std::string& p) {
    if (d < size) size = d, where = p;
  };
  switch (s.kind) {
    case Shape::Kind::Circle: take(2.0 * s.radius_m, path + "/radius_m"); break;
    case Shape::Kind::Box: take(s.size_m.minCoeff(), path + "/size_m"); break;
    case Shape::Kind::Polygon: {
      // width of a convex polygon: the smallest extent across its edge normals
      const auto& v = s.vertices_m;
      double w = kInf;
      for (size_t i = 0; i < v.size(); ++i) {
        const Vec2 e = v[(i + 1) % v.size()] - v[i];
        const Vec2 n = Vec2(-e.y(), e.x()).normalized();
        double lo = kInf, hi = -kInf;
        for (const auto& p : v) lo = std::min(lo, n.dot(p)), hi = std::max(hi, n.dot(p));
        w = std::min(w, hi - lo);
      }
      take(w, path + "/vertices_m");
      break;
    }
    case Shape::Kind::Union:
      for (size_t i = 0; i < s.parts.size(); ++i) smallest_feature(s.parts[i], path + "/parts/" + std::to_string(i), size, where);
      break;
  }
}

// Why a body with bounds [lo, hi] at some time is not allowed there; "" if it is.
std::string wall_problem(const Scene& s, const Vec2& lo, const Vec2& hi) {
  const double W = s.domain.width_m, H = s.domain.height_m, dx = s.domain.dx_m;
  const double tol = 1e-9 * std::max(W, H);
  struct Side { const char* name; const Wall& wall; double clearance; };
  const Side sides[] = {{"left", s.walls.left, lo.x()}, {"right", s.walls.right, W - hi.x()},
                        {"bottom", s.walls.bottom, lo.y()}, {"top", s.walls.top, H - hi.y()}};
  for (const auto& side : sides)
    if (side.clearance < -tol) return std::string("it crosses the ") + side.name + " edge of the domain";
  for (const auto& side : sides)
    if (side.wall.kind != Wall::Kind::Open && side.clearance < dx - tol)
      return std::string("it overlaps the ") + side.name + " wall: clearance " + approx(side.clearance) +
             " m is less than one cell (dx_m = " + num_str(dx) + ")";
  return "";
}

// Bounds of a body about its origin for the whole run: one that turns may point any way, so its
// reach in every direction; one that does not, its outline at the start angle.
std::pair<Vec2, Vec2> body_run_bounds_m(const Body& b) {
  if (!b.rotates()) return shape_bounds_m(b.shape);
  const bool turns = b.dynamics.free_angle || motion_max_angular_speed_rad_s(b.motion) > 0.0;
  const double ca = std::cos(b.start_angle_rad), sa = std::sin(b.start_angle_rad);
  Vec2 lo = Vec2::Constant(kInf), hi = -lo;
  double reach = 0.0;
  for (const auto& loop : shape_outline(b.shape, 64))
    for (const Vec2& p : loop) {
      reach = std::max(reach, p.norm());
      const Vec2 w(ca * p.x() - sa * p.y(), sa * p.x() + ca * p.y());
      lo = lo.cwiseMin(w), hi = hi.cwiseMax(w);
    }
  const double pad = 0.002 * std::max(reach, (hi - lo).maxCoeff());  // a 64-gon lies inside its circle
  if (turns) return {Vec2::Constant(-reach - pad), Vec2::Constant(reach + pad)};
  return {lo - Vec2::Constant(pad), hi + Vec2::Constant(pad)};
}

}  // namespace

void check_scene(const Ctx& c, const Scene& s) {
  const double W = s.domain.width_m, H = s.domain.height_m, dx = s.domain.dx_m;
  const double tol = 1e-9 * std::max(W, H);

  if (dx > 0.25 * std::min(W, H))
    fail(c, "/domain/dx_m", num_str(dx), "at most a quarter of the domain's smaller side (" +
                                             num_str(0.25 * std::min(W, H)) + " m)");
  const double nodes = (W / dx + 2.0) * (H / dx + 2.0);
  if (nodes > 2e9) fail(c, "/domain/dx_m", num_str(dx), "a grid of fewer than 2e9 nodes (this is " + approx(nodes) + ")");

  // materials: unique names, each used by some bed
  for (size_t i = 0; i < s.materials.size(); ++i) {
    for (size_t k = 0; k < i; ++k)
      if (s.materials[k].name == s.materials[i].name)
        fail(c, idx_path("materials", i, "name"), json(s.materials[i].name),
             "a name not used by another material (/materials/" + std::to_string(k) + " has it)");
    bool used = false;
    for (const auto& b : s.beds) used |= b.material == s.materials[i].name;
    if (!used)
      fail(c, idx_path("materials", i, "name"), json(s.materials[i].name),
           "a material some bed uses (an unused material would still slow the time step)");
  }

  // beds: inside the domain, at least a cell each way, not overlapping each other
  for (size_t i = 0; i < s.beds.size(); ++i) {
    const Bed& b = s.beds[i];
    if (!(b.max_m.x() > b.min_m.x() && b.max_m.y() > b.min_m.y()))
      fail(c, idx_path("beds", i, "max_m"), vec_str(b.max_m),
           "a corner above and right of min_m " + vec_str(b.min_m) + " (the bed is empty)");
    if ((b.max_m - b.min_m).minCoeff() < dx - tol)
      fail(c, idx_path("beds", i, "max_m"), vec_str(b.max_m),
           "a bed at least one cell (dx_m = " + num_str(dx) + ") wide and tall from min_m " + vec_str(b.min_m));
    if (b.min_m.x() < -tol || b.min_m.y() < -tol)
      fail(c, idx_path("beds", i, "min_m"), vec_str(b.min_m), "a corner inside the domain [0, " + num_str(W) +
                                                                  "] x [0, " + num_str(H) + "] m");
    if (b.max_m.x() > W + tol || b.max_m.y() > H + tol)
      fail(c, idx_path("beds", i, "max_m"), vec_str(b.max_m), "a corner inside the domain [0, " + num_str(W) +
                                                                  "] x [0, " + num_str(H) + "] m");
    for (size_t k = 0; k < i; ++k) {
      const Bed& o = s.beds[k];
      const Vec2 lo = b.min_m.cwiseMax(o.min_m), hi = b.max_m.cwiseMin(o.max_m);
      if (hi.x() - lo.x() > tol && hi.y() - lo.y() > tol)
        fail(c, idx_path("beds", i), "a bed from " + vec_str(b.min_m) + " to " + vec_str(b.max_m),
             "beds that do not overlap (it overlaps /beds/" + std::to_string(k) + ")");
    }
  }

  // bodies: unique names, resolvable by the grid, inside the domain for the whole run
  const double t_end = estimate_end_time_s(s);
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    const Body& b = s.bodies[i];
    for (size_t k = 0; k < i; ++k)
      if (s.bodies[k].name == b.name)
        fail(c, idx_path("bodies", i, "name"), json(b.name),
             "a name not used by another body (/bodies/" + std::to_string(k) + " has it)");
    double feature = kInf;
    std::string where;
    smallest_feature(b.shape, idx_path("bodies", i, "shape"), feature, where);
    if (dx > feature)
      fail(c, where, "a feature " + num_str(feature) + " m across",
           "a body at least one cell across (domain.dx_m = " + num_str(dx) + " m); use a smaller dx_m");
    const auto [lo, hi] = body_run_bounds_m(b);
    const std::string turning = b.rotates() && b.start_angle_rad == 0.0 ? " (turning, it reaches " + approx(hi.x()) + " m from its origin every way)" : "";
    if (std::string why = wall_problem(s, b.start_m + lo, b.start_m + hi); !why.empty())
      fail(c, idx_path("bodies", i, "start_m"), vec_str(b.start_m), "a start that keeps the body inside the domain" + turning + "; " + why);
    if (b.dynamics.any_free() && s.solver.contact == ContactMethod::Particle)
      fail(c, idx_path("bodies", i, "free"), "free degrees of freedom with solver.contact \"particle\"",
           "\"node\" or \"cell_fraction\" contact: a body responds through the grid's contact impulse");
    // a free body goes where the media let it: the run stops with an error if it leaves the domain
    if (motion_max_speed_m_s(b.motion) == 0.0 || b.dynamics.any_free()) continue;
    // sample the run (exact at knots and at the end; position is piecewise quadratic between)
    std::vector<double> times;
    for (int k = 1; k <= 256; ++k) times.push_back(t_end * k / 256.0);
    for (const auto& knot : b.motion.path)
      if (knot.t_s < t_end) times.push_back(knot.t_s);
    std::sort(times.begin(), times.end());
    for (double t : times) {
      const Vec2 p = b.start_m + motion_displacement_m(b.motion, t);
      if (std::string why = wall_problem(s, p + lo, p + hi); !why.empty())
        fail(c, idx_path("bodies", i, "motion"), "a motion reaching " + approx(p) + " at t = " + approx(t) + " s",
             "a motion that keeps the body inside the domain until the run ends at t = " + approx(t_end) +
                 " s; " + why + " (or end the run sooner: solver.end_time_s / end_displacement_m)");
    }
  }

  if (s.solver.end_displacement_m > 0.0 && reference_body_index(s) < 0)
    fail(c, "/solver/end_displacement_m", num_str(s.solver.end_displacement_m), "null: no body moves");

  // averaging window must start before the run ends
  if (s.outputs.average_from_m >= 0.0) {
    const int ref = reference_body_index(s);
    if (ref < 0)
      fail(c, "/outputs/average_window", "a displacement window", "a time window {\"from_s\", \"to_s\"}: no body moves");
    const double reach = motion_displacement_m(s.bodies[size_t(ref)].motion, t_end).norm();
    if (s.outputs.average_from_m >= reach * (1 + 1e-9))
      fail(c, "/outputs/average_window/from_m", num_str(s.outputs.average_from_m),
           "a displacement the run reaches (body \"" + s.bodies[size_t(ref)].name + "\" travels " + approx(reach) + " m)");
  } else if (s.outputs.average_from_s >= t_end) {
    fail(c, "/outputs/average_window/from_s", num_str(s.outputs.average_from_s),
         "a time before the run ends (" + approx(t_end) + " s)");
  }

  // cost: `--yes` (allow_large) lets big runs through
  const double particles = double(estimate_particle_count(s));
  if (particles > kMaxParticles && !c.options.allow_large)
    fail(c, "/domain/dx_m", num_str(dx),
         "at most " + num_str(kMaxParticles) + " particles (estimated " + approx(particles) +
             " = bed area / dx^2 * ppc^2); use a larger dx_m, or --yes to accept");
  const double steps = double(estimate_step_count(s));
  if (steps > kMaxSteps && !c.options.allow_large)
    fail(c, "/solver/end_time_s", num_str(s.solver.end_time_s),
         "at most " + num_str(kMaxSteps) + " steps (estimated " + approx(steps) + " at dt = " +
             approx(estimate_time_step_s(s)) + " s); shorten the run, or --yes to accept");
}

}  // namespace furrow::scene_detail
