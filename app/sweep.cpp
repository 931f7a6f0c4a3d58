#include "app/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "engine/analysis.hpp"
#include "engine/scene/scene_io.hpp"

namespace furrow::sweep {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr size_t kMaxValues = 10000;
constexpr double kPi = 3.14159265358979323846;

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

bool parse_number(const std::string& text, double& out) {
  const std::string t = trim(text);
  if (t.empty()) return false;
  char* end = nullptr;
  out = std::strtod(t.c_str(), &end);
  return end == t.c_str() + t.size() && std::isfinite(out);
}

// Splits at `sep` outside brackets, braces and double quotes.
std::vector<std::string> split_top_level(const std::string& s, char sep) {
  std::vector<std::string> parts(1);
  int depth = 0;
  bool quoted = false;
  for (size_t i = 0; i < s.size(); ++i) {
    const char ch = s[i];
    if (quoted) {
      if (ch == '\\' && i + 1 < s.size()) parts.back() += s[i++];
      else if (ch == '"') quoted = false;
    } else if (ch == '"') {
      quoted = true;
    } else if (ch == '[' || ch == '{') {
      ++depth;
    } else if (ch == ']' || ch == '}') {
      --depth;
    } else if (ch == sep && depth == 0) {
      parts.emplace_back();
      continue;
    }
    parts.back() += ch;
  }
  return parts;
}

std::string format_value(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}

}  // namespace

Vary parse_vary(const std::string& spec) {
  Vary v;
  v.spec = spec;
  const std::string where = "--vary " + spec + ": ";
  const size_t eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw VaryError(where + "expected KEYS=VALUES, e.g. --vary domain.dx_m=0.01:0.02:0.005 or "
                            "--vary bodies.0.friction=0.2,0.35");
  v.column = spec.substr(0, eq);
  for (const auto& k : split_top_level(v.column, '+')) {
    if (trim(k).empty()) throw VaryError(where + "empty key path in '" + v.column + "' (keys are joined by '+')");
    v.keys.push_back(trim(k));
  }
  const std::string text = spec.substr(eq + 1);
  if (trim(text).empty()) throw VaryError(where + "no values after '=' (expected a:b:step or v1,v2,...)");

  const auto range = split_top_level(text, ':');
  if (range.size() > 1) {
    double a = 0, b = 0, step = 0;
    if (range.size() != 3 || !parse_number(range[0], a) || !parse_number(range[1], b) ||
        !parse_number(range[2], step))
      throw VaryError(where + "malformed range '" + text + "': expected a:b:step with three numbers");
    if (step == 0.0) throw VaryError(where + "range step is 0 (expected a non-zero step)");
    const double n = (b - a) / step;
    if (n < -1e-9)
      throw VaryError(where + "range step " + format_value(step) + " leads away from " + format_value(b) +
                      " (use a negative step to count down)");
    if (n + 1 > double(kMaxValues))
      throw VaryError(where + "range gives " + format_value(std::floor(n + 1e-9) + 1) + " values (at most " +
                      std::to_string(kMaxValues) + ")");
    const long count = long(std::floor(n + 1e-9)) + 1;
    for (long k = 0; k < count; ++k) v.values.push_back(format_value(a + double(k) * step));
  } else {
    for (const auto& part : split_top_level(text, ',')) {
      const std::string t = trim(part);
      if (t.empty()) throw VaryError(where + "empty value in the list '" + text + "'");
      v.values.push_back(t);
    }
  }
  std::set<std::string> seen;
  for (const auto& val : v.values) {
    if (!seen.insert(val).second) throw VaryError(where + "value " + val + " is listed twice");
    std::vector<std::string> parts = split_top_level(val, ';');
    if (parts.size() == 1) {
      v.per_key.emplace_back(v.keys.size(), val);
      continue;
    }
    if (parts.size() != v.keys.size())
      throw VaryError(where + "value '" + val + "' gives " + std::to_string(parts.size()) +
                      " values separated by ';' for " + std::to_string(v.keys.size()) +
                      " key(s) (expected one per key joined by '+', or one value for all)");
    for (auto& part : parts) {
      part = trim(part);
      if (part.empty()) throw VaryError(where + "empty value in '" + val + "' (values are separated by ';')");
    }
    v.per_key.push_back(parts);
  }
  return v;
}

