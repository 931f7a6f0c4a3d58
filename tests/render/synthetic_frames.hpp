// Synthetic FieldFrames with known fields, for renderer tests and benchmarks.
#pragma once
#include <cmath>

#include "engine/fields.hpp"

namespace furrow::test {

constexpr double kRhoBulk_kg_m3 = 1512.0;  // 2520 * 0.6
constexpr double kG_m_s2 = 9.81;

// A bed of nx x ny cells of size dx, filled with material below `surface_m` (height above the
// bottom), hydrostatic pressure rho g depth, strain rate 10^(4 x / width - 3) (so log10 of it is
// linear in x), a plate outline at the given box, at time t.
inline FieldFrame hydrostatic_frame(int nx, int ny, double dx, double surface_m, double time_s = 0.123) {
  FieldFrame f;
  f.scene_name = "hydrostatic";
  f.step = 42;
  f.time_s = time_s;
  f.dt_s = 1e-5;
  f.dx_m = dx;
  f.origin_m = {0.0, 0.0};
  f.nx = nx, f.ny = ny;
  const size_t n = size_t(nx) * size_t(ny);
  f.active.assign(n, 0);
  auto& p = f.scalars["pressure"];
  auto& sr = f.scalars["strain_rate"];
  p.assign(n, 0.f);
  sr.assign(n, 0.f);
  f.velocity_x.assign(n, 0.f);
  f.velocity_y.assign(n, 0.f);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double y = (j + 0.5) * dx, x = (i + 0.5) * dx;
      if (y > surface_m) continue;
      const size_t k = f.index(i, j);
      f.active[k] = 1;
      p[k] = float(kRhoBulk_kg_m3 * kG_m_s2 * (surface_m - y));
      sr[k] = float(std::pow(10.0, 4.0 * x / (nx * dx) - 3.0));
      f.velocity_x[k] = 0.03f;
      f.velocity_y[k] = -0.04f;
    }
  return f;
}

inline BodyOutline box_body(const std::string& name, double x0, double y0, double x1, double y1) {
  BodyOutline b;
  b.name = name;
  b.outline_m = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  b.position_m = {0.5 * (x0 + x1), 0.5 * (y0 + y1)};
  b.force_N_per_m = {0.0, 120.0};
  return b;
}

}  // namespace furrow::test
