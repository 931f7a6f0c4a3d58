// The scene schema's key lists, message helpers and path helpers (engine/scene/scene_detail.hpp), and
// schema_keys(), which `--set` uses to tell a missing-but-valid key from a typo.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "engine/scene/scene_detail.hpp"

namespace furrow {
namespace scene_detail {

// A short, always-printable dump of a value for messages.
std::string short_dump(const json& v) {
  std::string s = v.dump(-1, ' ', false, json::error_handler_t::replace);
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s;
}

// Shortest text that reads back as the same double ("0", "0.3", "1e-05").
std::string num_str(double x) {
  char buf[40];
  if (std::floor(x) == x && std::fabs(x) < 1e7) {
    std::snprintf(buf, sizeof buf, "%.0f", x);
    return buf;
  }
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

std::string vec_str(const Vec2& v) { return "[" + num_str(v.x()) + ", " + num_str(v.y()) + "]"; }

// Derived quantities (clearances, positions along a path) to four significant digits.
std::string approx(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}
std::string approx(const Vec2& v) { return "[" + approx(v.x()) + ", " + approx(v.y()) + "]"; }

std::string escape_pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string join(const KeyList& keys, const std::string& sep) {
  std::string s;
  for (size_t i = 0; i < keys.size(); ++i) s += (i ? sep : "") + keys[i];
  return s;
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      const bool same = std::tolower((unsigned char)a[i - 1]) == std::tolower((unsigned char)b[j - 1]);
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (same ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// " (did you mean "x"?)" when a candidate is close enough to be a plausible typo.
std::string suggestion(const std::string& got, const KeyList& candidates) {
  std::string best;
  size_t best_d = std::numeric_limits<size_t>::max();
  for (const auto& c : candidates) {
    const size_t d = edit_distance(got, c);
    if (d < best_d) best_d = d, best = c;
  }
  if (best.empty() || got.size() > 200) return "";
  const size_t limit = std::max<size_t>(2, std::min(got.size(), best.size()) / 3);
  if (best_d <= limit) return " (did you mean \"" + best + "\"?)";
  return "";
}

std::string one_of(const KeyList& names) {
  KeyList q;
  for (const auto& n : names) q.push_back("\"" + n + "\"");
  return q.size() == 1 ? q[0] : "one of " + join(q);
}

const KeyList kRootKeys = {"schema_version", "name", "description", "domain", "solver", "materials",
                           "beds", "bodies", "walls", "effects", "outputs"};
const KeyList kDomainKeys = {"width_m", "height_m", "dx_m"};
const KeyList kSolverKeys = {"shape_function", "particles_per_cell_1d", "cfl", "flip_blend", "contact", "end_time_s",
                             "end_displacement_m", "threads", "max_steps"};
const KeyList kMaterialNdpmKeys = {"name", "model", "grain_density_kg_m3", "phi_c", "mu_s",
                                   "youngs_modulus_Pa", "poisson_ratio", "mu_2", "I0", "grain_diameter_m"};
const KeyList kMaterialDpmKeys = {"name", "model", "grain_density_kg_m3", "phi_c", "mu_c", "chi",
                                  "phi_min", "youngs_modulus_Pa", "poisson_ratio", "mu_2", "I0", "grain_diameter_m"};
const KeyList kBedKeys = {"material", "min_m", "max_m", "packing_fraction", "k0", "geostatic"};
const KeyList kBodyKeys = {"name", "shape", "start_m", "start_angle_deg", "motion", "free", "mass_kg_per_m", "density_kg_m3",
                           "inertia_kg_m", "applied_force_N_per_m", "applied_torque_N", "load_ramp_s", "friction"};
const KeyList kBoxKeys = {"type", "size_m"};
const KeyList kCircleKeys = {"type", "radius_m"};
const KeyList kPolygonKeys = {"type", "vertices_m"};
const KeyList kUnionKeys = {"type", "parts"};
const KeyList kConstantMotionKeys = {"type", "velocity_m_s", "angular_velocity_rad_s"};
const KeyList kPathMotionKeys = {"type", "knots"};
const KeyList kKnotKeys = {"t_s", "velocity_m_s", "angular_velocity_rad_s"};
const KeyList kWallsKeys = {"left", "right", "bottom", "top", "front_back"};
const KeyList kFrontBackKeys = {"gap_m", "friction"};
const KeyList kFrictionWallKeys = {"type", "friction"};
const KeyList kPlainWallKeys = {"type"};
const KeyList kEffectsKeys = {"gravity", "gravity_m_s2", "dilatancy", "separation", "body_friction",
                              "wall_friction", "rate_dependence"};
const KeyList kOutputsKeys = {"frame_interval_s", "fields", "movies", "points", "layout", "force_interval_s",
                              "average_window"};
const KeyList kLayoutKeys = {"name", "fields", "frame_of", "zoom", "normalize"};
const KeyList kWindowKeys = {"from_s", "to_s", "from_m", "to_m"};

const KeyList kModels = {"ndpm", "dpm"};  // enum orders of scene.hpp
const KeyList kShapeTypes = {"circle", "box", "polygon", "union"};  // Shape::Kind order
const KeyList kMotionTypes = {"constant_velocity", "path"};
const KeyList kWallTypes = {"slip", "friction", "sticky", "open"};
const KeyList kShapeFunctions = {"linear", "quadratic", "cubic"};
const KeyList kContactMethods = {"node", "particle", "cell_fraction"};  // ContactMethod order

KeyList merged(std::initializer_list<const KeyList*> lists) {
  KeyList out;
  for (const KeyList* l : lists)
    for (const auto& k : *l)
      if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
  return out;
}

KeyList with_offset(KeyList keys) {
  keys.push_back("offset_m");
  return keys;
}

// Keys for a variant object: the variant named by `tag` in `obj`, or all variants' keys.
KeyList shape_keys(const json* obj, bool is_part) {
  std::string type;
  if (obj && obj->is_object() && obj->contains("type") && (*obj)["type"].is_string())
    type = (*obj)["type"].get<std::string>();
  KeyList k;
  if (type == "box") k = kBoxKeys;
  else if (type == "circle") k = kCircleKeys;
  else if (type == "polygon") k = kPolygonKeys;
  else if (type == "union") k = kUnionKeys;
  else k = merged({&kBoxKeys, &kCircleKeys, &kPolygonKeys, &kUnionKeys});
  return is_part ? with_offset(k) : k;
}

std::string variant_tag(const json* obj, const char* key) {
  if (obj && obj->is_object() && obj->contains(key) && (*obj)[key].is_string())
    return (*obj)[key].get<std::string>();
  return "";
}

KeyList material_keys(const json* obj) {
  const std::string m = variant_tag(obj, "model");
  if (m == "ndpm") return kMaterialNdpmKeys;
  if (m == "dpm") return kMaterialDpmKeys;
  return merged({&kMaterialNdpmKeys, &kMaterialDpmKeys});
}

KeyList motion_keys(const json* obj) {
  const std::string t = variant_tag(obj, "type");
  if (t == "constant_velocity") return kConstantMotionKeys;
  if (t == "path") return kPathMotionKeys;
  return merged({&kConstantMotionKeys, &kPathMotionKeys});
}

KeyList wall_keys(const json* obj) {
  const std::string t = variant_tag(obj, "type");
  if (t == "friction") return kFrictionWallKeys;
  if (std::find(kWallTypes.begin(), kWallTypes.end(), t) != kWallTypes.end()) return kPlainWallKeys;
  return kFrictionWallKeys;
}

[[noreturn]] void fail(const Ctx& c, const std::string& path, const std::string& value,
                       const std::string& expected) {
  throw SceneError(c.source, path, value, expected);
}

[[noreturn]] void fail(const Ctx& c, const std::string& path, const char* value,
                       const std::string& expected) {
  fail(c, path, std::string(value), expected);
}

[[noreturn]] void fail(const Ctx& c, const std::string& path, const json& value,
                       const std::string& expected) {
  fail(c, path, short_dump(value), expected);
}

std::vector<std::string> split_path(const std::string& key_path) {
  std::vector<std::string> segs;
  if (!key_path.empty() && key_path[0] == '/') {
    // JSON pointer
    std::string cur;
    for (size_t i = 1; i <= key_path.size(); ++i) {
      if (i == key_path.size() || key_path[i] == '/') {
        segs.push_back(cur);
        cur.clear();
      } else if (key_path[i] == '~' && i + 1 < key_path.size() && (key_path[i + 1] == '0' || key_path[i + 1] == '1')) {
        cur += key_path[i + 1] == '0' ? '~' : '/';
        ++i;
      } else {
        cur += key_path[i];
      }
    }
    return segs;
  }
  std::string cur;
  for (char ch : key_path) {
    if (ch == '.') segs.push_back(cur), cur.clear();
    else cur += ch;
  }
  segs.push_back(cur);
  return segs;
}

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() < 10 && std::all_of(s.begin(), s.end(), [](char ch) { return std::isdigit((unsigned char)ch); });
}

}  // namespace scene_detail

using namespace scene_detail;

std::vector<std::string> schema_keys(const json& root, const std::string& pointer) {
  const std::vector<std::string> segs = pointer.empty() ? std::vector<std::string>{} : split_path(pointer);
  auto node_at = [&](size_t depth) -> const json* {
    const json* n = &root;
    for (size_t i = 0; i < depth && n; ++i) {
      if (n->is_object()) {
        auto it = n->find(segs[i]);
        n = it == n->end() ? nullptr : &*it;
      } else if (n->is_array() && all_digits(segs[i]) && std::stoul(segs[i]) < n->size()) {
        n = &(*n)[std::stoul(segs[i])];
      } else {
        n = nullptr;
      }
    }
    return n;
  };
  const size_t n = segs.size();
  const json* here = node_at(n);
  auto is = [&](size_t i, const char* s) { return i < n && segs[i] == s; };
  if (n == 0) return kRootKeys;
  if (n == 1) {
    if (is(0, "domain")) return kDomainKeys;
    if (is(0, "solver")) return kSolverKeys;
    if (is(0, "walls")) return kWallsKeys;
    if (is(0, "effects")) return kEffectsKeys;
    if (is(0, "outputs")) return kOutputsKeys;
    return {};
  }
  if (n == 2) {
    if (is(0, "materials")) return material_keys(here);
    if (is(0, "beds")) return kBedKeys;
    if (is(0, "bodies")) return kBodyKeys;
    if (is(0, "walls") && is(1, "front_back")) return kFrontBackKeys;
    if (is(0, "walls")) return wall_keys(here);
    if (is(0, "outputs") && is(1, "average_window")) return kWindowKeys;
    if (is(0, "outputs") && is(1, "layout")) return kLayoutKeys;
    return {};
  }
  if (!is(0, "bodies")) return {};
  if (n == 3 && is(2, "motion")) return motion_keys(here);
  if (n == 5 && is(2, "motion") && is(3, "knots")) return kKnotKeys;
  if (is(2, "shape")) {
    // /bodies/i/shape(/parts/k)*
    for (size_t i = 3; i < n; i += 2)
      if (!(is(i, "parts") && i + 1 < n)) return {};
    return shape_keys(here, n > 3);
  }
  return {};
}

const char* contact_method_name(ContactMethod method) { return scene_detail::kContactMethods.at(size_t(method)).c_str(); }

}  // namespace furrow
