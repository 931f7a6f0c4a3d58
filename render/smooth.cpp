#include "render/smooth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace furrow::render {

std::vector<float> upsample_within_material(const std::vector<float>& values, int nx, int ny, int factor, bool log) {
  if (nx <= 0 || ny <= 0 || values.size() != size_t(nx) * size_t(ny))
    throw std::invalid_argument("smoothing: " + std::to_string(values.size()) + " values for a " + std::to_string(nx) +
                                "x" + std::to_string(ny) + " grid");
  if (factor < 1) throw std::invalid_argument("smoothing factor must be >= 1, got " + std::to_string(factor));
  if (factor == 1) return values;
  std::vector<float> v = values;
  if (log)
    for (float& x : v)
      if (!std::isnan(x)) x = std::log10(x);
  const int fx = nx * factor, fy = ny * factor;
  std::vector<float> out(size_t(fx) * size_t(fy), std::numeric_limits<float>::quiet_NaN());
  auto at = [&](int i, int j) { return v[size_t(std::clamp(j, 0, ny - 1)) * size_t(nx) + size_t(std::clamp(i, 0, nx - 1))]; };
  for (int J = 0; J < fy; ++J)
    for (int I = 0; I < fx; ++I) {
      // position in cell-centre coordinates (centre of cell i at i)
      const double x = (I + 0.5) / factor - 0.5, y = (J + 0.5) / factor - 0.5;
      const int i0 = int(std::floor(x)), j0 = int(std::floor(y));
      const double tx = x - i0, ty = y - j0;
      double sum = 0, weight = 0;
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) {
          const float c = at(i0 + a, j0 + b);
          if (std::isnan(c)) continue;
          const double w = (a ? tx : 1 - tx) * (b ? ty : 1 - ty);
          sum += w * c, weight += w;
        }
      // the surface where the blended material indicator crosses one half: within half a cell
      // of the cells' outline, and without its staircase
      if (!(weight >= 0.5)) continue;
      out[size_t(J) * size_t(fx) + size_t(I)] = float(log ? std::pow(10.0, sum / weight) : sum / weight);
    }
  return out;
}

}  // namespace furrow::render
