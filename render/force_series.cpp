#include "render/force_series.hpp"

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

}  // namespace furrow::render