std::vector<std::vector<size_t>> combinations(const std::vector<Vary>& varies) {
  std::vector<std::vector<size_t>> out;
  if (varies.empty()) return out;
  std::vector<size_t> idx(varies.size(), 0);
  for (const auto& v : varies)
    if (v.values.empty()) return out;
  while (true) {
    out.push_back(idx);
    size_t k = varies.size();
    while (k > 0) {
      --k;
      if (++idx[k] < varies[k].values.size()) break;
      idx[k] = 0;
      if (k == 0) return out;
    }
  }
}

std::vector<std::string> run_overrides(const std::vector<Vary>& varies, const std::vector<size_t>& combo) {
  std::vector<std::string> sets;
  for (size_t k = 0; k < varies.size(); ++k)
    for (size_t i = 0; i < varies[k].keys.size(); ++i)
      sets.push_back(varies[k].keys[i] + "=" + varies[k].per_key[combo[k]][i]);
  return sets;
}

std::vector<std::string> run_dir_names(const std::string& scene_name, const std::vector<Vary>& varies,
                                       const std::vector<std::vector<size_t>>& combos) {
  auto clean = [](const std::string& s) {
    std::string o;
    for (char ch : s) {
      const bool ok = std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '=' ||
                      ch == '+' || ch == '-';
      o += ok ? ch : '_';
    }
    return o;
  };
  std::vector<std::string> names;
  std::set<std::string> used;
  for (size_t r = 0; r < combos.size(); ++r) {
    std::string n = clean(scene_name);
    for (size_t k = 0; k < varies.size(); ++k) {
      std::string key = varies[k].column;
      if (!key.empty() && key[0] == '/') key = key.substr(1);
      n += "_" + clean(key) + "=" + clean(varies[k].values[combos[r][k]]);
    }
    if (n.size() > 200 || used.count(n)) n = n.substr(0, 190) + "_run" + std::to_string(r + 1);
    used.insert(n);
    names.push_back(n);
  }
  return names;
}

// ---- forces -------------------------------------------------------------------------------------

std::vector<std::vector<ForceSample>> read_forces_csv(const std::string& path, const Scene& scene) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  std::getline(in, line);
  if (line.rfind("t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m", 0) != 0)
    throw std::runtime_error(path + ": unexpected header '" + line + "' (expected t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m)");
  std::map<std::string, size_t> index;
  for (size_t b = 0; b < scene.bodies.size(); ++b) index[scene.bodies[b].name] = b;
  std::vector<std::vector<ForceSample>> out(scene.bodies.size());
  size_t row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) f.push_back(cell);
    if (f.size() < 6) throw std::runtime_error(path + ":" + std::to_string(row) + ": expected 6 columns");
    auto it = index.find(f[1]);
    if (it == index.end()) throw std::runtime_error(path + ":" + std::to_string(row) + ": unknown body '" + f[1] + "'");
    ForceSample s;
    s.t_s = std::strtod(f[0].c_str(), nullptr);
    s.position_m = Vec2(std::strtod(f[2].c_str(), nullptr), std::strtod(f[3].c_str(), nullptr));
    s.force_N_per_m = Vec2(std::strtod(f[4].c_str(), nullptr), std::strtod(f[5].c_str(), nullptr));
    if (f.size() > 6) s.torque_N = std::strtod(f[6].c_str(), nullptr);
    out[it->second].push_back(s);
  }
  return out;
}

namespace {

// Centred moving average over travel (travel is monotone for the prescribed motions).
std::vector<double> smooth_by_travel(const std::vector<double>& travel_m, const std::vector<double>& v, double width_m) {
  const size_t n = std::min(travel_m.size(), v.size());
  std::vector<double> sm(n);
  size_t lo = 0, hi = 0;
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    while (hi < n && travel_m[hi] <= travel_m[i] + 0.5 * width_m) sum += v[hi++];
    while (lo < hi && travel_m[lo] < travel_m[i] - 0.5 * width_m) sum -= v[lo++];
    sm[i] = sum / double(hi - lo);
  }
  return sm;
}

}  // namespace

