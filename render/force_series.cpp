#include "render/force_series.hpp"

#include <algorithm>
#include <filesystem>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "engine/scene/scene_io.hpp"

namespace fs = std::filesystem;

namespace furrow::render {

namespace {
std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

struct Sample {
  double t, x, y, fx, fy;
  double torque = 0, angle_deg = 0, vx = 0, vy = 0, omega = 0;  // 0 in a forces.csv without them
};

// What scene.json beside forces.csv says of a body's degrees of freedom.
struct BodyDofs {
  bool known = false, turns = false, free_x = false, free_y = false;
  double reach_m = 0.0;  // the farthest the shape's box reaches from the body's origin
};

std::map<std::string, BodyDofs> scene_dofs(const std::string& forces_path) {
  std::map<std::string, BodyDofs> out;
  const fs::path scene = fs::path(forces_path).parent_path() / "scene.json";
  if (!fs::exists(scene)) return out;
  try {
    for (const Body& b : load_scene(scene.string()).bodies) {
      const auto [lo, hi] = shape_bounds_m(b.shape);
      out[b.name] = {true, b.rotates(), b.dynamics.free_x, b.dynamics.free_y,
                     std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff())};
    }
  } catch (const std::exception&) {
    // an unreadable scene.json: the rows follow the data alone
  }
  return out;
}
}  // namespace

namespace {
// The rows of the bodies that turn or are free. A body turns when scene.json says so (a start
// angle, an angular velocity, a free angle) or, without scene.json, when its angle or angular
// velocity is ever nonzero; which DOFs are free only scene.json says.
std::vector<MotionRow> motion_rows(const std::vector<std::string>& order,
                                   std::map<std::string, std::vector<Sample>>& bodies,
                                   const std::map<std::string, BodyDofs>& dofs) {
  MotionRow torque{"torque", "torque (N m/m)", true, {}}, depth{"depth", "depth below start (mm)", true, {}};
  MotionRow speed{"speed", "speed (m/s)", false, {}}, angle{"angle", "angle (deg)", false, {}};
  for (const std::string& name : order) {
    const std::vector<Sample>& s = bodies[name];
    BodyDofs d;
    if (const auto it = dofs.find(name); it != dofs.end()) d = it->second;
    if (!d.known)
      for (const Sample& q : s) d.turns |= q.omega != 0.0 || q.angle_deg != 0.0;
    if (!d.turns && !d.free_x && !d.free_y) continue;
    ForceSeries tq, dp, sp, an;
    tq.label = dp.label = sp.label = an.label = name;
    // a torque under 1% of the largest force times the body's reach is round-off or nearly so
    for (const Sample& q : s) torque.y_floor = std::max(torque.y_floor, 0.01 * std::hypot(q.fx, q.fy) * d.reach_m);
    for (const Sample& q : s) {
      for (ForceSeries* f : {&tq, &dp, &sp, &an}) f->t_s.push_back(q.t), f->x.push_back(q.t);
      tq.y.push_back(q.torque);
      dp.y.push_back(1e3 * (s.front().y - q.y));
      sp.y.push_back(std::hypot(q.vx, q.vy));
      an.y.push_back(q.angle_deg);
    }
    torque.series.push_back(std::move(tq));
    if (d.free_y) depth.series.push_back(std::move(dp));
    if (d.free_x || d.free_y) speed.series.push_back(std::move(sp));
    angle.series.push_back(std::move(an));
  }
  std::vector<MotionRow> rows;  // in motion_row_keys()' order
  for (MotionRow* r : {&torque, &depth, &speed, &angle})
    if (!r->series.empty()) rows.push_back(std::move(*r));
  return rows;
}
}  // namespace

