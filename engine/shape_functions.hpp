// B-spline shape functions on a uniform grid. Each kernel fills per-axis weights for the N nodes
// starting at `base`, and per-axis derivatives d w / d x_particle (1/m). MLS kernels (quadratic, cubic) also
// give the constant inertia-tensor inverse D^-1 used by APIC/MLS transfers.
#pragma once
#include <cmath>

#include "engine/scene/scene.hpp"

namespace furrow {

struct LinearKernel {
  static constexpr int N = 1 + 1;
  static constexpr bool mls = false;  // APIC D is singular at nodes: use true gradients
  // the first of the N node columns (or rows) a point at xg (in cells) reaches
  static inline int base(double xg) { return int(std::floor(xg)); }
  static inline int weights(double xg, double w[N], double dw[N], double inv_dx) {
    const int b = base(xg);
    const double f = xg - b;
    w[0] = 1.0 - f;
    w[1] = f;
    dw[0] = -inv_dx;
    dw[1] = inv_dx;
    return b;
  }
  static double inv_D(double inv_dx) { return 0.0; }
};

struct QuadraticKernel {
  static constexpr int N = 3;
  static constexpr bool mls = true;
  static inline int base(double xg) { return int(std::floor(xg - 0.5)); }
  static inline int weights(double xg, double w[N], double dw[N], double inv_dx) {
    const int b = base(xg);
    const double f = xg - b;  // in [0.5, 1.5)
    w[0] = 0.5 * (1.5 - f) * (1.5 - f);
    w[1] = 0.75 - (f - 1.0) * (f - 1.0);
    w[2] = 0.5 * (f - 0.5) * (f - 0.5);
    dw[0] = (f - 1.5) * inv_dx;
    dw[1] = -2.0 * (f - 1.0) * inv_dx;
    dw[2] = (f - 0.5) * inv_dx;
    return b;
  }
  static double inv_D(double inv_dx) { return 4.0 * inv_dx * inv_dx; }
};

struct CubicKernel {
  static constexpr int N = 4;
  static constexpr bool mls = true;
  static inline int base(double xg) { return int(std::floor(xg)) - 1; }
  static inline int weights(double xg, double w[N], double dw[N], double inv_dx) {
    const int b = base(xg);
    const double f = xg - b;  // in [1, 2)
    for (int k = 0; k < N; ++k) {
      const double d = f - k;  // particle minus node, in cells
      const double a = std::fabs(d), s = d >= 0 ? 1.0 : -1.0;
      if (a < 1.0) {
        w[k] = 0.5 * a * a * a - a * a + 2.0 / 3.0;
        dw[k] = s * (1.5 * a * a - 2.0 * a) * inv_dx;
      } else if (a < 2.0) {
        const double b = 2.0 - a;
        w[k] = b * b * b / 6.0;
        dw[k] = -s * 0.5 * b * b * inv_dx;
      } else {
        w[k] = 0.0;
        dw[k] = 0.0;
      }
    }
    return b;
  }
  static double inv_D(double inv_dx) { return 3.0 * inv_dx * inv_dx; }
};

}  // namespace furrow
