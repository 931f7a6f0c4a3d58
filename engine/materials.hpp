// Rate-independent granular plasticity (paper section 2), one update per material point.
//
// Elasticity is split: pressure follows the volumetric strain measured from the dense state,
// P = K ln(phi / phi_d) (so the open/dense switch of the model is exactly P <= 0), and the
// deviatoric stress s is hypoelastic with a Jaumann rate. Plastic flow is a closed-form return:
// open material (phi < phi_d) carries no stress; otherwise s is scaled back onto tau = mu P.
// Plane strain: in-plane kinematics, but s_zz is carried.
// With effects.rate_dependence the friction is mu(I) = mu + (mu_2 - mu) I / (I0 + I), and the
// return is implicit in the rate: the plastic increment solves tau_trial - G dgamma = mu(I) P with
// I evaluated at dgamma / dt, a quadratic with one positive root for any rate and any P >= 0.
#pragma once
#include <algorithm>
#include <cmath>

#include "engine/scene/scene.hpp"

namespace furrow {

struct MaterialParams {
  double rho_g = 2520.0;  // grain density (kg/m^3)
  double phi_c = 0.60;
  double mu = 0.40;        // mu_s (NDPM) or mu_c (DPM)
  double chi = 0.0;
  double phi_min = 0.45;
  double K = 0.0, G = 0.0;  // bulk and shear moduli (Pa)
  bool separation = true;   // effects.separation: stress-free when open
  double dmu = 0.0;         // mu_2 - mu: what the rate can add to the friction
  double I0 = 0.279;
  double d_m = 0.53e-3;     // grain diameter