ForcePanel read_force_panel(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ": empty file, expected a header line");
  const std::vector<std::string> header = split(line);
  const char* wanted[] = {"t_s", "body", "x_m", "y_m", "Fx_N_per_m", "Fy_N_per_m"};
  int col[6];
  for (int k = 0; k < 6; ++k) {
    col[k] = -1;
    for (size_t c = 0; c < header.size(); ++c)
      if (header[c] == wanted[k]) col[k] = int(c);
    if (col[k] < 0)
      throw std::runtime_error(path + ":1: missing column '" + wanted[k] +
                               "' (expected header t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m)");
  }
  // the motion columns (forces.csv since free bodies); older files have none
  const char* motion_names[] = {"torque_N_m_per_m", "angle_deg", "vx_m_s", "vy_m_s", "omega_rad_s"};
  int mcol[5];
  bool has_motion = true;
  for (int k = 0; k < 5; ++k) {
    mcol[k] = -1;
    for (size_t c = 0; c < header.size(); ++c)
      if (header[c] == motion_names[k]) mcol[k] = int(c);
    has_motion &= mcol[k] >= 0;
  }
  std::vector<std::string> order;
  std::map<std::string, std::vector<Sample>> bodies;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (trim(line).empty()) continue;
    const std::vector<std::string> cells = split(line);
    if (cells.size() != header.size())
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": " + std::to_string(cells.size()) +
                               " values, header has " + std::to_string(header.size()));
    // a cell of a number column, or an error naming the file, line and column
    const auto number = [&](int column, const std::string& name) {
      const std::string& c = cells[size_t(column)];
      char* end = nullptr;
      const double x = std::strtod(c.c_str(), &end);
      if (c.empty() || *end != '\0' || !std::isfinite(x))
        throw std::runtime_error(path + ":" + std::to_string(line_no) + ": column '" + name +
                                 "' must be a finite number, got '" + c + "'");
      return x;
    };
    double v[6] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < 6; ++k)
      if (k != 1) v[k] = number(col[k], wanted[k]);
    double m[5] = {0, 0, 0, 0, 0};
    for (int k = 0; k < 5 && has_motion; ++k) m[k] = number(mcol[k], motion_names[k]);
    const std::string& name = cells[size_t(col[1])];
    if (!bodies.count(name)) order.push_back(name);
    bodies[name].push_back({v[0], v[2], v[3], v[4], v[5], m[0], m[1], m[2], m[3], m[4]});
  }

  ForcePanel panel;
  bool any_moves = false;
  for (const auto& [name, s] : bodies)
    any_moves |= std::hypot(s.back().x - s.front().x, s.back().y - s.front().y) > 1e-9;
  if (!any_moves) {
    panel.x_label = "time (s)";
    panel.y_label = "force magnitude (N/m)";
  }
  for (const std::string& name : order) {
    const std::vector<Sample>& s = bodies[name];
    ForceSeries out;
    out.label = name;
    const double tx = s.back().x - s.front().x, ty = s.back().y - s.front().y, travel = std::hypot(tx, ty);
    for (const Sample& q : s) {
      out.t_s.push_back(q.t);
      if (!any_moves) {
        out.x.push_back(q.t);
        out.y.push_back(std::hypot(q.fx, q.fy));
      } else {
        out.x.push_back(1e3 * std::hypot(q.x - s.front().x, q.y - s.front().y));
        out.y.push_back(travel > 1e-9 ? -(q.fx * tx + q.fy * ty) / travel : std::hypot(q.fx, q.fy));
      }
    }
    panel.series.push_back(std::move(out));
  }
  if (has_motion) panel.rows = motion_rows(order, bodies, scene_dofs(path));
  return panel;
}

ForcePanel with_running_mean(const ForcePanel& panel, double window, const std::string& window_text) {
  if (!(window > 0) || panel.x_label.rfind("displacement", 0) != 0) return panel;
  ForcePanel out = panel;
  out.series.clear();
  for (const ForceSeries& raw : panel.series) {
    ForceSeries mean = raw;
    const size_t n = std::min(raw.x.size(), raw.y.size());
    // travel only grows along a body's straight path: a sliding window of +-window/2 with sums
    std::vector<double> sum(n + 1, 0.0);
    for (size_t k = 0; k < n; ++k) sum[k + 1] = sum[k] + raw.y[k];
    size_t lo = 0, hi = 0;
    for (size_t k = 0; k < n; ++k) {
      while (lo < k && raw.x[lo] < raw.x[k] - 0.5 * window) ++lo;
      if (hi < k + 1) hi = k + 1;
      while (hi < n && raw.x[hi] <= raw.x[k] + 0.5 * window) ++hi;
      mean.y[k] = (sum[hi] - sum[lo]) / double(hi - lo);
    }
    ForceSeries faint = raw;
    faint.faint = true;
    out.series.push_back(faint);
    out.series.push_back(mean);
  }
  out.title = panel.title + "\n(line: mean over " + window_text + "; faint: raw)";
  return out;
}

}  // namespace furrow::render
