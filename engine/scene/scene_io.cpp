// Scene JSON reading and validation.
// Each object declares its keys once (the k*Keys lists of scene_schema.cpp); the reader rejects any
// other key with its JSON pointer and the nearest valid key, and checks that every declared key
// was looked at. The checks across sections (geometry, cost) are in scene_check.cpp.
#include "engine/scene/scene_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "engine/bodies.hpp"
#include "engine/fields.hpp"
#include "engine/scene/scene_detail.hpp"

namespace furrow {

using namespace scene_detail;

// ---------------------------------------------------------------------------------------------
// errors

static std::string format_error(const SceneError& e) {
  std::ostringstream os;
  os << e.file;
  if (e.line > 0)
    os << ":" << e.line << ":" << e.column << " (byte " << e.byte << ")";
  else
    os << ": " << (e.path.empty() ? "/" : e.path);
  os << ": got " << e.value << ", expected " << e.expected;
  if (!e.note.empty()) os << " (" << e.note << ")";
  return os.str();
}

SceneError::SceneError(std::string file_, std::string path_, std::string value_,
                       std::string expected_, std::string note_, int line_, int column_,
                       size_t byte_)
    : std::runtime_error(""), file(std::move(file_)), path(std::move(path_)),
      value(std::move(value_)), expected(std::move(expected_)), note(std::move(note_)),
      line(line_), column(column_), byte(byte_) {
  static_cast<std::runtime_error&>(*this) = std::runtime_error(format_error(*this));
}

namespace {

// ---------------------------------------------------------------------------------------------
// reading

// One JSON object being consumed: unknown keys are rejected on construction, and finish()
// checks that the code looked at every key it declared (schema and reader cannot drift apart).
class Obj {
 public:
  Obj(const Ctx& c, const json& j, std::string path, KeyList keys,
      std::map<std::string, std::string> hints = {}, const std::string& what = "an object")
      : c_(c), j_(j), path_(std::move(path)), keys_(std::move(keys)) {
    if (!j.is_object()) fail(c, path_, j, what + " {" + join(keys_) + "}");
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (std::find(keys_.begin(), keys_.end(), it.key()) != keys_.end()) continue;
      const std::string at = path_ + "/" + escape_pointer_token(it.key());
      const std::string got = short_dump(json(it.key())) + ": " + short_dump(it.value());
      if (auto h = hints.find(it.key()); h != hints.end()) fail(c, at, got, h->second);
      fail(c, at, got,
           "a key of " + display() + suggestion(it.key(), keys_) + "; keys here: " + join(keys_));
    }
  }

