// The constitutive update (the laws are in materials.hpp): four points at a time where it can, else
// a point at a time through PlasticityModel::update.
#include <cmath>
#include <cstddef>
#include <immintrin.h>
#include <vector>

#include "engine/materials.hpp"
#include "engine/simd4.hpp"
#include "engine/simulation.hpp"

namespace furrow {

// The rate-independent update (PlasticityModel<Dilatancy>::update) four points at a time, a point
// per lane: the same operations in the same order, the branches as lane selects (the same bits,
// tested). A group whose points are of different materials, or a lane whose volume strain needs the
// library's exp (1e-3 in a step), goes through update() instead; the library's log (pressure away
// from the dense state) and DPM's exp (the packing's relaxation in a yielding lane) are called per
// lane, as update() calls them. Returns `end`, or where constitutive_range's loop must take over
// when built without AVX.
template <bool Dilatancy, bool Track>
size_t Simulation::constitutive_by_four(size_t begin, size_t end) {
#if !defined(__AVX__)
  return begin;
#else
  using V = Vec4d;
  typedef long long M __attribute__((vector_size(32)));  // a lane mask
  const double dt = dt_s_;
  auto& P = p_;
  auto pick = [](const M& m, const V& yes, const V& no) { return m ? yes : no; };
  const V zero = {0, 0, 0, 0};
  auto scalar = [&](size_t q) { constitutive_point<Dilatancy, Track, false>(q, {materials_[P.material[q]]}); };
  size_t p = begin;
  for (; p + 4 <= end; p += 4) {
    const uint8_t mat = P.material[p];
    if (P.material[p + 1] != mat || P.material[p + 2] != mat || P.material[p + 3] != mat) {
      for (size_t q = p; q < p + 4; ++q) scalar(q);
      continue;
    }
    const MaterialParams& mp = materials_[mat];
    const V L00 = load4(P.c00.data() + p), L01 = load4(P.c01.data() + p), L10 = load4(P.c10.data() + p),
            L11 = load4(P.c11.data() + p);
    // kinematics (see update): the cubic for |e| < 1e-3, else the library's exp
    const V e = dt * (L00 + L11);
    const M small_e = (e < 1e-3) & (e > -1e-3);
    V volume = load4(P.volume.data() + p) * (1.0 + e * (1.0 + e * (0.5 + e / 6.0)));
    if (!(small_e[0] && small_e[1] && small_e[2] && small_e[3])) {
      for (size_t q = p; q < p + 4; ++q) scalar(q);
      continue;
    }
    const V phi = load4(P.mass.data() + p) / (mp.rho_g * volume);
    const V phi_d = Dilatancy ? load4(P.phi_d.data() + p) : zero + mp.phi_c;
    const M open = mp.separation ? M(phi < phi_d) : M{0, 0, 0, 0};
    // MaterialParams::friction: std::max(0.0, mu + (phi_d - phi_c) chi)
    auto friction = [&](const V& pd) {
      if constexpr (!Dilatancy) return zero + mp.friction(mp.phi_c);
      const V f = mp.mu + (pd - mp.phi_c) * mp.chi;
      return pick(zero < f, f, zero);
    };
    // P = K log_near_one(phi / phi_d): log_series in every lane where |q - 1| is in its reach,
    // else the library's log (the lanes in `needed`; the others keep whatever the series gives)
    auto pressure_of = [&](const V& pd, const M& needed) {
      const V q = phi / pd, x = q - 1.0;
      const M series = (x <= kLogSeriesReach) & (x >= -kLogSeriesReach);
      V pressure = mp.K * log_series(x, [](const V& a, const V& b, const V& c) { return fma4(a, b, c); });
      for (int l = 0; l < 4; ++l)
        if (!series[l] && needed[l]) pressure[l] = mp.K * std::log(q[l]);
      return pressure;
    };
    auto positive = [&](const V& v) { return pick(v < 0.0, zero, v); };  // std::max(v, 0.0), -0 kept
    // elastic trial
    const V trD = L00 + L11;
    const V Dxy = 0.5 * (L01 + L10), w = 0.5 * (L01 - L10);
    const V sxx = load4(P.sxx.data() + p), syy = load4(P.syy.data() + p), sxy = load4(P.sxy.data() + p);
    V txx = sxx + dt * (2.0 * mp.G * (L00 - trD / 3.0) + 2.0 * w * sxy);
    V tyy = syy + dt * (2.0 * mp.G * (L11 - trD / 3.0) - 2.0 * w * sxy);
    V txy = sxy + dt * (2.0 * mp.G * Dxy + w * (syy - sxx));
    V tzz = load4(P.szz.data() + p) + dt * (2.0 * mp.G * (-trD / 3.0));
    const V tr3 = (txx + tyy + tzz) / 3.0;
    txx -= tr3;
    tyy -= tr3;
    tzz -= tr3;
    V pressure = pressure_of(phi_d, ~open);
    const V tau = (V)_mm256_sqrt_pd((__m256d)(0.5 * (txx * txx + tyy * tyy + tzz * tzz) + txy * txy));
    V tau_max = friction(phi_d) * positive(pressure);
    const M plastic = ~(tau <= tau_max);
    const V dgamma = (tau - tau_max) / mp.G;
    const M flows = plastic & ~open;
    if constexpr (Dilatancy) {
      // the yielding lanes relax phi_d toward phi_c and take the pressure and friction it gives
      V relaxed = phi_d;
      bool any = false;
      for (int l = 0; l < 4; ++l)
        if (flows[l]) relaxed[l] = mp.phi_c + (phi_d[l] - mp.phi_c) * std::exp(-mp.chi * mp.phi_c * dgamma[l]), any = true;
      if (any) {
        const V relaxed_pressure = pressure_of(relaxed, flows);
        pressure = pick(flows, relaxed_pressure, pressure);
        tau_max = pick(flows, (friction(relaxed) + 0.0) * positive(relaxed_pressure), tau_max);
      }
      // open: stress-free, and compaction below phi_min forgotten
      const V forgotten = pick(phi < mp.phi_min, zero + mp.phi_min, phi_d);
      store4(P.phi_d.data() + p, pick(open, forgotten, relaxed));
    }
    const V scale = pick(tau > 0.0, tau_max / tau, zero);
    auto out = [&](const V& trial) { return pick(open, zero, pick(plastic, trial * scale, trial)); };
    store4(P.volume.data() + p, volume);
    store4(P.sxx.data() + p, out(txx));
    store4(P.syy.data() + p, out(tyy));
    store4(P.sxy.data() + p, out(txy));
    store4(P.szz.data() + p, out(tzz));
    store4(P.pressure.data() + p, pick(open, zero, pressure));
    if constexpr (Track) {
      const V ps = load4(P.plastic_strain.data() + p);
      store4(P.plastic_strain.data() + p, pick(flows, ps + dgamma, ps));
      store4(P.strain_rate.data() + p, pick(flows, dgamma / dt, zero));
    }
  }
  return p;
#endif
}

// One point's update: PlasticityModel::update on its stored state.
template <bool Dilatancy, bool Track, bool Rate>
void Simulation::constitutive_point(size_t p, const PlasticityModel<Dilatancy, Rate>& model) {
  auto& P = p_;
  PointState s{P.volume[p], P.sxx[p], P.syy[p], P.sxy[p], P.szz[p], P.pressure[p],
               Dilatancy ? P.phi_d[p] : 0.0, Track ? P.plastic_strain[p] : 0.0, 0.0};
  model.update(dt_s_, P.c00[p], P.c01[p], P.c10[p], P.c11[p], P.mass[p], s);
  P.volume[p] = s.volume_m2;
  P.sxx[p] = s.sxx;
  P.syy[p] = s.syy;
  P.sxy[p] = s.sxy;
  P.szz[p] = s.szz;
  P.pressure[p] = s.pressure_Pa;
  if constexpr (Dilatancy) P.phi_d[p] = s.phi_d;
  if constexpr (Track) {
    P.plastic_strain[p] = s.plastic_strain;
    P.strain_rate[p] = s.strain_rate_1_s;
  }
}

template <bool Dilatancy, bool Track, bool Rate>
void Simulation::constitutive_range(size_t begin, size_t end) {
  if constexpr (!Rate)
    if (by_four_) begin = constitutive_by_four<Dilatancy, Track>(begin, end);
  if (begin == end) return;  // the four-wide pass took every point: no models to build (a heap allocation per block)
  std::vector<PlasticityModel<Dilatancy, Rate>> models;
  for (const auto& m : materials_) models.push_back({m});
  for (size_t p = begin; p < end; ++p) constitutive_point<Dilatancy, Track, Rate>(p, models[p_.material[p]]);
}

// the instances Simulation's constructor picks from
template void Simulation::constitutive_range<true, true, true>(size_t, size_t);
template void Simulation::constitutive_range<true, true, false>(size_t, size_t);
template void Simulation::constitutive_range<true, false, true>(size_t, size_t);
template void Simulation::constitutive_range<true, false, false>(size_t, size_t);
template void Simulation::constitutive_range<false, true, true>(size_t, size_t);
template void Simulation::constitutive_range<false, true, false>(size_t, size_t);
template void Simulation::constitutive_range<false, false, true>(size_t, size_t);
template void Simulation::constitutive_range<false, false, false>(size_t, size_t);

}  // namespace furrow