std::pair<double, double> initial_peak(const std::vector<double>& travel_m, const std::vector<double>& drag,
                                       double smooth_m, double drop) {
  const std::vector<double> sm = smooth_by_travel(travel_m, drag, smooth_m);
  if (sm.empty()) return {kNaN, kNaN};
  double best = sm[0];
  size_t at = 0;
  for (size_t i = 1; i < sm.size(); ++i) {
    if (sm[i] > best) best = sm[i], at = i;
    else if (best > 0.0 && sm[i] < (1.0 - drop) * best) return {best, travel_m[at]};
  }
  return {kNaN, kNaN};
}

double smoothed_max(const std::vector<double>& travel_m, const std::vector<double>& drag, double smooth_m) {
  const std::vector<double> sm = smooth_by_travel(travel_m, drag, smooth_m);
  return sm.empty() ? kNaN : *std::max_element(sm.begin(), sm.end());
}

namespace {

const Bed* bed_under(const Scene& s, double x) {
  const Bed* best = nullptr;
  for (const auto& b : s.beds)
    if (x >= b.min_m.x() && x <= b.max_m.x() && (!best || b.max_m.y() > best->max_m.y())) best = &b;
  if (!best)
    for (const auto& b : s.beds)
      if (!best || b.max_m.y() > best->max_m.y()) best = &b;
  return best;
}

bool moves(const Body& b) { return motion_max_speed_m_s(b.motion) > 0.0; }

Vec2 direction(const Body& b, double t_s) {
  Vec2 v = motion_velocity_m_s(b.motion, t_s);
  if (v.norm() == 0.0) v = motion_velocity_m_s(b.motion, 0.0);
  if (v.norm() == 0.0) {
    // a path starting at rest: its first non-zero knot
    for (const auto& k : b.motion.path)
      if (k.velocity_m_s.norm() > 0.0) {
        v = k.velocity_m_s;
        break;
      }
  }
  return v.norm() > 0.0 ? Vec2(v / v.norm()) : Vec2(1.0, 0.0);
}

const char* kind_name(Shape::Kind k) {
  switch (k) {
    case Shape::Kind::Circle: return "circle";
    case Shape::Kind::Box: return "box";
    case Shape::Kind::Polygon: return "polygon";
    case Shape::Kind::Union: return "union";
  }
  return "?";
}

}  // namespace