  const json* opt(const std::string& key) {
    used_.insert(key);
    auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  const json& req(const std::string& key, const std::string& expected) {
    const json* v = opt(key);
    if (!v) fail(c_, at(key), "(missing)", expected);
    return *v;
  }
  std::string at(const std::string& key) const { return path_ + "/" + key; }
  const std::string& path() const { return path_; }
  const Ctx& ctx() const { return c_; }
  void finish() const {
    for (const auto& k : keys_)
      if (!used_.count(k)) throw std::logic_error("scene reader never read declared key " + at(k));
  }

 private:
  std::string display() const { return path_.empty() ? "/" : path_; }
  const Ctx& c_;
  const json& j_;
  std::string path_;
  KeyList keys_;
  std::set<std::string> used_;
};

// Accepted number ranges; the expectation text is generated from them.
struct Range {
  double lo = -kInf, hi = kInf;
  bool lo_open = false, hi_open = false;
  bool contains(double x) const {
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
  std::string text(const std::string& unit) const {
    std::string s;
    if (lo == -kInf && hi == kInf) s = "a finite number";
    else if (hi == kInf) s = std::string("a number ") + (lo_open ? "> " : ">= ") + num_str(lo);
    else if (lo == -kInf) s = std::string("a number ") + (hi_open ? "< " : "<= ") + num_str(hi);
    else
      s = std::string("a number in ") + (lo_open ? "(" : "[") + num_str(lo) + ", " + num_str(hi) +
          (hi_open ? ")" : "]");
    if (!unit.empty()) s += " (" + unit + ")";
    return s;
  }
};
const Range kAny{};
const Range kPositive{0.0, kInf, true, false};
const Range kNonNegative{0.0, kInf, false, false};
Range open(double a, double b) { return {a, b, true, true}; }
Range closed(double a, double b) { return {a, b, false, false}; }
Range half_open(double a, double b) { return {a, b, false, true}; }
const Range kFriction = closed(0.0, 5.0);
const Range kPacking = open(0.3, 0.75);

double as_number(const Ctx& c, const json& v, const std::string& path, const Range& r,
                 const std::string& unit, const std::string& why = "") {
  const std::string expected = r.text(unit) + why;
  if (!v.is_number()) fail(c, path, v, expected);
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(c, path, v, "a finite number" + (unit.empty() ? "" : " (" + unit + ")"));
  if (!r.contains(x)) fail(c, path, v, expected);
  return x;
}

double num(Obj& o, const std::string& key, const Range& r, const std::string& unit,
           std::optional<double> def = std::nullopt, const std::string& why = "") {
  const json* v = def ? o.opt(key) : &o.req(key, r.text(unit) + why);
  if (!v) return *def;
  return as_number(o.ctx(), *v, o.at(key), r, unit, why);
}

int64_t as_integer(const Ctx& c, const json& v, const std::string& path, int64_t lo, int64_t hi) {
  const std::string expected = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!v.is_number()) fail(c, path, v, expected);
  const double x = v.get<double>();
  if (!(x >= double(lo) && x <= double(hi)) || std::floor(x) != x) fail(c, path, v, expected);
  return int64_t(x);
}

int64_t integer(Obj& o, const std::string& key, int64_t lo, int64_t hi, std::optional<int64_t> def) {
  const std::string expected = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  const json* v = def ? o.opt(key) : &o.req(key, expected);
  if (!v) return *def;
  return as_integer(o.ctx(), *v, o.at(key), lo, hi);
}

bool boolean(Obj& o, const std::string& key, bool def) {
  const json* v = o.opt(key);
  if (!v) return def;
  if (!v->is_boolean()) fail(o.ctx(), o.at(key), *v, "true or false");
  return v->get<bool>();
}

std::string as_string(const Ctx& c, const json& v, const std::string& path, const std::string& expected) {
  if (!v.is_string()) fail(c, path, v, expected);
  std::string s = v.get<std::string>();
  try {
    (void)json(s).dump();  // strings set from the command line may not be UTF-8
  } catch (const json::exception&) {
    fail(c, path, v, expected + " (valid UTF-8)");
  }
  return s;
}

bool valid_name(const std::string& s) {
  if (s.empty() || s.size() > 64 || s[0] == '.' || s[0] == '-') return false;
  for (char ch : s)
    if (!(std::isalnum((unsigned char)ch) || ch == '_' || ch == '-' || ch == '.')) return false;
  return true;
}
const char* kNameRule = "a name of 1-64 characters from A-Z a-z 0-9 _ - . (not starting with . or -)";

std::string name_value(Obj& o, const std::string& key, std::optional<std::string> def = std::nullopt) {
  const json* v = def ? o.opt(key) : &o.req(key, kNameRule);
  if (!v) return *def;
  std::string s = as_string(o.ctx(), *v, o.at(key), kNameRule);
  if (!valid_name(s)) fail(o.ctx(), o.at(key), *v, kNameRule);
  return s;
}

// Index into `names` of the string at `key` (required unless def >= 0).
int choice(Obj& o, const std::string& key, const KeyList& names, int def = -1) {
  const json* v = def >= 0 ? o.opt(key) : &o.req(key, one_of(names));
  if (!v) return def;
  if (!v->is_string()) fail(o.ctx(), o.at(key), *v, one_of(names));
  const std::string s = v->get<std::string>();
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == s) return int(i);
  fail(o.ctx(), o.at(key), *v, one_of(names) + suggestion(s, names));
}

Vec2 as_vec2(const Ctx& c, const json& v, const std::string& path, const Range& r,
             const std::string& unit) {
  const std::string expected = "[x, y], two numbers" +
                               (r.lo == -kInf && r.hi == kInf ? std::string(" (") + unit + ")"
                                                              : ", each " + r.text(unit));
  if (!v.is_array() || v.size() != 2) fail(c, path, v, expected);
  Vec2 out;
  for (int i = 0; i < 2; ++i) {
    const std::string p = path + "/" + std::to_string(i);
    if (!v[size_t(i)].is_number()) fail(c, p, v[size_t(i)], expected);
    out[i] = as_number(c, v[size_t(i)], p, r, unit);
  }
  return out;
}

Vec2 vec2(Obj& o, const std::string& key, const Range& r, const std::string& unit,
          std::optional<Vec2> def = std::nullopt) {
  const json* v = def ? o.opt(key) : &o.req(key, "[x, y], two numbers (" + unit + ")");
  if (!v) return *def;
  return as_vec2(o.ctx(), *v, o.at(key), r, unit);
}

const json& array(Obj& o, const std::string& key, const std::string& what, bool required,
                  size_t min_items) {
  static const json empty = json::array();
  const std::string expected = "an array of " + what +
                               (min_items ? " (at least " + std::to_string(min_items) + ")" : "");
  const json* v = required ? &o.req(key, expected) : o.opt(key);
  if (!v) return empty;
  if (!v->is_array() || v->size() < min_items) fail(o.ctx(), o.at(key), *v, expected);
  if (v->size() > kMaxListItems)
    fail(o.ctx(), o.at(key), "an array of " + std::to_string(v->size()) + " items",
         "at most " + std::to_string(kMaxListItems) + " " + what);
  return *v;
}

// ---------------------------------------------------------------------------------------------
// sections

Domain read_domain(const Ctx& c, const json& j) {
  Obj o(c, j, "/domain", kDomainKeys);
  Domain d;
  d.width_m = num(o, "width_m", kPositive, "m");
  d.height_m = num(o, "height_m", kPositive, "m");
  d.dx_m = num(o, "dx_m", kPositive, "m", std::nullopt, ", the grid cell size");
  o.finish();
  return d;
}

Solver read_solver(const Ctx& c, const json& j) {
  Obj o(c, j, "/solver", kSolverKeys);
  Solver s;
  s.shape_function = ShapeFunction(choice(o, "shape_function", kShapeFunctions, 1));
  s.particles_per_cell_1d = int(integer(o, "particles_per_cell_1d", 1, 8, 2));
  s.cfl = num(o, "cfl", Range{0.0, 1.0, true, false}, "", 0.4);
  s.flip_blend = num(o, "flip_blend", Range{0.0, 1.0, false, false}, "", 0.99);
  // A scene file without the key gets cell_fraction, as every template with bodies ships: node's
  // force comb is a choice to make, not a default (engine/README.md, "Body contact"). The C++
  // Solver struct keeps Node so scenes built in code, the tests' among them, do not move.
  s.contact = ContactMethod(choice(o, "contact", kContactMethods, int(ContactMethod::CellFraction)));
  s.end_time_s = num(o, "end_time_s", kPositive, "s");
  if (const json* v = o.opt("end_displacement_m"); v && !v->is_null())
    s.end_displacement_m = as_number(c, *v, o.at("end_displacement_m"), kPositive, "m", ", or null for none");
  s.threads = int(integer(o, "threads", 0, 1024, 0));
  s.max_steps = int(integer(o, "max_steps", 1, std::numeric_limits<int>::max(), 50'000'000));
  o.finish();
  return s;
}

Material read_material(const Ctx& c, const json& j, const std::string& path) {
  const std::string model = variant_tag(&j, "model");
  const bool dpm = model == "dpm";
  std::map<std::string, std::string> hints;
  if (model == "ndpm") {
    const std::string why = " (DPM-only key; this material has \"model\": \"ndpm\")";
    hints["chi"] = "no \"chi\" on an NDPM material" + why;
    hints["phi_min"] = "no \"phi_min\" on an NDPM material" + why;
    hints["mu_c"] = "\"mu_s\" on an NDPM material (mu_c is the DPM name)";
  } else if (dpm) {
    hints["mu_s"] = "\"mu_c\" on a DPM material (its mu_s follows from phi_d: mu_c + (phi_d - phi_c) chi)";
  }
  Obj o(c, j, path, material_keys(&j), hints, "a material object");
  Material m;
  m.name = name_value(o, "name");
  m.model = MaterialModel(choice(o, "model", kModels));
  m.grain_density_kg_m3 = num(o, "grain_density_kg_m3", Range{0.0, 1e5, true, false}, "kg/m^3");
  m.phi_c = num(o, "phi_c", kPacking, "");
  if (dpm) {
    m.mu = num(o, "mu_c", kFriction, "");
    m.chi = num(o, "chi", closed(0.0, 100.0), "");
    m.phi_min = num(o, "phi_min", open(0.3, m.phi_c), "", 0.45, " (below phi_c)");
  } else {
    m.mu = num(o, "mu_s", kFriction, "");
  }
  m.youngs_modulus_Pa = num(o, "youngs_modulus_Pa", kPositive, "Pa", 5.0e6);
  m.poisson_ratio = num(o, "poisson_ratio", half_open(0.0, 0.5), "", 0.3);
  // mu(I): the rate part is mu_2 - mu on top of the static friction (of phi_d for DPM)
  m.mu_2 = num(o, "mu_2", closed(m.mu, kFriction.hi), "", std::min(m.mu + 0.26, kFriction.hi), dpm ? " (at least mu_c)" : " (at least mu_s)");
  m.inertial_I0 = num(o, "I0", Range{0.0, 10.0, true, false}, "", 0.279);
  m.grain_diameter_m = num(o, "grain_diameter_m", Range{0.0, 0.1, true, false}, "m", 0.53e-3);
  o.finish();
  return m;
}

Bed read_bed(const Ctx& c, const json& j, const std::string& path, const Scene& s) {
  Obj o(c, j, path, kBedKeys, {}, "a bed object");
  Bed b;
  KeyList names;
  for (const auto& m : s.materials) names.push_back(m.name);
  const json& mv = o.req("material", "the name of a material: " + one_of(names));
  b.material = as_string(c, mv, o.at("material"), "the name of a material: " + one_of(names));
  const Material* mat = s.find_material(b.material);
  if (!mat) fail(c, o.at("material"), mv, "the name of a material: " + one_of(names) + suggestion(b.material, names));
  b.min_m = vec2(o, "min_m", kAny, "m");
  b.max_m = vec2(o, "max_m", kAny, "m");
  const Range packing = mat->model == MaterialModel::DPM ? Range{mat->phi_min, 0.75, false, true} : kPacking;
  b.packing_fraction = num(o, "packing_fraction", packing, "", mat->phi_c,
                           mat->model == MaterialModel::DPM ? " (at least the material's phi_min)" : "");
  if (const json* k0 = o.opt("k0")) {
    const std::string expected = "\"jaky\" or a number in (0, 3]";
    if (k0->is_string()) {
      if (k0->get<std::string>() != "jaky") fail(c, o.at("k0"), *k0, expected);
      b.k0 = -1.0;
    } else {
      b.k0 = as_number(c, *k0, o.at("k0"), Range{0.0, 3.0, true, false}, "", " or \"jaky\"");
    }
  }
  b.geostatic = boolean(o, "geostatic", true);
  o.finish();
  return b;
}

Shape read_shape(const Ctx& c, const json& j, const std::string& path, bool is_part, int depth) {
  std::map<std::string, std::string> hints;
  if (!is_part) hints["offset_m"] = "no \"offset_m\" here (only union parts have one; move the body with start_m)";
  const std::string type = variant_tag(&j, "type");
  if (type == "box" || type == "circle" || type == "polygon" || type == "union") {
    for (const auto& [key, t] : std::map<std::string, std::string>{
             {"size_m", "box"}, {"radius_m", "circle"}, {"vertices_m", "polygon"}, {"parts", "union"}})
      if (t != type) hints[key] = "no \"" + key + "\" on a " + type + " (it belongs to a " + t + ")";
  }
  Obj o(c, j, path, shape_keys(&j, is_part), hints, "a shape object");
  Shape s;
  s.kind = Shape::Kind(choice(o, "type", kShapeTypes));
  switch (s.kind) {
    case Shape::Kind::Box:
      s.size_m = vec2(o, "size_m", kPositive, "m");
      break;
    case Shape::Kind::Circle:
      s.radius_m = num(o, "radius_m", kPositive, "m");
      break;
    case Shape::Kind::Polygon: {
      const json& vs = array(o, "vertices_m", "[x, y] vertices (m)", true, 3);
      for (size_t i = 0; i < vs.size(); ++i)
        s.vertices_m.push_back(as_vec2(c, vs[i], o.at("vertices_m") + "/" + std::to_string(i), kAny, "m"));
      // convex and counter-clockwise: every turn is to the left, and the area is positive
      const size_t n = s.vertices_m.size();
      double area2 = 0.0;
      for (size_t i = 0; i < n; ++i) {
        const Vec2 a = s.vertices_m[i], b = s.vertices_m[(i + 1) % n], d = s.vertices_m[(i + 2) % n];
        const Vec2 e1 = b - a, e2 = d - b;
        area2 += a.x() * b.y() - b.x() * a.y();
        if (e1.x() * e2.y() - e1.y() * e2.x() <= 0.0)
          fail(c, o.at("vertices_m") + "/" + std::to_string((i + 1) % n), vs[(i + 1) % n],
               "a convex polygon listed counter-clockwise (each vertex a strict left turn)");
      }
      if (!(area2 > 0.0)) fail(c, o.at("vertices_m"), vs, "a convex counter-clockwise polygon with area > 0");
      break;
    }
    case Shape::Kind::Union: {
      if (depth >= 4) fail(c, o.at("parts"), *o.opt("parts"), "unions nested at most 4 deep");
      const json& ps = array(o, "parts", "shapes", true, 1);
      for (size_t i = 0; i < ps.size(); ++i)
        s.parts.push_back(read_shape(c, ps[i], o.at("parts") + "/" + std::to_string(i), true, depth + 1));
      break;
    }
  }
  if (is_part) s.offset_m = vec2(o, "offset_m", kAny, "m", Vec2::Zero());
  else o.opt("offset_m");
  o.finish();
  return s;
}

Motion read_motion(const Ctx& c, const json& j, const std::string& path) {
  const std::string type = variant_tag(&j, "type");
  std::map<std::string, std::string> hints;
  if (type == "path") hints["velocity_m_s"] = "velocities inside \"knots\" for a path motion";
  if (type == "constant_velocity") hints["knots"] = "no \"knots\" on a constant_velocity motion (use \"type\": \"path\")";
  Obj o(c, j, path, motion_keys(&j), hints, "a motion object");
  Motion m;
  m.kind = Motion::Kind(choice(o, "type", kMotionTypes));
  if (m.kind == Motion::Kind::ConstantVelocity) {
    m.velocity_m_s = vec2(o, "velocity_m_s", kAny, "m/s");
    m.angular_velocity_rad_s = num(o, "angular_velocity_rad_s", kAny, "rad/s, counter-clockwise", 0.0);
  } else {
    const json& ks = array(o, "knots", "{\"t_s\", \"velocity_m_s\"} knots", true, 1);
    for (size_t i = 0; i < ks.size(); ++i) {
      const std::string kp = o.at("knots") + "/" + std::to_string(i);
      Obj k(c, ks[i], kp, kKnotKeys, {}, "a knot object");
      Motion::Knot knot{};
      if (i == 0) {
        knot.t_s = num(k, "t_s", closed(0.0, 0.0), "s", std::nullopt, " (the first knot is at t = 0)");
      } else {
        const double prev = m.path.back().t_s;
        knot.t_s = num(k, "t_s", Range{prev, kInf, true, false}, "s", std::nullopt, " (knot times increase)");
      }
      knot.velocity_m_s = vec2(k, "velocity_m_s", kAny, "m/s");
      knot.angular_velocity_rad_s = num(k, "angular_velocity_rad_s", kAny, "rad/s, counter-clockwise", 0.0);
      k.finish();
      m.path.push_back(knot);
    }
    m.velocity_m_s = m.path.front().velocity_m_s;
    m.angular_velocity_rad_s = m.path.front().angular_velocity_rad_s;
  }
  o.finish();
  return m;
}

// "free": the degrees of freedom that respond to the media, with what they need: a mass (or a
// density, times the shape's area) and, for the angle, a moment of inertia (the shape's own unless
// given).
BodyDynamics read_dynamics(Obj& o, const Shape& shape) {
  const Ctx& c = o.ctx();
  BodyDynamics d;
  const json& free = array(o, "free", "degrees of freedom, each \"x\", \"y\" or \"angle\"", false, 0);
  for (size_t i = 0; i < free.size(); ++i) {
    const std::string p = o.at("free") + "/" + std::to_string(i);
    const std::string dof = as_string(c, free[i], p, "\"x\", \"y\" or \"angle\"");
    bool* flag = dof == "x" ? &d.free_x : dof == "y" ? &d.free_y : dof == "angle" ? &d.free_angle : nullptr;
    if (!flag) fail(c, p, free[i], "\"x\", \"y\" or \"angle\"");
    if (*flag) fail(c, p, free[i], "each degree of freedom listed once");
    *flag = true;
  }
  const json* mass = o.opt("mass_kg_per_m");
  const json* density = o.opt("density_kg_m3");
  const json* inertia = o.opt("inertia_kg_m");
  const json* force = o.opt("applied_force_N_per_m");
  const json* torque = o.opt("applied_torque_N");
  const json* ramp = o.opt("load_ramp_s");
  if (!d.any_free()) {
    // a prescribed body has no use for them: say so rather than ignore them
    for (const auto& [key, v] : {std::pair{"mass_kg_per_m", mass}, {"density_kg_m3", density}, {"inertia_kg_m", inertia},
                                 {"applied_force_N_per_m", force}, {"applied_torque_N", torque}, {"load_ramp_s", ramp}})
      if (v) fail(c, o.at(key), *v, "no \"" + std::string(key) + "\" on a body whose motion is all prescribed (list the degrees of freedom that respond in \"free\")");
    return d;
  }
  if (mass && density) fail(c, o.at("density_kg_m3"), *density, "either \"mass_kg_per_m\" or \"density_kg_m3\", not both");
  if (!mass && !density)
    fail(c, o.at("mass_kg_per_m"), "(missing)", "a positive mass (kg per metre) or \"density_kg_m3\": the body has free degrees of freedom");
  const ShapeMass sm = shape_mass_properties(shape);
  if (mass) {
    d.mass_kg_per_m = as_number(c, *mass, o.at("mass_kg_per_m"), kPositive, "kg per metre");
  } else {
    d.mass_kg_per_m = as_number(c, *density, o.at("density_kg_m3"), kPositive, "kg/m^3") * sm.area_m2;
  }
  if (inertia) {
    d.inertia_kg_m = as_number(c, *inertia, o.at("inertia_kg_m"), kPositive, "kg m^2 per metre, about the body's origin");
  } else {
    d.inertia_kg_m = d.mass_kg_per_m * sm.second_moment_m4 / sm.area_m2;  // a uniform body
  }
  if (force) d.applied_force_N_per_m = as_vec2(c, *force, o.at("applied_force_N_per_m"), kAny, "N per metre");
  if (torque) d.applied_torque_N = as_number(c, *torque, o.at("applied_torque_N"), kAny, "N m per metre, counter-clockwise");
  if (ramp) d.load_ramp_s = as_number(c, *ramp, o.at("load_ramp_s"), kNonNegative, "seconds over which the applied load rises from 0");
  return d;
}

Body read_body(const Ctx& c, const json& j, const std::string& path) {
  Obj o(c, j, path, kBodyKeys, {}, "a body object");
  Body b;
  b.name = name_value(o, "name");
  b.shape = read_shape(c, o.req("shape", "a shape object {\"type\": " + one_of(kShapeTypes) + ", ...}"),
                       o.at("shape"), false, 0);
  b.start_m = vec2(o, "start_m", kAny, "m");
  b.start_angle_rad = num(o, "start_angle_deg", closed(-360.0, 360.0), "degrees, counter-clockwise", 0.0) * M_PI / 180.0;
  if (const json* mv = o.opt("motion")) b.motion = read_motion(c, *mv, o.at("motion"));
  b.dynamics = read_dynamics(o, b.shape);
  b.friction = num(o, "friction", kFriction, "", 0.35);
  o.finish();
  return b;
}

Wall read_wall(const Ctx& c, const json* j, const std::string& path, Wall def) {
  if (!j) return def;
  std::map<std::string, std::string> hints;
  const std::string type = variant_tag(j, "type");
  if (!type.empty() && type != "friction")
    hints["friction"] = "no \"friction\" on a " + type + " wall (use \"type\": \"friction\")";
  Obj o(c, *j, path, wall_keys(j), hints, "a wall object");
  Wall w;
  w.kind = Wall::Kind(choice(o, "type", kWallTypes));
  if (w.kind == Wall::Kind::Friction) w.friction = num(o, "friction", kFriction, "");
  else o.opt("friction");
  o.finish();
  return w;
}

Walls read_walls(const Ctx& c, const json* j) {
  Walls w;
  if (!j) return w;
  Obj o(c, *j, "/walls", kWallsKeys);
  w.left = read_wall(c, o.opt("left"), o.at("left"), w.left);
  w.right = read_wall(c, o.opt("right"), o.at("right"), w.right);
  w.bottom = read_wall(c, o.opt("bottom"), o.at("bottom"), w.bottom);
  w.top = read_wall(c, o.opt("top"), o.at("top"), w.top);
  if (const json* fb = o.opt("front_back"); fb && !fb->is_null()) {
    Obj f(c, *fb, o.at("front_back"), kFrontBackKeys);
    w.front_back.gap_m = num(f, "gap_m", Range{0.0, 10.0, true, false}, "m");
    w.front_back.friction = num(f, "friction", kFriction, "");
    f.finish();
  }
  o.finish();
  return w;
}

Effects read_effects(const Ctx& c, const json* j, const Scene& s) {
  bool any_dpm = false;
  for (const auto& m : s.materials) any_dpm |= m.model == MaterialModel::DPM;
  Effects e;
  e.dilatancy = any_dpm;
  if (!j) return e;
  Obj o(c, *j, "/effects", kEffectsKeys);
  e.gravity = boolean(o, "gravity", true);
  e.gravity_m_s2 = vec2(o, "gravity_m_s2", kAny, "m/s^2", e.gravity_m_s2);
  e.dilatancy = boolean(o, "dilatancy", any_dpm);
  if (e.dilatancy && !any_dpm)
    fail(c, o.at("dilatancy"), *o.opt("dilatancy"), "false: dilatancy needs a material with \"model\": \"dpm\"");
  e.separation = boolean(o, "separation", true);
  e.body_friction = boolean(o, "body_friction", true);
  e.wall_friction = boolean(o, "wall_friction", true);
  e.rate_dependence = boolean(o, "rate_dependence", false);
  o.finish();
  return e;
}

KeyList field_names() {
  KeyList names;
  for (const auto& f : field_registry()) names.push_back(f.name);
  return names;
}

Outputs read_outputs(const Ctx& c, const json* j, const Scene& s) {
  Outputs out;
  if (!j) return out;
  Obj o(c, *j, "/outputs", kOutputsKeys);
  out.frame_interval_s = num(o, "frame_interval_s", kNonNegative, "s", 0.0, ", 0 for no frames");
  bool any_dpm = false;
  for (const auto& m : s.materials) any_dpm |= m.model == MaterialModel::DPM;
  const KeyList names = field_names();
  const json& fields = array(o, "fields", "field names", false, 0);
  for (size_t i = 0; i < fields.size(); ++i) {
    const std::string p = o.at("fields") + "/" + std::to_string(i);
    const std::string f = as_string(c, fields[i], p, "a field name: " + one_of(names));
    const FieldInfo* info = find_field(f);
    if (!info) fail(c, p, fields[i], "a field name: " + one_of(names) + suggestion(f, names));
    if (info->dpm_only && !any_dpm)
      fail(c, p, fields[i], "a field this scene has (\"" + f + "\" exists only with a DPM material)");
    if (std::find(out.fields.begin(), out.fields.end(), f) != out.fields.end())
      fail(c, p, fields[i], "each field listed once");
    out.fields.push_back(f);
  }
  const json& movies = array(o, "movies", "field names", false, 0);
  for (size_t i = 0; i < movies.size(); ++i) {
    const std::string p = o.at("movies") + "/" + std::to_string(i);
    const std::string expected = "a name listed in /outputs/fields" +
                                 (out.fields.empty() ? std::string(" (which is empty)") : ": " + one_of(out.fields));
    const std::string f = as_string(c, movies[i], p, expected);
    if (std::find(out.fields.begin(), out.fields.end(), f) == out.fields.end())
      fail(c, p, movies[i], expected + suggestion(f, out.fields));
    if (std::find(out.movies.begin(), out.movies.end(), f) != out.movies.end())
      fail(c, p, movies[i], "each movie listed once");
    out.movies.push_back(f);
  }
  if (!out.fields.empty() && out.frame_interval_s == 0.0)
    fail(c, o.at("frame_interval_s"), o.opt("frame_interval_s") ? short_dump(*o.opt("frame_interval_s")) : "(missing)",
         "a number > 0 (s) when /outputs/fields lists fields");
  out.points = boolean(o, "points", false);
  // points are written with each stored frame; fields listed imply frame_interval_s > 0 (above)
  if (out.points && out.fields.empty())
    fail(c, o.at("points"), *o.opt("points"),
         "false when no frames are stored (points go with each frame: list /outputs/fields and set "
         "/outputs/frame_interval_s > 0)");
  if (const json* l = o.opt("layout"); l && !l->is_null()) {
    Obj a(c, *l, o.at("layout"), kLayoutKeys);
    MovieLayout& lay = out.layout;
    lay.name = name_value(a, "name");
    const json& lf = array(a, "fields", "field names", true, 1);
    // any drawable field: one the scene does not store (fields overridden to [] for a quick run)
    // leaves the layout's movie out of that run, it does not make the scene invalid
    KeyList drawable = names;
    drawable.insert(drawable.end(), {"velocity_x", "velocity_y"});
    const std::string expected = "a field name: " + one_of(drawable);
    for (size_t i = 0; i < lf.size(); ++i) {
      const std::string p = a.at("fields") + "/" + std::to_string(i);
      const std::string f = as_string(c, lf[i], p, expected);
      if (std::find(drawable.begin(), drawable.end(), f) == drawable.end())
        fail(c, p, lf[i], expected + suggestion(f, drawable));
      if (std::find(lay.fields.begin(), lay.fields.end(), f) != lay.fields.end())
        fail(c, p, lf[i], "each field listed once");
      lay.fields.push_back(f);
    }
    if (const json* b = a.opt("frame_of"); b && !b->is_null()) {
      KeyList bodies;
      for (const auto& body : s.bodies) bodies.push_back(body.name);
      const std::string want = "the name of a body in /bodies" + (bodies.empty() ? std::string(" (there is none)") : ": " + one_of(bodies));
      lay.frame_of = as_string(c, *b, a.at("frame_of"), want);
      if (std::find(bodies.begin(), bodies.end(), lay.frame_of) == bodies.end())
        fail(c, a.at("frame_of"), *b, want + suggestion(lay.frame_of, bodies));
    }
    lay.zoom = num(a, "zoom", closed(1.0, 50.0), "", 1.0);
    if (lay.zoom != 1.0 && lay.frame_of.empty())
      fail(c, a.at("zoom"), *a.opt("zoom"), "1 without /outputs/layout/frame_of (the view is enlarged about a body)");
    // with no moving body (a template's plate held still by an override) the movie is drawn in
    // units instead: a layout never makes a scene invalid for its physics
    lay.normalize = boolean(a, "normalize", false);
    a.finish();
  }
  out.force_interval_s = num(o, "force_interval_s", kNonNegative, "s", 0.0, ", 0 for every step");
  if (const json* w = o.opt("average_window")) {
    Obj a(c, *w, o.at("average_window"), kWindowKeys);
    const bool by_time = a.opt("from_s") || a.opt("to_s");
    const bool by_disp = a.opt("from_m") || a.opt("to_m");
    if (by_time == by_disp)
      fail(c, a.path(), *w, "either {\"from_s\", \"to_s\"} (time) or {\"from_m\", \"to_m\"} (body displacement)");
    const std::string unit = by_time ? "s" : "m";
    double from = num(a, by_time ? "from_s" : "from_m", kNonNegative, unit, 0.0);
    double to = -1.0;
    const std::string to_key = by_time ? "to_s" : "to_m";
    if (const json* t = a.opt(to_key); t && !t->is_null())
      to = as_number(c, *t, a.at(to_key), Range{from, kInf, true, false}, unit, ", or null for the end of the run");
    (by_time ? out.average_from_s : out.average_from_m) = from;
    (by_time ? out.average_to_s : out.average_to_m) = to;
    a.finish();
  }
  o.finish();
  return out;
}

std::string default_name(const std::string& source) {
  std::string stem = source;
  if (auto slash = stem.find_last_of('/'); slash != std::string::npos) stem = stem.substr(slash + 1);
  if (auto dot = stem.rfind('.'); dot != std::string::npos && dot > 0) stem = stem.substr(0, dot);
  return valid_name(stem) ? stem : "scene";
}

}  // namespace

