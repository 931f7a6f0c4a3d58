#include "render/point_splat.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace furrow::render {

std::string points_path_for(const std::string& frame_path) {
  const std::filesystem::path p(frame_path);
  std::string name = p.filename().string();
  if (name.rfind("frame_", 0) == 0) name = "points_" + name.substr(6);
  return (p.parent_path() / name).string();
}

FieldFrame splat_points(const PointFrame& pts, const FieldFrame& grid, int sub, const std::vector<std::string>& fields,
                        const std::string& source) {
  if (sub < 1) throw std::invalid_argument("splat_points: sub must be >= 1");
  FieldFrame f;
  f.scene_name = pts.scene_name;
  f.step = pts.step;
  f.time_s = pts.time_s, f.dt_s = pts.dt_s;
  f.dx_m = grid.dx_m / sub;
  f.origin_m = grid.origin_m;
  f.nx = grid.nx * sub, f.ny = grid.ny * sub;
  f.bodies = pts.bodies;
  const size_t n = size_t(f.nx) * size_t(f.ny);
  f.active.assign(n, 0);
  // the point arrays each field reads (velocity: both components)
  std::vector<std::pair<std::vector<float>*, const std::vector<float>*>> copies;
  for (const auto& name : fields) {
    if (name == "velocity" || name == "velocity_x" || name == "velocity_y") {
      if (f.velocity_x.empty()) {
        f.velocity_x.assign(n, 0.f), f.velocity_y.assign(n, 0.f);
        copies.push_back({&f.velocity_x, &pts.vx_m_s});
        copies.push_back({&f.velocity_y, &pts.vy_m_s});
      }
      continue;
    }
    const std::vector<float>* src = name == "pressure"           ? &pts.pressure_Pa
                                    : name == "strain_rate"      ? &pts.strain_rate_1_s
                                    : name == "plastic_strain"   ? &pts.plastic_strain
                                    : name == "packing_fraction" ? &pts.packing_fraction
                                    : name == "phi_d"            ? &pts.phi_d
                                                                 : nullptr;
    if (!src || src->size() != pts.size())
      throw std::runtime_error(source + ": the points hold no '" + name +
                               "' (points files hold velocity, pressure, packing_fraction, strain_rate, "
                               "plastic_strain and, for DPM, phi_d)");
    auto& out = f.scalars[name];
    out.assign(n, 0.f);
    copies.push_back({&out, src});
  }
  const double inv_h = 1.0 / f.dx_m;
  for (size_t k = 0; k < pts.size(); ++k) {
    const double r = std::sqrt(std::max(0.0, double(pts.volume_m2[k])) / M_PI) * inv_h;  // in texels
    const double cx = (pts.x_m[k] - f.origin_m.x()) * inv_h, cy = (pts.y_m[k] - f.origin_m.y()) * inv_h;
    if (!std::isfinite(cx) || !std::isfinite(cy)) continue;
    // texels whose centre lies in the disc, at least the one under the point
    const int i0 = std::max(0, int(std::floor(cx - r))), i1 = std::min(f.nx - 1, int(std::floor(cx + r)));
    const int j0 = std::max(0, int(std::floor(cy - r))), j1 = std::min(f.ny - 1, int(std::floor(cy + r)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const double ex = i + 0.5 - cx, ey = j + 0.5 - cy;
        const bool under = i == int(std::floor(cx)) && j == int(std::floor(cy));
        if (ex * ex + ey * ey > r * r && !under) continue;
        const size_t c = f.index(i, j);
        f.active[c] = 1;
        for (auto& [dst, src] : copies) (*dst)[c] = (*src)[k];
      }
  }
  return f;
}

}  // namespace furrow::render