RunMetrics run_metrics(const Scene& scene, const RunSummary& summary,
                       const std::vector<std::vector<ForceSample>>& samples) {
  RunMetrics m;
  const double t_end = summary.run_json.value("end_time_s", estimate_end_time_s(scene));
  const int ref = reference_body_index(scene);

  // averaging window in time: a displacement window is converted with the reference body's motion
  const auto& o = scene.outputs;
  if (o.average_from_m >= 0.0 && ref >= 0) {
    const Motion& mo = scene.bodies[size_t(ref)].motion;
    m.window_from_s = std::min(t_end, time_to_displacement_s(mo, o.average_from_m, t_end));
    m.window_to_s = o.average_to_m > o.average_from_m ? std::min(t_end, time_to_displacement_s(mo, o.average_to_m, t_end))
                                                      : t_end;
  } else {
    m.window_from_s = std::max(0.0, o.average_from_s);
    m.window_to_s = o.average_to_s >= 0.0 ? std::min(o.average_to_s, t_end) : t_end;
  }
  const double t_mid = 0.5 * (m.window_from_s + m.window_to_s);

  m.g_m_s2 = scene.effects.gravity ? scene.effects.gravity_m_s2.norm() : kNaN;
  const Body* first_moving = nullptr;
  for (const auto& b : scene.bodies)
    if (moves(b) && !first_moving) first_moving = &b;
  const Body* density_body = first_moving ? first_moving : (scene.bodies.empty() ? nullptr : &scene.bodies[0]);
  const Bed* bed = density_body ? bed_under(scene, density_body->start_m.x()) : (scene.beds.empty() ? nullptr : &scene.beds[0]);
  if (bed) {
    const Material* mat = scene.find_material(bed->material);
    m.rho_d_kg_m3 = mat ? mat->grain_density_kg_m3 * bed->packing_fraction : kNaN;
    m.surface_y_m = bed->max_m.y();
  } else {
    m.rho_d_kg_m3 = m.surface_y_m = kNaN;
  }

  // moving boxes: L_avg, z (bottom depth at the window's middle), inner gap of the first two
  std::vector<size_t> boxes;
  double L_sum = 0.0, z_sum = 0.0;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const Body& body = scene.bodies[b];
    if (body.shape.kind != Shape::Kind::Box || !moves(body)) continue;
    boxes.push_back(b);
    L_sum += body.shape.size_m.x();
    const Vec2 pos = body.start_m + motion_displacement_m(body.motion, t_mid);
    z_sum += m.surface_y_m - (pos.y() - 0.5 * body.shape.size_m.y());
  }
  m.L_avg_m = boxes.empty() ? kNaN : L_sum / double(boxes.size());
  m.z_m = boxes.empty() ? kNaN : z_sum / double(boxes.size());
  m.gap_m = kNaN;
  if (boxes.size() >= 2) {
    const Body *a = &scene.bodies[boxes[0]], *c = &scene.bodies[boxes[1]];
    if (a->start_m.x() > c->start_m.x()) std::swap(a, c);
    m.gap_m = (c->start_m.x() - 0.5 * c->shape.size_m.x()) - (a->start_m.x() + 0.5 * a->shape.size_m.x());
    // to the nanometre: touching plates read s = 0, not the -1e-16 of decimal positions in binary
    m.gap_m = std::round(m.gap_m * 1e9) * 1e-9;
    if (m.gap_m == 0.0) m.gap_m = 0.0;  // not -0
  }
  m.total_F0_N_per_m = m.rho_d_kg_m3 * m.g_m_s2 * m.z_m * m.L_avg_m * 1.0;
  m.total_mean_drag_N_per_m = boxes.empty() ? kNaN : 0.0;

  // reference travel per sample (for displacement windows and peak positions)
  const double dx = scene.domain.dx_m;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const Body& body = scene.bodies[b];
    BodyMetrics bm;
    bm.name = body.name;
    bm.kind = kind_name(body.shape.kind);
    bm.moving = moves(body);
    const auto bounds = shape_bounds_m(body.shape);
    bm.size_m = body.shape.kind == Shape::Kind::Circle ? 2.0 * body.shape.radius_m : bounds.second.x() - bounds.first.x();
    const Vec2 u = direction(body, 0.0);
    const Vec2 n(-u.y(), u.x());
    const auto& s = b < samples.size() ? samples[b] : std::vector<ForceSample>{};

    // time-weighted mean over the window; each row averages the forces since the previous row
    Vec2 sum(0, 0);
    double span = 0.0, torque_sum = 0.0, sinkage_sum = 0.0;
    std::vector<double> travel, drag, bottom_depth;
    const Bed* own = bed_under(scene, body.start_m.x());
    const double surface = own ? own->max_m.y() : m.surface_y_m;
    double t_prev = 0.0;
    for (const auto& r : s) {
      const double dt = r.t_s - t_prev;
      t_prev = r.t_s;
      if (r.t_s >= m.window_from_s - 1e-12 && r.t_s <= m.window_to_s + 1e-12 && dt > 0.0) {
        sum += r.force_N_per_m * dt;
        torque_sum += r.torque_N * dt;
        sinkage_sum += (body.start_m.y() - r.position_m.y()) * dt;
        span += dt;
      }
      const double d = -r.force_N_per_m.dot(u);
      travel.push_back((r.position_m - body.start_m).norm());
      drag.push_back(d);
      bottom_depth.push_back(surface - (r.position_m.y() + bounds.first.y()));
    }
    bm.mean_N_per_m = span > 0.0 ? Vec2(sum / span) : Vec2(kNaN, kNaN);
    bm.mean_torque_N = span > 0.0 ? torque_sum / span : kNaN;
    bm.sinkage_m = span > 0.0 ? sinkage_sum / span : kNaN;
    bm.mean_drag_N_per_m = -bm.mean_N_per_m.dot(u);
    bm.mean_lift_N_per_m = bm.mean_N_per_m.dot(n);
    // smoothing over two cells of travel removes the cell-crossing ripple (period one cell)
    bm.max_drag_N_per_m = smoothed_max(travel, drag, 2.0 * dx);
    const auto pk = bm.moving ? initial_peak(travel, drag, 2.0 * dx) : std::pair<double, double>{kNaN, kNaN};
    bm.peak_drag_N_per_m = pk.first;
    bm.peak_drag_travel_m = pk.second;
    bm.onset_drag_N_per_m = kNaN;
    if (bm.moving && body.shape.kind == Shape::Kind::Box && !bottom_depth.empty() &&
        *std::max_element(bottom_depth.begin(), bottom_depth.end()) >= 0.5 * bm.size_m) {
      // the first cell of depth is the contact transient; the line over [dx, L/2] is the bearing line
      double sx = 0, sy = 0, sxx = 0, sxy = 0;
      size_t n = 0;
      for (size_t k = 0; k < bottom_depth.size(); ++k) {
        const double z = bottom_depth[k];
        if (z < dx || z > 0.5 * bm.size_m) continue;
        sx += z, sy += drag[k], sxx += z * z, sxy += z * drag[k], ++n;
      }
      const double var = sxx - sx * sx / double(n);
      if (n >= 2 && var > 0.0) {
        const double slope = (sxy - sx * sy / double(n)) / var;
        bm.onset_drag_N_per_m = (sy - slope * sx) / double(n);
      }
    }
    const Vec2 pos_mid = body.start_m + motion_displacement_m(body.motion, t_mid);
    if (body.shape.kind == Shape::Kind::Circle) {
      bm.depth_m = surface - pos_mid.y();
      const double r = body.shape.radius_m;
      bm.F0_N_per_m = kPi * r * r * m.rho_d_kg_m3 * m.g_m_s2 * 1.0;
    } else if (body.shape.kind == Shape::Kind::Box) {
      bm.depth_m = surface - (pos_mid.y() - 0.5 * body.shape.size_m.y());
      bm.F0_N_per_m = bm.moving ? m.total_F0_N_per_m : kNaN;
    } else {
      bm.depth_m = surface - (pos_mid.y() + bounds.first.y());
      bm.F0_N_per_m = kNaN;
    }
    if (bm.moving && body.shape.kind == Shape::Kind::Box) m.total_mean_drag_N_per_m += bm.mean_drag_N_per_m;
    m.bodies.push_back(bm);
  }
  const auto c = summary.run_json.find("collapse");
  if (c != summary.run_json.end() && c->is_object()) {
    auto number = [&](const char* key) { return c->contains(key) && (*c)[key].is_number() ? (*c)[key].get<double>() : kNaN; };
    m.collapse = true;
    m.settled = c->value("settled", false);
    m.aspect_ratio = number("aspect_ratio");
    m.runout_relative = number("runout_relative");
    m.final_height_relative = number("final_height_relative");
    const CollapseGeometry g = collapse_geometry(scene);
    const double L0 = number("L0_m");
    if (c->contains("final_surface") && std::isfinite(L0)) {
      const auto& fs = (*c)["final_surface"];
      const auto xs = fs.value("x_m", std::vector<double>{}), hs = fs.value("height_m", std::vector<double>{});
      for (size_t i = 0; i < std::min(xs.size(), hs.size()); ++i) {
        const double d = xs[i] - g.back_x_m;
        m.surface_x_over_L0.push_back((g.side < 0 ? -d : g.side > 0 ? d : std::abs(d)) / L0);
        m.surface_height_over_L0.push_back(hs[i] / L0);
      }
    }
  }
  return m;
}