Scene parse_scene(const json& j, const std::string& source, const ValidationOptions& options) {
  const Ctx c{source, options};
  Obj o(c, j, "", kRootKeys, {}, "a scene: a JSON object");
  Scene s;
  const std::string version_rule = "1 (the only schema_version this furrow reads)";
  const json& version = o.req("schema_version", version_rule);
  if (!(version.is_number_integer() && version.get<int64_t>() == 1)) fail(c, "/schema_version", version, version_rule);
  s.schema_version = 1;
  s.name = name_value(o, "name", default_name(source));
  if (const json* d = o.opt("description")) s.description = as_string(c, *d, "/description", "a string");
  s.domain = read_domain(c, o.req("domain", "an object {" + join(kDomainKeys) + "}"));
  s.solver = read_solver(c, o.req("solver", "an object {" + join(kSolverKeys) + "} with at least end_time_s"));

  const json& mats = array(o, "materials", "material objects", true, 1);
  for (size_t i = 0; i < mats.size(); ++i) s.materials.push_back(read_material(c, mats[i], idx_path("materials", i)));
  const json& beds = array(o, "beds", "bed objects", true, 1);
  for (size_t i = 0; i < beds.size(); ++i) s.beds.push_back(read_bed(c, beds[i], idx_path("beds", i), s));
  const json& bodies = array(o, "bodies", "body objects", false, 0);
  for (size_t i = 0; i < bodies.size(); ++i) s.bodies.push_back(read_body(c, bodies[i], idx_path("bodies", i)));
  s.walls = read_walls(c, o.opt("walls"));
  s.effects = read_effects(c, o.opt("effects"), s);
  s.outputs = read_outputs(c, o.opt("outputs"), s);
  o.finish();
  check_scene(c, s);
  return s;
}

}  // namespace furrow
