#include "render/force_series.hpp"

#include <algorithm>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

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
};
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
    double v[6] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < 6; ++k) {
      if (k == 1) continue;
      const std::string& s = cells[size_t(col[k])];
      char* end = nullptr;
      v[k] = std::strtod(s.c_str(), &end);
      if (s.empty() || *end != '\0' || !std::isfinite(v[k]))
        throw std::runtime_error(path + ":" + std::to_string(line_no) + ": column '" + wanted[k] +
                                 "' must be a finite number, got '" + s + "'");
    }
    const std::string& name = cells[size_t(col[1])];
    if (!bodies.count(name)) order.push_back(name);
    bodies[name].push_back({v[0], v[2], v[3], v[4], v[5]});
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