// ---- the sweep table ----------------------------------------------------------------------------

namespace {

struct Column {
  std::string name, meaning;
  std::function<std::string(const SweepRow&)> cell;
};

std::string num_cell(double v) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}


std::vector<Column> columns(const std::vector<Vary>& varies, const std::vector<SweepRow>& rows) {
  std::vector<Column> cols;
  cols.push_back({"run", "run directory inside the sweep directory", [](const SweepRow& r) { return r.dir; }});
  for (size_t k = 0; k < varies.size(); ++k)
    cols.push_back({varies[k].column, "swept value (--vary " + varies[k].spec + "); unit as the key's suffix says",
                    [k](const SweepRow& r) { return k < r.values.size() ? r.values[k] : std::string(); }});
  cols.push_back({"status", "ok, or failed (why: the error column)",
                  [](const SweepRow& r) { return std::string(r.ok ? "ok" : "failed"); }});
  cols.push_back({"error", "why the run failed: an invalid scene, a solver error, a missing result",
                  [](const SweepRow& r) { return r.ok ? std::string() : r.error; }});
  cols.push_back({"wall_s", "wall time of the run (s)", [](const SweepRow& r) { return num_cell(r.wall_s); }});
  auto metric = [&](const std::string& name, const std::string& meaning, double RunMetrics::*field) {
    cols.push_back({name, meaning, [field](const SweepRow& r) { return r.ok ? num_cell(r.metrics.*field) : ""; }});
  };
  metric("rho_d_kg_m3", "bed density rho_d = rho_g * packing_fraction of the bed under the first moving body (kg/m^3)",
         &RunMetrics::rho_d_kg_m3);
  metric("g_m_s2", "|gravity| (m/s^2)", &RunMetrics::g_m_s2);
  metric("window_from_s", "start of the force averaging window (s)", &RunMetrics::window_from_s);
  metric("window_to_s", "end of the force averaging window (s)", &RunMetrics::window_to_s);

  // bodies, by name in order of first appearance; plate-pair columns when any run has a moving box
  std::vector<std::string> names;
  bool any_box = false;
  for (const auto& r : rows)
    for (const auto& b : r.metrics.bodies) {
      if (std::find(names.begin(), names.end(), b.name) == names.end()) names.push_back(b.name);
      any_box |= b.moving && b.kind == "box";
    }
  bool any_collapse = false;
  for (const auto& r : rows) any_collapse |= r.metrics.collapse;
  if (any_collapse) {
    metric("aspect_ratio_nondim", "released column: a = H0 / L0 (beds' extent; L0 a half-width when both sides are free)",
           &RunMetrics::aspect_ratio);
    metric("runout_nondim", "released column: (Lf - L0) / L0, Lf the final front (run.json collapse)",
           &RunMetrics::runout_relative);
    metric("final_height_nondim", "released column: Hf / H0, Hf the final highest point", &RunMetrics::final_height_relative);
    cols.push_back({"settled", "released column: the front moved less than 1% of L0 over the last tenth of the run",
                    [](const SweepRow& r) { return r.ok && r.metrics.collapse ? std::string(r.metrics.settled ? "yes" : "no") : ""; }});
  }
  if (any_box) {
    metric("L_avg_m", "mean width of the moving boxes (plates), L_avg (m)", &RunMetrics::L_avg_m);
    metric("z_m", "depth of the moving boxes' bottoms below the bed surface at the middle of the averaging window (m)",
           &RunMetrics::z_m);
    metric("gap_m", "gap between the inner edges of the first two moving boxes, s (m)", &RunMetrics::gap_m);
    cols.push_back({"s_over_L_nondim", "s / L_avg",
                    [](const SweepRow& r) { return r.ok ? num_cell(r.metrics.gap_m / r.metrics.L_avg_m) : ""; }});
    metric("total_mean_drag_N_per_m", "sum of the moving boxes' mean drag (N/m)", &RunMetrics::total_mean_drag_N_per_m);
    metric("total_F0_N_per_m", "rho_d g z L_avg w, w = 1 m (N/m)", &RunMetrics::total_F0_N_per_m);
    cols.push_back({"total_mean_drag_nondim", "total_mean_drag / total_F0", [](const SweepRow& r) {
                      return r.ok ? num_cell(r.metrics.total_mean_drag_N_per_m / r.metrics.total_F0_N_per_m) : "";
                    }});
  }
  for (const auto& name : names) {
    auto body = [name](const SweepRow& r) -> const BodyMetrics* {
      if (!r.ok) return nullptr;
      for (const auto& b : r.metrics.bodies)
        if (b.name == name) return &b;
      return nullptr;
    };
    auto add = [&](const std::string& col, const std::string& meaning, std::function<double(const BodyMetrics&)> f) {
      cols.push_back({name + "." + col, meaning, [body, f](const SweepRow& r) {
                        const BodyMetrics* b = body(r);
                        return b ? num_cell(f(*b)) : std::string();
                      }});
    };
    add("size_m", "circle: diameter D; box: width L (m)", [](const BodyMetrics& b) { return b.size_m; });
    add("depth_m", "circle: centre depth; box: bottom depth; below the bed surface, at the middle of the window (m)",
        [](const BodyMetrics& b) { return b.depth_m; });
    add("mean_Fx_N_per_m", "mean Fx over the window (N/m)", [](const BodyMetrics& b) { return b.mean_N_per_m.x(); });
    add("mean_Fy_N_per_m", "mean Fy over the window (N/m)", [](const BodyMetrics& b) { return b.mean_N_per_m.y(); });
    add("mean_torque_N_m_per_m", "mean torque of the media on the body about its origin over the window, "
        "counter-clockwise (N m/m)", [](const BodyMetrics& b) { return b.mean_torque_N; });
    add("sinkage_m", "mean over the window of how far the body's origin is below its start (m)",
        [](const BodyMetrics& b) { return b.sinkage_m; });
    add("mean_drag_N_per_m", "mean drag -F.u over the window, u the direction of motion (N/m)",
        [](const BodyMetrics& b) { return b.mean_drag_N_per_m; });
    add("mean_lift_N_per_m", "mean lift F.n over the window, n = u turned +90 degrees (N/m)",
        [](const BodyMetrics& b) { return b.mean_lift_N_per_m; });
    add("peak_drag_N_per_m",
        "initial peak of the drag (smoothed over 2 dx of travel): the largest drag before it first falls 5% below "
        "its running maximum; empty when it never does (N/m)",
        [](const BodyMetrics& b) { return b.peak_drag_N_per_m; });
    add("peak_travel_m", "travel of the body at the initial peak (m)", [](const BodyMetrics& b) { return b.peak_drag_travel_m; });
    add("max_drag_N_per_m", "largest drag of the run, smoothed over 2 dx of travel (N/m)",
        [](const BodyMetrics& b) { return b.max_drag_N_per_m; });
    add("onset_drag_N_per_m",
        "moving box: drag at the start of penetration, the z -> 0 end of a straight line fitted to the drag "
        "against the bottom's depth z over [dx, L/2] (N/m)",
        [](const BodyMetrics& b) { return b.onset_drag_N_per_m; });
    add("F0_N_per_m",
        "force scale: circle pi (D/2)^2 rho_d g w; moving box rho_d g z L_avg w; w = 1 m (N/m)",
        [](const BodyMetrics& b) { return b.F0_N_per_m; });
    add("mean_drag_nondim", "mean_drag / F0", [](const BodyMetrics& b) { return b.mean_drag_N_per_m / b.F0_N_per_m; });
    add("mean_lift_nondim", "mean_lift / F0", [](const BodyMetrics& b) { return b.mean_lift_N_per_m / b.F0_N_per_m; });
    add("peak_drag_nondim", "peak_drag / F0", [](const BodyMetrics& b) { return b.peak_drag_N_per_m / b.F0_N_per_m; });
    add("onset_drag_nondim", "onset_drag / F0", [](const BodyMetrics& b) { return b.onset_drag_N_per_m / b.F0_N_per_m; });
  }
  return cols;
}

}  // namespace

std::string sweep_csv(const std::vector<Vary>& varies, const std::vector<SweepRow>& rows) {
  const auto cols = columns(varies, rows);
  std::string out;
  for (size_t c = 0; c < cols.size(); ++c) out += (c ? "," : "") + csv_quote(cols[c].name);
  out += "\n";
  for (const auto& r : rows) {
    for (size_t c = 0; c < cols.size(); ++c) out += (c ? "," : "") + csv_quote(cols[c].cell(r));
    out += "\n";
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> sweep_columns(const std::vector<Vary>& varies,
                                                               const std::vector<SweepRow>& rows) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& c : columns(varies, rows)) out.emplace_back(c.name, c.meaning);
  return out;
}

std::string csv_quote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + "\"";
}

}  // namespace furrow::sweep
