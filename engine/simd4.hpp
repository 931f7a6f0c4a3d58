// Four doubles at a time (GCC vector extensions, AVX intrinsics) for the hot paths of P2G, G2P and
// the constitutive update. Internal to the engine's step files. In an unnamed namespace, as when they
// lived in one file: each file has its own copy, inlined as before (results are compared to the bit).
#pragma once

#include <cstddef>
#include <cstring>
#include <immintrin.h>
#include <type_traits>

#include "engine/simulation.hpp"

namespace furrow {
namespace {

// P2G and G2P move a node's fields four at a time (GCC vector extensions): m, vx, vy, vx0 and
// vx, vy, vx0, vy0 must be consecutive doubles.
static_assert(sizeof(GridNode) == 5 * sizeof(double) && offsetof(GridNode, vx) == sizeof(double) &&
                  offsetof(GridNode, vy0) == 4 * sizeof(double),
              "GridNode's fields are read four at a time");
typedef double Vec4d __attribute__((vector_size(32)));
// A node's four consecutive doubles read or written in place. GCC gives a vector type its
// element's alias set, so unlike memcpy (or the intrinsics' may_alias types) these accesses
// do not make the compiler reload every pointer and size around them (-20% P2G instructions).
typedef double Vec4dU __attribute__((vector_size(32), aligned(8)));
inline Vec4dU& four_at(double* first) { return *reinterpret_cast<Vec4dU*>(first); }
inline const Vec4dU& four_at(const double* first) { return *reinterpret_cast<const Vec4dU*>(first); }

// a * b + c rounded once (lane by lane), where the machine has FMA. Written out where two paths'
// sums must agree to the bit: left to the compiler, which product of `x * y + z * w` it fuses can
// change with the code around it. Without FMA, unfused (a library fma would be slow).
inline Vec4d fma4(const Vec4d& a, const Vec4d& b, const Vec4d& c) {
#if defined(__FMA__)
  return (Vec4d)_mm256_fmadd_pd((__m256d)a, (__m256d)b, (__m256d)c);
#else
  return a * b + c;
#endif
}
inline Vec4d splat(double v) { return Vec4d{v, v, v, v}; }
#if defined(__AVX__)
inline Vec4d lane(const Vec4d& v, int l) { return (Vec4d)_mm256_broadcast_sd(&v[l]); }  // v[l] in every lane
#endif

#if defined(__AVX__)
typedef float Vec4f __attribute__((vector_size(16)));
// Four consecutive values as doubles, and back (a float array rounds each once, as a scalar store).
template <class T> inline Vec4d load4(const T* a) {
  if constexpr (std::is_same_v<T, float>) {
    return (Vec4d)_mm256_cvtps_pd(_mm_loadu_ps(a));  // one instruction; GCC splits __builtin_convertvector in two
  } else {
    Vec4d v;
    std::memcpy(&v, a, sizeof v);
    return v;
  }
}
template <class T> inline void store4(T* a, const Vec4d& v) {
  if constexpr (std::is_same_v<T, float>) {
    const Vec4f f = __builtin_convertvector(v, Vec4f);
    std::memcpy(a, &f, sizeof f);
  } else {
    std::memcpy(a, &v, sizeof v);
  }
}

// QuadraticKernel::weights for four points, a point per lane (the same arithmetic, the same bits);
// returns the first node's index as doubles and fills `base` with it as ints
inline Vec4d quadratic_weights_by_four(const Vec4d& x_m, double inv_dx, Vec4d w[3], int base[4]) {
  const Vec4d xg = x_m * inv_dx;
  const Vec4d b = (Vec4d)_mm256_floor_pd((__m256d)(xg - 0.5));
  const Vec4d f = xg - b;
  w[0] = 0.5 * (1.5 - f) * (1.5 - f);
  w[1] = 0.75 - (f - 1.0) * (f - 1.0);
  w[2] = 0.5 * (f - 0.5) * (f - 0.5);
  for (int l = 0; l < 4; ++l) base[l] = int(b[l]);
  return b;
}
#endif

}  // namespace
}  // namespace furrow