  static MaterialParams from(const Material& m, bool separation) {
    MaterialParams p;
    p.rho_g = m.grain_density_kg_m3;
    p.phi_c = m.phi_c;
    p.mu = m.mu;
    p.chi = m.model == MaterialModel::DPM ? m.chi : 0.0;
    p.phi_min = m.phi_min;
    p.K = m.youngs_modulus_Pa / (3.0 * (1.0 - 2.0 * m.poisson_ratio));
    p.G = m.youngs_modulus_Pa / (2.0 * (1.0 + m.poisson_ratio));
    p.separation = separation;
    p.dmu = m.mu_2 - m.mu;
    p.I0 = m.inertial_I0;
    p.d_m = m.grain_diameter_m;
    return p;
  }
  // friction at dense-state packing phi_d; never negative
  double friction(double phi_d) const { return std::max(0.0, mu + (phi_d - phi_c) * chi); }
};

// Everything the constitutive law reads and writes for one material point.
struct PointState {
  double volume_m2;          // current area per metre out of plane
  double sxx, syy, sxy, szz; // deviatoric Cauchy stress (Pa)
  double pressure_Pa;        // P = -tr(sigma)/3
  double phi_d;              // dense-state packing (DPM); phi_c for NDPM
  double plastic_strain;     // accumulated equivalent plastic shear strain
  double strain_rate_1_s;    // equivalent plastic shear rate of this step
};

// The plastic shear increment of the mu(I) return: tau_trial - G x = P (mu_s + dmu I / (I0 + I)),
// I = x d / (dt sqrt(P / rho_g)). With m = dt sqrt(P / rho_g) / d (so I = x / m) it is the quadratic
//   G x^2 + (G I0 m + P dmu - A) x - A I0 m = 0,   A = tau_trial - mu_s P > 0,
// whose positive root is taken in the form that does not cancel: at P -> 0 (m = 0) it tends to
// (A - P dmu) / G, the rate-independent return at mu_2, so large rates and small pressures are safe.
inline double rate_dependent_increment(double tau_trial, double P, double mu_s, double dt, const MaterialParams& p,
                                       double* rate_part) {
  const double A = tau_trial - mu_s * P;
  const double m = dt * std::sqrt(P / p.rho_g) / p.d_m;
  const double b = p.G * p.I0 * m + P * p.dmu - A;
  const double disc = std::sqrt(b * b + 4.0 * p.G * A * p.I0 * m);
  const double x = b >= 0.0 ? 2.0 * A * p.I0 * m / (b + disc) : (disc - b) / (2.0 * p.G);
  *rate_part = x > 0.0 ? p.dmu * x / (p.I0 * m + x) : 0.0;  // dmu I / (I0 + I)
  return x;
}

// a * b + c rounded once where the machine has FMA (else unfused: a library fma would be slow).
// Written out where a scalar and a four-wide path must agree to the bit: left to the compiler,
// which product of `x * y + z * w` it fuses can change with the code around it.
inline double fma1(double a, double b, double c) {
#if defined(__FMA__)
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

// ln(q) for q = phi / phi_d, the elastic volume strain: |q - 1| ~ 1e-4 near the surface, ~2e-3
// under 0.6 m of sand at E 5 MPa, rarely beyond 0.1. There ln q = 2 atanh(y), y = x / (2 + x),
// x = q - 1 (exact for q in [0.5, 2]); |y| <= 0.053, so the odd series to y^13 is exact to 1e-19
// and the result to about an ulp (tested). Cheaper than the library log (the update's instructions
// -35% on plate_intrusion, engine/README.md), and the same operations in every lane of the four-wide update
// (constitutive.cpp), which must give the same bits.
// T is double, or a GCC vector of doubles (one lane per point) with its own `fma`.
constexpr double kLogSeriesReach = 0.1;
template <class T, class Fma> inline T log_series(const T& x, Fma fma) {
  const T zero{};  // zero + c: c itself, or c in every lane
  const T y = x / (2.0 + x), y2 = y * y;
  T s = fma(y2, zero + 1.0 / 13.0, zero + 1.0 / 11.0);
  s = fma(s, y2, zero + 1.0 / 9.0);
  s = fma(s, y2, zero + 1.0 / 7.0);
  s = fma(s, y2, zero + 1.0 / 5.0);
  s = fma(s, y2, zero + 1.0 / 3.0);
  return fma(2.0 * y, y2 * s, 2.0 * y);
}
inline double log_near_one(double q) {
  const double x = q - 1.0;
  return std::abs(x) <= kLogSeriesReach ? log_series(x, fma1) : std::log(q);
}

// Shared by both models; Dilatancy selects the DPM state law and Rate the mu(I) friction at
// compile time, so a run carries no per-particle branch or state for an effect it does not use.
template <bool Dilatancy, bool Rate = false>
struct PlasticityModel {
  MaterialParams p;

  // L: velocity gradient (row-major 2x2: dvx/dx, dvx/dy, dvy/dx, dvy/dy), mass in kg per metre.
  inline void update(double dt, double L00, double L01, double L10, double L11, double mass,
                     PointState& s) const {
    // kinematics: log volume strain advances by dt tr(D) (plane strain: D_zz = 0); unlike
    // det(I + dt L) this is exactly 1 under rigid spin, so rotation never changes pressure
    const double e = dt * (L00 + L11);  // |e| << 1 under the CFL bound: a cubic is exp to round-off
    s.volume_m2 *= std::abs(e) < 1e-3 ? 1.0 + e * (1.0 + e * (0.5 + e / 6.0)) : std::exp(e);
    const double phi = mass / (p.rho_g * s.volume_m2);
    double phi_d = Dilatancy ? s.phi_d : p.phi_c;

    if (p.separation && phi < phi_d) {
      // open: stress-free; DPM forgets compaction below phi_min
      if (Dilatancy && phi < p.phi_min) s.phi_d = p.phi_min;
      s.sxx = s.syy = s.sxy = s.szz = 0.0;
      s.pressure_Pa = 0.0;
      s.strain_rate_1_s = 0.0;
      return;
    }

    // elastic trial: Jaumann-rotated deviator plus 2G dev(D)
    const double trD = L00 + L11;
    const double Dxy = 0.5 * (L01 + L10), w = 0.5 * (L01 - L10);
    const double sxx = s.sxx, syy = s.syy, sxy = s.sxy;
    s.sxx = sxx + dt * (2.0 * p.G * (L00 - trD / 3.0) + 2.0 * w * sxy);
    s.syy = syy + dt * (2.0 * p.G * (L11 - trD / 3.0) - 2.0 * w * sxy);
    s.sxy = sxy + dt * (2.0 * p.G * Dxy + w * (syy - sxx));
    s.szz = s.szz + dt * (2.0 * p.G * (-trD / 3.0));
    // keep the deviator traceless against round-off drift
    const double tr3 = (s.sxx + s.syy + s.szz) / 3.0;
    s.sxx -= tr3;
    s.syy -= tr3;
    s.szz -= tr3;

    double P = p.K * log_near_one(phi / phi_d);
    const double tau = std::sqrt(0.5 * (s.sxx * s.sxx + s.syy * s.syy + s.szz * s.szz) + s.sxy * s.sxy);
    double tau_max = p.friction(phi_d) * std::max(P, 0.0);
    if (tau <= tau_max) {
      s.pressure_Pa = P;
      s.strain_rate_1_s = 0.0;
      return;
    }
    // plastic: equivalent shear strain increment from the overshoot (tau = G * gamma)
    double rate_part = 0.0;
    const double dgamma = Rate ? rate_dependent_increment(tau, std::max(P, 0.0), p.friction(phi_d), dt, p, &rate_part)
                               : (tau - tau_max) / p.G;
    // from the friction, not tau - G dgamma: at high rates tau_trial >> tau and the difference cancels
    if constexpr (Rate) tau_max = (p.friction(phi_d) + rate_part) * std::max(P, 0.0);
    if (Dilatancy) {
      // d phi_d / d gamma = -chi phi_c (phi_d - phi_c): exact relaxation over the increment,
      // monotone toward phi_c from either side
      phi_d = p.phi_c + (phi_d - p.phi_c) * std::exp(-p.chi * p.phi_c * dgamma);
      s.phi_d = phi_d;
      P = p.K * log_near_one(phi / phi_d);
      tau_max = (p.friction(phi_d) + rate_part) * std::max(P, 0.0);
    }
    const double scale = tau > 0.0 ? tau_max / tau : 0.0;
    s.sxx *= scale;
    s.syy *= scale;
    s.sxy *= scale;
    s.szz *= scale;
    s.pressure_Pa = P;
    s.plastic_strain += dgamma;
    s.strain_rate_1_s = dgamma / dt;
  }
};

using NdpmModel = PlasticityModel<false>;
using DpmModel = PlasticityModel<true>;

}  // namespace furrow
