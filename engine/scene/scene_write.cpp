// Scene -> resolved JSON (every key written) and its pretty text in schema order.
#include <algorithm>
#include <cmath>

#include "engine/scene/scene_detail.hpp"

namespace furrow {

using namespace scene_detail;

namespace {

template <class J>
J vec_json(const Vec2& v) {
  return J::array({v.x(), v.y()});
}

template <class J>
J shape_json(const Shape& s, bool is_part) {
  J j = J::object();
  j["type"] = kShapeTypes[size_t(s.kind)];
  switch (s.kind) {
    case Shape::Kind::Box: j["size_m"] = vec_json<J>(s.size_m); break;
    case Shape::Kind::Circle: j["radius_m"] = s.radius_m; break;
    case Shape::Kind::Polygon:
      j["vertices_m"] = J::array();
      for (const auto& v : s.vertices_m) j["vertices_m"].push_back(vec_json<J>(v));
      break;
    case Shape::Kind::Union:
      j["parts"] = J::array();
      for (const auto& p : s.parts) j["parts"].push_back(shape_json<J>(p, true));
      break;
  }
  if (is_part) j["offset_m"] = vec_json<J>(s.offset_m);
  return j;
}

template <class J>
J wall_json(const Wall& w) {
  J j = J::object();
  j["type"] = kWallTypes[size_t(w.kind)];
  if (w.kind == Wall::Kind::Friction) j["friction"] = w.friction;
  return j;
}

template <class J>
J optional_number(double x) {
  return x >= 0.0 ? J(x) : J(nullptr);
}

template <class J>
J to_json(const Scene& s) {
  J j = J::object();
  j["schema_version"] = s.schema_version;
  j["name"] = s.name;
  j["description"] = s.description;
  j["domain"] = {{"width_m", s.domain.width_m}, {"height_m", s.domain.height_m}, {"dx_m", s.domain.dx_m}};
  J solver = J::object();
  solver["shape_function"] = kShapeFunctions[size_t(s.solver.shape_function)];
  solver["particles_per_cell_1d"] = s.solver.particles_per_cell_1d;
  solver["cfl"] = s.solver.cfl;
  solver["flip_blend"] = s.solver.flip_blend;
  solver["contact"] = kContactMethods[size_t(s.solver.contact)];
  solver["end_time_s"] = s.solver.end_time_s;
  solver["end_displacement_m"] = s.solver.end_displacement_m > 0.0 ? J(s.solver.end_displacement_m) : J(nullptr);
  solver["threads"] = s.solver.threads;
  solver["max_steps"] = s.solver.max_steps;
  j["solver"] = solver;

  j["materials"] = J::array();
  for (const auto& m : s.materials) {
    J mj = J::object();
    const bool dpm = m.model == MaterialModel::DPM;
    mj["name"] = m.name;
    mj["model"] = kModels[size_t(m.model)];
    mj["grain_density_kg_m3"] = m.grain_density_kg_m3;
    mj["phi_c"] = m.phi_c;
    mj[dpm ? "mu_c" : "mu_s"] = m.mu;
    if (dpm) {
      mj["chi"] = m.chi;
      mj["phi_min"] = m.phi_min;
    }
    mj["youngs_modulus_Pa"] = m.youngs_modulus_Pa;
    mj["poisson_ratio"] = m.poisson_ratio;
    mj["mu_2"] = m.mu_2;
    mj["I0"] = m.inertial_I0;
    mj["grain_diameter_m"] = m.grain_diameter_m;
    j["materials"].push_back(mj);
  }
  j["beds"] = J::array();
  for (const auto& b : s.beds) {
    J bj = J::object();
    bj["material"] = b.material;
    bj["min_m"] = vec_json<J>(b.min_m);
    bj["max_m"] = vec_json<J>(b.max_m);
    bj["packing_fraction"] = b.packing_fraction;
    bj["k0"] = b.k0 < 0.0 ? J("jaky") : J(b.k0);
    bj["geostatic"] = b.geostatic;
    j["beds"].push_back(bj);
  }
  j["bodies"] = J::array();
  for (const auto& b : s.bodies) {
    J bj = J::object();
    bj["name"] = b.name;
    bj["shape"] = shape_json<J>(b.shape, false);
    bj["start_m"] = vec_json<J>(b.start_m);
    // rotation and dynamics keys only when used: a body that neither turns nor responds keeps the
    // resolved scene (and its hash) it had before bodies could
    if (b.start_angle_rad != 0.0) bj["start_angle_deg"] = b.start_angle_rad * 180.0 / M_PI;
    J mj = J::object();
    mj["type"] = kMotionTypes[size_t(b.motion.kind)];
    if (b.motion.kind == Motion::Kind::ConstantVelocity) {
      mj["velocity_m_s"] = vec_json<J>(b.motion.velocity_m_s);
      if (b.motion.angular_velocity_rad_s != 0.0) mj["angular_velocity_rad_s"] = b.motion.angular_velocity_rad_s;
    } else {
      mj["knots"] = J::array();
      for (const auto& k : b.motion.path) {
        J kj = J::object();
        kj["t_s"] = k.t_s;
        kj["velocity_m_s"] = vec_json<J>(k.velocity_m_s);
        if (k.angular_velocity_rad_s != 0.0) kj["angular_velocity_rad_s"] = k.angular_velocity_rad_s;
        mj["knots"].push_back(kj);
      }
    }
    bj["motion"] = mj;
    if (const BodyDynamics& d = b.dynamics; d.any_free()) {
      J free = J::array();
      if (d.free_x) free.push_back("x");
      if (d.free_y) free.push_back("y");
      if (d.free_angle) free.push_back("angle");
      bj["free"] = free;
      bj["mass_kg_per_m"] = d.mass_kg_per_m;
      bj["inertia_kg_m"] = d.inertia_kg_m;
      bj["applied_force_N_per_m"] = vec_json<J>(d.applied_force_N_per_m);
      bj["applied_torque_N"] = d.applied_torque_N;
      if (d.load_ramp_s > 0.0) bj["load_ramp_s"] = d.load_ramp_s;
    }
    bj["friction"] = b.friction;
    j["bodies"].push_back(bj);
  }
  J walls = J::object();
  walls["left"] = wall_json<J>(s.walls.left);
  walls["right"] = wall_json<J>(s.walls.right);
  walls["bottom"] = wall_json<J>(s.walls.bottom);
  walls["top"] = wall_json<J>(s.walls.top);
  if (s.walls.front_back.present()) {
    J fb = J::object();
    fb["gap_m"] = s.walls.front_back.gap_m;
    fb["friction"] = s.walls.front_back.friction;
    walls["front_back"] = fb;
  } else {
    walls["front_back"] = nullptr;  // plane strain: no such walls
  }
  j["walls"] = walls;
  J effects = J::object();
  effects["gravity"] = s.effects.gravity;
  effects["gravity_m_s2"] = vec_json<J>(s.effects.gravity_m_s2);
  effects["dilatancy"] = s.effects.dilatancy;
  effects["separation"] = s.effects.separation;
  effects["body_friction"] = s.effects.body_friction;
  effects["wall_friction"] = s.effects.wall_friction;
  effects["rate_dependence"] = s.effects.rate_dependence;
  j["effects"] = effects;
  J out = J::object();
  out["frame_interval_s"] = s.outputs.frame_interval_s;
  out["fields"] = s.outputs.fields;
  out["movies"] = s.outputs.movies;
  out["points"] = s.outputs.points;
  out["layout"] = nullptr;  // none: resolved scenes list every key
  if (!s.outputs.layout.name.empty()) {
    J lay = J::object();
    lay["name"] = s.outputs.layout.name;
    lay["fields"] = s.outputs.layout.fields;
    lay["frame_of"] = s.outputs.layout.frame_of.empty() ? J(nullptr) : J(s.outputs.layout.frame_of);
    lay["zoom"] = s.outputs.layout.zoom;
    lay["normalize"] = s.outputs.layout.normalize;
    out["layout"] = lay;
  }
  out["force_interval_s"] = s.outputs.force_interval_s;
  J window = J::object();
  if (s.outputs.average_from_m >= 0.0) {
    window["from_m"] = s.outputs.average_from_m;
    window["to_m"] = optional_number<J>(s.outputs.average_to_m);
  } else {
    window["from_s"] = std::max(0.0, s.outputs.average_from_s);
    window["to_s"] = optional_number<J>(s.outputs.average_to_s);
  }
  out["average_window"] = window;
  j["outputs"] = out;
  return j;
}

}  // namespace

json scene_to_json(const Scene& scene) { return to_json<json>(scene); }

namespace {

using ojson = nlohmann::ordered_json;

bool scalar(const ojson& v) { return !v.is_structured(); }
bool scalar_array(const ojson& v) {
  return v.is_array() && std::all_of(v.begin(), v.end(), [](const ojson& x) { return scalar(x); });
}
std::string dump_scalar(const ojson& v) { return v.dump(-1, ' ', false, json::error_handler_t::replace); }

// Two-space indented JSON that keeps short things on one line: [x, y] pairs, lists of names,
// vertex lists, and small objects such as {"type": "slip"}.
void pretty(const ojson& v, int indent, std::string& out) {
  const std::string pad(size_t(indent) * 2, ' ');
  if (scalar(v)) {
    out += dump_scalar(v);
  } else if (v.is_array()) {
    const bool inline_all = scalar_array(v) || std::all_of(v.begin(), v.end(), [](const ojson& x) { return scalar_array(x); });
    if (v.empty() || inline_all) {
      out += "[";
      for (size_t i = 0; i < v.size(); ++i) {
        if (i) out += ", ";
        pretty(v[i], 0, out);
      }
      out += "]";
    } else {
      out += "[\n";
      for (size_t i = 0; i < v.size(); ++i) {
        out += pad + "  ";
        pretty(v[i], indent + 1, out);
        out += i + 1 < v.size() ? ",\n" : "\n";
      }
      out += pad + "]";
    }
  } else {
    if (v.empty()) {
      out += "{}";
      return;
    }
    bool flat = true;
    for (const auto& [k, x] : v.items()) flat &= scalar(x) || scalar_array(x);
    if (flat) {
      std::string line = "{";
      bool first = true;
      for (const auto& [k, x] : v.items()) {
        line += (first ? "" : ", ") + dump_scalar(ojson(k)) + ": ";
        pretty(x, 0, line);
        first = false;
      }
      line += "}";
      if (line.size() <= 72) {
        out += line;
        return;
      }
    }
    out += "{\n";
    size_t i = 0;
    for (const auto& [k, x] : v.items()) {
      out += pad + "  " + dump_scalar(ojson(k)) + ": ";
      pretty(x, indent + 1, out);
      out += ++i < v.size() ? ",\n" : "\n";
    }
    out += pad + "}";
  }
}

}  // namespace

std::string format_scene(const Scene& scene) {
  std::string out;
  pretty(to_json<ojson>(scene), 0, out);
  return out + "\n";
}

}  // namespace furrow
