#include "engine/simulation.hpp"

#include <Eigen/Dense>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <immintrin.h>
#include <cstddef>
#include <cstring>
#include <istream>
#include <limits>
#include <ostream>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <type_traits>

#include "engine/bodies.hpp"
#include "engine/scene_io.hpp"
#include "engine/shape_functions.hpp"

namespace furrow {

namespace {

constexpr size_t kGrain = 4096;  // particles per TBB task
// grid nodes per task of the grid passes (clear, grid update): 2048 x 40 B = 80 kB, so the 34k nodes
// of the bench bed (dx 5 mm) make 17 tasks; at 16384 they made 3, two threads split them 2:1
constexpr size_t kGridGrain = 2048;
// particles G2P and the constitutive update take in turn when fused: their ~20 arrays of a block
// stay in L2 (256 points x 20 x 8 B = 40 kB). Measured alone this gains nothing (README,
// Performance); it is the shape a fused G2P + constitutive + next P2G pass would take.
constexpr size_t kFusedBlock = 256;
// cell-fraction contact: the body as its own mass field (see contact_nodes). Its sample points
// fill the body deeper than kBodyFieldInset cells, and deeper than kBodyFieldSideInset cells
// across the body's motion (its faces along the motion, which never cross node lines, need no
// smooth reach, and a field reaching past them made the body act wider: README, "Body
// contact"), kBodySamplesPerCell per cell and axis, each with kBodyDensityRatio times the bed's
// mean density. All four were chosen by measurement.
constexpr double kBodyFieldInset = 0.5;
constexpr double kBodyFieldSideInset = 1.0;
constexpr int kBodySamplesPerCell = 4;
constexpr double kBodyDensityRatio = 20.0;
// cell-fraction contact starts where a point's surface comes this close to a body, in cells (the
// onset target: nothing until the surfaces are within a quarter cell)
constexpr double kTouchCells = 0.2;

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

// P2G's sum over a run of consecutive points with the same stencil (the reorder sorts them
// together, ~4 a run): the run's points add into registers and the grid takes the sum once, not a
// read-modify-write of every node for every point. Pays only with AVX-512's 32 vector registers
// (-15% P2G time); AVX2's 16 spill the twelve sums and it breaks even (README, Performance).
template <int N> struct StencilRun {
  static_assert(N <= 4, "a stencil row's vy0 is one Vec4d");
  Vec4d four[N][N];  // node (a, b)'s [m vx vy vx0]
  Vec4d fifth[N];    // row b's vy0, node a in lane a
  GridNode* column0 = nullptr;  // the stencil's first node
  size_t NY;
  explicit StencilRun(size_t ny) : NY(ny) {}
  // the point's stencil starts at `first`: a new stencil first hands the old run to the grid
  void start(GridNode* first) __attribute__((always_inline)) {
    if (first == column0) return;
    flush();
    column0 = first;
    for (int a = 0; a < N; ++a) {
      fifth[a] = Vec4d{0, 0, 0, 0};
      for (int b = 0; b < N; ++b) four[a][b] = Vec4d{0, 0, 0, 0};
    }
  }
  void flush() __attribute__((always_inline)) {
    if (!column0) return;
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b) {
        GridNode& n = column0[size_t(a) * NY + size_t(b)];
        four_at(&n.m) += four[a][b];
        n.vy0 += fifth[b][a];
      }
  }
};

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

// P2G's strips. A point whose stencil starts at node column `base` (the kernel's) belongs, when the
// points are reordered, to strip s = floor(base / width) + 1: its nominal bases are
// [width (s - 1), width s - 1]. Until the next reorder it may stray one column either way: its
// window of bases [width (s - 1) - 1, width s] writes node columns up to width s + N - 1, which stay
// left of what strip s + 2's window writes (width (s + 1) - 1) for width > N. So strips of one
// colour never share a node, and P2G scatters a colour's strips in parallel without sorting.
template <class K> struct StripWindow {
  static constexpr int width = K::N + 1 > 4 ? K::N + 1 : 4;  // 4 node columns, 5 for cubic
  static int count(int nx) { return nx / width + 3; }
  static int of_base(int base, int strips) { return std::clamp((base + width) / width, 0, strips - 1); }  // base >= -2
  static bool holds(int strip, int base) { return unsigned(base - (width * (strip - 1) - 1)) <= unsigned(width + 1); }
#if defined(__AVX__)
  // holds() for four points at once (strips and bases as 32-bit lanes): true when all four hold
  static bool holds4(__m128i strip, __m128i base) {
    const __m128i first = _mm_sub_epi32(_mm_mullo_epi32(strip, _mm_set1_epi32(width)), _mm_set1_epi32(width + 1));
    const __m128i offset = _mm_sub_epi32(base, first), last = _mm_set1_epi32(width + 1);
    return _mm_movemask_epi8(_mm_cmpeq_epi32(_mm_max_epu32(offset, last), last)) == 0xffff;
  }
#endif
};

// The grid nodes a body's box covers, one node of margin, clipped to the padded grid. One
// function for every contact pass, so a node one pass marks is a node another pass visits.
struct NodeBox {
  int i0, i1, j0, j1;
};
inline NodeBox body_node_box(const BodyState& s, const Grid& g) {
  const double inv_dx = 1.0 / g.dx;
  const Vec2 lo = (s.position_m + s.lo_m) * inv_dx, hi = (s.position_m + s.hi_m) * inv_dx;
  return {std::max(-Grid::kPad, int(std::floor(lo.x())) - 1), std::min(g.nx + Grid::kPad, int(std::ceil(hi.x())) + 1),
          std::max(-Grid::kPad, int(std::floor(lo.y())) - 1), std::min(g.ny + Grid::kPad, int(std::ceil(hi.y())) + 1)};
}

// The first and last P2G strips whose points may lie within `reach_m` of a body's box: a strip
// either side more than the points there now, since a point may have strayed from its strip.
template <class K> inline std::pair<int, int> body_strip_span(const BodyState& s, double reach_m, double inv_dx, int strips) {
  using W = StripWindow<K>;
  const int first = W::of_base(K::base((s.position_m.x() + s.lo_m.x() - reach_m) * inv_dx), strips);
  const int last = W::of_base(K::base((s.position_m.x() + s.hi_m.x() + reach_m) * inv_dx), strips);
  return {std::max(first - 1, 0), std::min(last + 1, strips - 1)};
}

}  // namespace

Simulation::Simulation(const Scene& scene) : scene_(scene) {
  const auto& d = scene_.domain;
  if (!(d.dx_m > 0.0) || !(d.width_m > 0.0) || !(d.height_m > 0.0))
    throw std::invalid_argument("scene domain needs positive width, height and dx");
  if (scene_.materials.empty() && !scene_.beds.empty()) throw std::invalid_argument("scene has beds but no materials");
  if (scene_.materials.size() > 255) throw std::invalid_argument("at most 255 materials");
  g_.dx = d.dx_m;
  g_.nx = int(std::ceil(d.width_m / d.dx_m - 1e-9));
  g_.ny = int(std::ceil(d.height_m / d.dx_m - 1e-9));
  g_.NX = g_.nx + 1 + 2 * Grid::kPad;
  if (StripWindow<QuadraticKernel>::count(g_.nx) > 65535)  // each point's home strip is kept in 16 bits
    throw std::invalid_argument("domain too wide: at most 262,000 cells across");
  g_.NY = g_.ny + 1 + 2 * Grid::kPad;
  const size_t nodes = size_t(g_.NX) * g_.NY;
  g_.node.assign(nodes, GridNode{});

  bool any_dpm = false;
  for (const auto& m : scene_.materials) {
    materials_.push_back(MaterialParams::from(m, scene_.effects.separation));
    wave_speed_ = std::max(wave_speed_, furrow::wave_speed_m_s(m));
    any_dpm |= m.model == MaterialModel::DPM;
  }
  dilatancy_ = scene_.effects.dilatancy && any_dpm;
  gravity_ = scene_.effects.gravity ? scene_.effects.gravity_m_s2 : Vec2(0.0, 0.0);

  for (const auto& b : scene_.bodies) {
    BodyState s;
    s.position_m = b.start_m;
    s.velocity_m_s = motion_velocity_m_s(b.motion, 0.0);
    s.omega_rad_s = motion_angular_velocity_rad_s(b.motion, 0.0);
    s.turns = b.rotates();
    std::tie(s.lo_m, s.hi_m) = shape_bounds_m(b.shape);
    bodies_.push_back(s);
    if (b.dynamics.any_free() && scene_.solver.contact == ContactMethod::Particle)
      throw std::invalid_argument("body '" + b.name + "': free degrees of freedom need node or cell_fraction contact");
    // the outline's corners, for the bounds at any angle (circles: 64-gon, padded by its sagitta)
    std::vector<Vec2> corners;
    for (const auto& loop : shape_outline(b.shape, 64)) corners.insert(corners.end(), loop.begin(), loop.end());
    body_corners_m_.push_back(std::move(corners));
    set_body_angle(bodies_.size() - 1, b.start_angle_rad);
  }
  // plastic strain and its rate are kept only when a stored field or the stored points need them
  for (const auto& f : scene_.outputs.fields) track_plastic_ |= f == "strain_rate" || f == "plastic_strain";
  track_plastic_ |= scene_.outputs.points;
  seed_beds();
  if (scene_.solver.contact == ContactMethod::CellFraction) sample_body_fields();

  flip_ = scene_.solver.flip_blend > 0.0;
  auto pick = [&](auto kernel) {
    using K = decltype(kernel);
    p2g_ = flip_ ? &Simulation::particles_to_grid<K, true> : &Simulation::particles_to_grid<K, false>;
    switch (scene_.solver.contact) {
      case ContactMethod::Node: contact_ = &Simulation::contact_nodes<false>; break;
      case ContactMethod::Particle: contact_ = &Simulation::contact_particles<K>; break;
      case ContactMethod::CellFraction: contact_ = &Simulation::contact_cell_fraction<K>; break;
    }
    g2p_range_ = flip_ ? &Simulation::g2p_range<K, true> : &Simulation::g2p_range<K, false>;
    reorder_ = &Simulation::reorder_particles<K>;
    strips_hold_ = &Simulation::strips_hold_for<K>;
  };
  switch (scene_.solver.shape_function) {
    case ShapeFunction::Linear: pick(LinearKernel{}); break;
    case ShapeFunction::Quadratic: pick(QuadraticKernel{}); break;
    case ShapeFunction::Cubic: pick(CubicKernel{}); break;
  }
  auto pick_law = [&](auto rate) {
    constexpr bool R = decltype(rate)::value;
    if (dilatancy_)
      constitutive_range_ = track_plastic_ ? &Simulation::constitutive_range<true, true, R>
                                           : &Simulation::constitutive_range<true, false, R>;
    else
      constitutive_range_ = track_plastic_ ? &Simulation::constitutive_range<false, true, R>
                                           : &Simulation::constitutive_range<false, false, R>;
  };
  if (scene_.effects.rate_dependence) pick_law(std::true_type{});
  else pick_law(std::false_type{});
  const int threads = scene_.solver.threads > 0 ? scene_.solver.threads : tbb::task_arena::automatic;
  arena_ = std::make_unique<tbb::task_arena>(threads);
  (this->*reorder_)();
}

Simulation::~Simulation() = default;

void Simulation::seed_beds() {
  const int ppc = std::max(1, scene_.solver.particles_per_cell_1d);
  const double h = g_.dx / ppc, v0 = h * h;
  const double g = gravity_.norm();
  for (const auto& bed : scene_.beds) {
    const Material* mat = scene_.find_material(bed.material);
    if (!mat) throw std::invalid_argument("bed refers to unknown material '" + bed.material + "'");
    const uint8_t mi = uint8_t(mat - scene_.materials.data());
    const MaterialParams& mp = materials_[mi];
    const double phi_i = bed.packing_fraction;
    const double phi_d = dilatancy_ && mat->model == MaterialModel::DPM ? phi_i : mp.phi_c;
    const double k0 = bed.k0 >= 0.0 ? bed.k0 : 1.0 - std::sin(std::atan(mp.friction(phi_d)));
    // rounded to its stored precision first: the volume below is derived from the stored value, so
    // phi = m / (rho_g V) is the seeded packing to double round-off in either precision
    const double mass = mass_t(mp.rho_g * phi_i * v0);
    const long kx0 = long(std::floor(bed.min_m.x() / h)), kx1 = long(std::ceil(bed.max_m.x() / h));
    const long ky0 = long(std::floor(bed.min_m.y() / h)), ky1 = long(std::ceil(bed.max_m.y() / h));
    for (long ky = ky0; ky <= ky1; ++ky) {
      const double y = (ky + 0.5) * h;
      if (y < bed.min_m.y() || y >= bed.max_m.y()) continue;
      for (long kx = kx0; kx <= kx1; ++kx) {
        const double x = (kx + 0.5) * h;
        if (x < bed.min_m.x() || x >= bed.max_m.x()) continue;
        bool inside_body = false;
        for (size_t b = 0; b < scene_.bodies.size() && !inside_body; ++b)
          inside_body = shape_sdf(scene_.bodies[b].shape, bodies_[b].to_body(Vec2(x, y))) < 0.0;
        if (inside_body) continue;
        // geostatic stress: vertical rho g depth, horizontal and out-of-plane k0 times it
        const double sv = bed.geostatic ? mp.rho_g * phi_i * g * (bed.max_m.y() - y) : 0.0;
        const double P = sv * (1.0 + 2.0 * k0) / 3.0;
        const bool dense = phi_i >= phi_d;
        p_.x.push_back(x);
        p_.y.push_back(y);
        p_.vx.push_back(0.0);
        p_.vy.push_back(0.0);
        p_.mass.push_back(mass);
        // the elastic law P = K ln(phi/phi_d) fixes the volume that carries this pressure
        p_.volume.push_back(dense ? mass / (mp.rho_g * phi_d * std::exp(P / mp.K)) : v0);
        p_.sxx.push_back(dense ? P - k0 * sv : 0.0);
        p_.syy.push_back(dense ? P - sv : 0.0);
        p_.szz.push_back(dense ? P - k0 * sv : 0.0);
        p_.sxy.push_back(0.0);
        p_.pressure.push_back(dense ? P : 0.0);
        if (dilatancy_) p_.phi_d.push_back(phi_d);
        p_.material.push_back(mi);
      }
    }
  }
  const size_t n = p_.x.size();
  for (auto* a : {&p_.c00, &p_.c01, &p_.c10, &p_.c11}) a->assign(n, 0.0);
  if (track_plastic_) {
    p_.plastic_strain.assign(n, 0.0);
    p_.strain_rate.assign(n, 0.0);
  }
  // push_back left up to twice the points' storage (12% at 1.84M points); the reorder's swaps
  // would carry that slack along for the whole run
  p_.for_each_array([](const char*, auto& a) { a.shrink_to_fit(); });
}

double Simulation::next_dt_s() const {
  double vmax = stats_.max_speed_m_s;
  for (const auto& b : bodies_) {
    const double reach = std::max(b.lo_m.cwiseAbs().maxCoeff(), b.hi_m.cwiseAbs().maxCoeff());
    vmax = std::max(vmax, b.velocity_m_s.norm() + (b.turns ? std::abs(b.omega_rad_s) * std::sqrt(2.0) * reach : 0.0));
  }
  for (size_t b = 0; b < bodies_.size(); ++b)
    vmax = std::max(vmax, motion_velocity_m_s(scene_.bodies[b].motion, t_s_).norm());
  return scene_.solver.cfl * g_.dx / (wave_speed_ + vmax);
}

// Sample points of each body's mass field (cell-fraction contact), fixed in the body's frame so
// the field moves smoothly with it. The inset keeps the field's reach (the B-spline support of its
// outermost points) near the surface; a body thinner than two insets keeps its inner half.
void Simulation::sample_body_fields() {
  const double dx = g_.dx, h = dx / kBodySamplesPerCell;
  double mass = 0.0, volume = 0.0;
  for (size_t p = 0; p < p_.size(); ++p) mass += p_.mass[p], volume += p_.volume[p];
  const double density = volume > 0.0 ? kBodyDensityRatio * mass / volume : 0.0;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const auto [frame_lo, frame_hi] = shape_bounds_m(scene_.bodies[b].shape);  // in the body's frame
    std::vector<std::pair<Vec2, double>> inside;  // point, depth below the surface (m)
    double deepest = 0.0;
    for (double y = frame_lo.y() + 0.5 * h; y < frame_hi.y(); y += h)
      for (double x = frame_lo.x() + 0.5 * h; x < frame_hi.x(); x += h) {
        const double depth = -shape_sdf(scene_.bodies[b].shape, Vec2(x, y));
        if (depth <= 0.0) continue;
        inside.emplace_back(Vec2(x, y), depth);
        deepest = std::max(deepest, depth);
      }
    const double inset = std::min(kBodyFieldInset * dx, 0.5 * deepest);
    const Shape& shape = scene_.bodies[b].shape;
    // across the body's travel (a path that turns keeps the direction of its middle), in the
    // body's frame; none for a body that spins: no one direction is across its travel. A body
    // held at an angle keeps it (without, a plate tilted 0.001 degrees acted a side inset wider:
    // +15% force on plate_intrusion)
    const Body& body = scene_.bodies[b];
    const bool spins = body.dynamics.free_angle || motion_max_angular_speed_rad_s(body.motion) > 0.0;
    Vec2 travel = spins ? Vec2(0.0, 0.0) : travel_direction(scene_, body);
    if (!spins && body.start_angle_rad != 0.0) {
      const double c = std::cos(body.start_angle_rad), s = std::sin(body.start_angle_rad);
      travel = Vec2(c * travel.x() + s * travel.y(), -s * travel.x() + c * travel.y());
    }
    const Vec2 across(-travel.y(), travel.x());
    // distance from q to the surface along +-across (bisection on the SDF; the body is inside its box)
    auto depth_across = [&](const Vec2& q) {
      const double far = (frame_hi - frame_lo).norm();
      double depth = far;
      for (double sign : {-1.0, 1.0}) {
        double in = 0.0, out = far;
        for (int k = 0; k < 40; ++k) {
          const double mid = 0.5 * (in + out);
          (shape_sdf(shape, q + sign * mid * across) < 0.0 ? in : out) = mid;
        }
        depth = std::min(depth, out);
      }
      return depth;
    };
    std::vector<double> across_m(inside.size(), 0.0);
    double widest = 0.0;
    if (across.squaredNorm() > 0.0)
      for (size_t k = 0; k < inside.size(); ++k) widest = std::max(widest, across_m[k] = depth_across(inside[k].first));
    // as with the inset, a body too thin for it keeps its middle
    const double side_inset = std::min(kBodyFieldSideInset * dx, 0.5 * widest);
    std::vector<Vec2> samples;
    for (size_t k = 0; k < inside.size(); ++k)
      if (inside[k].second >= inset && across_m[k] >= side_inset) samples.push_back(inside[k].first);
    body_samples_m_.push_back(std::move(samples));
  }
  body_sample_mass_kg_ = density * h * h;
  body_node_full_kg_ = density * dx * dx;  // the field at a node whose whole stencil it fills
}

const char* instruction_set() {
#if defined(__AVX512F__) && defined(__AVX512VL__)
  return "x86-64-v4 (AVX-512)";
#elif defined(__AVX2__) && defined(__FMA__)
  return "x86-64-v3 (AVX2, FMA)";
#else
  return "x86-64";
#endif
}

void Simulation::step() {
  using clock = std::chrono::steady_clock;
  auto mark = clock::now();
  auto lap = [&](double& phase) {
    const auto now = clock::now();
    phase += std::chrono::duration<double>(now - mark).count();
    mark = now;
  };
  dt_s_ = next_dt_s();
  if (homes_stale_) arena_->execute([&] { (this->*reorder_)(); });
  arena_->execute([&] {
    clear_grid();
    lap(phase_s_.clear);
    (this->*p2g_)();
    lap(phase_s_.p2g);
    grid_update();
    lap(phase_s_.grid);
    bodies_and_walls();
    lap(phase_s_.contact);
    const bool front_back = scene_.walls.front_back.present() && scene_.effects.wall_friction;
    if (fuse_particle_passes_ && !front_back) {
      particles_update(true, true);
      lap(phase_s_.g2p_constitutive);
    } else {
      particles_update(true, false);
      lap(phase_s_.g2p);
      if (front_back) {
        front_back_friction();
        lap(phase_s_.contact);
      }
      particles_update(false, true);
      lap(phase_s_.constitutive);
    }
  });
  advance_bodies();
  t_s_ += dt_s_;
  ++steps_;
  // now and then for memory order; at once when a point strayed from its strip's window
  if (steps_ % kReorderSteps == 0 || strayed_) {
    ++(strayed_ && steps_ % kReorderSteps != 0 ? reorders_.strayed : reorders_.scheduled);
    arena_->execute([&] { (this->*reorder_)(); });
    lap(phase_s_.reorder);
  }
}

bool Simulation::finished() const {
  const auto& s = scene_.solver;
  if (t_s_ >= s.end_time_s - 1e-12) return true;
  if (steps_ >= s.max_steps) return true;
  return s.end_displacement_m > 0.0 && lead_body_travel_m() >= s.end_displacement_m;
}

double Simulation::lead_body_travel_m() const {
  const int b = reference_body_index(scene_);
  return b < 0 ? 0.0 : (bodies_[size_t(b)].position_m - scene_.bodies[size_t(b)].start_m).norm();
}

void Simulation::clear_grid() {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, g_.node.size(), kGridGrain), [&](const auto& r) {
    std::fill(g_.node.begin() + r.begin(), g_.node.begin() + r.end(), GridNode{});
  });
}

template <class K, bool Flip>
void Simulation::particles_to_grid() {
  const double dx = g_.dx, inv_dx = 1.0 / dx, dt = dt_s_;
  const double Dinv = K::inv_D(inv_dx);
  GridNode* grid = g_.node.data();
  const auto& P = p_;
  auto scatter_strip = [&](int s) {
    // locals, not captures: the grid stores below cannot change them, so they stay in registers
    GridNode* const nodes = grid;
    const size_t NY = size_t(g_.NY);
    const double *const X = P.x.data(), *const Y = P.y.data(), *const VX = P.vx.data(), *const VY = P.vy.data();
    const auto *const C00 = P.c00.data(), *const C01 = P.c01.data(), *const C10 = P.c10.data(), *const C11 = P.c11.data();
    const auto *const M = P.mass.data(), *const SXX = P.sxx.data(), *const SYY = P.syy.data(), *const SXY = P.sxy.data();
    const auto *const PRESSURE = P.pressure.data();
    const double* const VOL = P.volume.data();
    const double h = dx, ih = inv_dx, dt_ = dt, Dinv_ = Dinv;
    StencilRun<K::N> run(NY);
    for (uint32_t p = strip_start_[s], p_end = strip_start_[s + 1]; p < p_end; ++p) {
      double wx[K::N], wy[K::N], dwx[K::N], dwy[K::N];
      const double xp = X[p], yp = Y[p];
      const int bx = K::weights(xp * ih, wx, dwx, ih);
      const int by = K::weights(yp * ih, wy, dwy, ih);
      const double m = M[p], V = VOL[p];
      const double pressure = PRESSURE[p];
      const double sxx = SXX[p] - pressure, syy = SYY[p] - pressure, sxy = SXY[p];
      const double mvx = m * VX[p], mvy = m * VY[p];
      // momentum affine Q = m C; MLS force affine S = -dt V D^-1 sigma (grad w ~ w D^-1 (x_i - x_p)).
      // Without FLIP both act on the same momentum and fold into one matrix.
      const double ks = K::mls ? -dt_ * V * Dinv_ : 0.0;
      const double s00 = ks * sxx, s01 = ks * sxy, s11 = ks * syy;
      double q00 = m * C00[p], q01 = m * C01[p], q10 = m * C10[p], q11 = m * C11[p];
      if constexpr (K::mls && !Flip) {
        q00 += s00;
        q01 += s01;
        q10 += s01;
        q11 += s11;
      }
      const double dx0 = bx * h - xp, dy0 = by * h - yp;
      if constexpr (K::mls && Flip) {
        // The default path (FLIP, MLS kernels). A node's first four fields (m, momentum, force
        // impulse x) take w (base + dxp colA + dyp colB) in one 4-wide update, w = wx wy. dxp varies
        // along a row only and dyp down a column only, so the column factors are formed once per
        // particle, U_a = wx_a (base + dxp_a colA) and V_a = wx_a colB, and each node takes
        // wy_b U_a + (wy_b dyp_b) V_a: two FMAs. The fifth field (force impulse y) the same way.
        // Consecutive points with the same stencil (the reorder sorts them together) sum into
        // `run`, which the grid takes once (StencilRun). Same sums as the scalar path, associated
        // differently (round-off; README, Performance).
        const Vec4d base = {m, mvx, mvy, 0.0}, colA = {0.0, q00, q10, s00}, colB = {0.0, q01, q11, s01};
        Vec4d Ua[K::N], Va[K::N];
        double u[K::N], v[K::N];
        for (int a = 0; a < K::N; ++a) {
          const double dxp = dx0 + a * h;
          Ua[a] = wx[a] * fma4(splat(dxp), colA, base);
          Va[a] = wx[a] * colB;
          u[a] = wx[a] * dxp * s01;
          v[a] = wx[a] * s11;
        }
        run.start(nodes + Grid::index(bx, by, NY));
        for (int b = 0; b < K::N; ++b) {
          const double wb = wy[b], wdb = wy[b] * (dy0 + b * h);
          for (int a = 0; a < K::N; ++a) {
            run.four[a][b] += fma4(splat(wb), Ua[a], wdb * Va[a]);
            run.fifth[b][a] += fma1(wb, u[a], wdb * v[a]);
          }
        }
        continue;
      }
      for (int b = 0; b < K::N; ++b) {
        GridNode* row = grid + g_.index(bx, by + b);
        const double dyp = dy0 + b * dx;
        for (int a = 0; a < K::N; ++a) {
          const double dxp = dx0 + a * dx;
          const double w = wx[a] * wy[b];
          GridNode& n = row[a * NY];
          n.m += w * m;
          n.vx += w * (mvx + q00 * dxp + q01 * dyp);
          n.vy += w * (mvy + q10 * dxp + q11 * dyp);
          if constexpr (!K::mls) {
            // true B-spline gradients for the internal force
            const double gxw = dwx[a] * wy[b], gyw = wx[a] * dwy[b];
            const double fx = -dt * V * (sxx * gxw + sxy * gyw), fy = -dt * V * (sxy * gxw + syy * gyw);
            if constexpr (Flip) {
              n.vx0 += fx;
              n.vy0 += fy;
            } else {
              n.vx += fx;
              n.vy += fy;
            }
          } else if constexpr (Flip) {
            // FLIP keeps the internal-force impulse apart so the pre-force velocity is known
            n.vx0 += w * (s00 * dxp + s01 * dyp);
            n.vy0 += w * (s01 * dxp + s11 * dyp);
          }
        }
      }
    }
    run.flush();
  };
  const int strips = int(strip_start_.size()) - 1;
#if defined(__AVX__)
  if constexpr (std::is_same_v<K, QuadraticKernel> && Flip) {
    if (by_four_) {
      for (int colour = 0; colour < 2; ++colour)
        tbb::parallel_for(0, (strips + 1 - colour) / 2, [&](int k) { p2g_strip_quadratic_by_four(2 * k + colour); });
      return;
    }
  }
#endif
  for (int colour = 0; colour < 2; ++colour)
    tbb::parallel_for(0, (strips + 1 - colour) / 2, [&](int k) { scatter_strip(2 * k + colour); });
}

#if defined(__AVX__)
// out[l] = {a[l], b[l], c[l], d[l]}: four lane vectors to four per-lane vectors
inline void transpose4(const Vec4d& a, const Vec4d& b, const Vec4d& c, const Vec4d& d, Vec4d out[4]) {
  const __m256d ab_lo = _mm256_unpacklo_pd((__m256d)a, (__m256d)b), ab_hi = _mm256_unpackhi_pd((__m256d)a, (__m256d)b);
  const __m256d cd_lo = _mm256_unpacklo_pd((__m256d)c, (__m256d)d), cd_hi = _mm256_unpackhi_pd((__m256d)c, (__m256d)d);
  out[0] = (Vec4d)_mm256_permute2f128_pd(ab_lo, cd_lo, 0x20);
  out[1] = (Vec4d)_mm256_permute2f128_pd(ab_hi, cd_hi, 0x20);
  out[2] = (Vec4d)_mm256_permute2f128_pd(ab_lo, cd_lo, 0x31);
  out[3] = (Vec4d)_mm256_permute2f128_pd(ab_hi, cd_hi, 0x31);
}
#endif

// The default P2G (quadratic B-splines, FLIP) of one strip, four points at a time: a point per
// lane for its weights, stress and affine terms and the per-column factors of scatter_strip's
// default path; the scatter itself stays a point at a time, in the strip's order (the same sums
// in the same order: the same bits as scatter_strip, tested).
void Simulation::p2g_strip_quadratic_by_four(int strip) {
#if defined(__AVX__)
  using V = Vec4d;
  const double h = g_.dx, ih = 1.0 / h, dt = dt_s_, Dinv = QuadraticKernel::inv_D(ih);
  GridNode* const nodes = g_.node.data();
  const size_t NY = size_t(g_.NY);
  const Particles& P = p_;
  const V zero = {0, 0, 0, 0};
  StencilRun<3> run(NY);
  // points k..k+3 of the strip; count: a std::integral_constant 4 for a full group (plain loads),
  // a size_t for the strip's last, whose empty lanes take its last point and scatter nothing.
  // Inlined, so the grid's address and stride stay in registers across the scatter's stores.
  auto group = [&](const uint32_t k, const auto count) __attribute__((always_inline)) {
    auto gather = [&](const auto& a) {
      if (count == 4) return load4(a.data() + k);
      V v;
      for (size_t l = 0; l < 4; ++l) v[l] = double(a[k + std::min(l, size_t(count) - 1)]);
      return v;
    };
    const V xp = gather(P.x), yp = gather(P.y);
    V wx[3], wy[3];
    int bx[4], by[4];
    const V bxd = quadratic_weights_by_four(xp, ih, wx, bx), byd = quadratic_weights_by_four(yp, ih, wy, by);
    const V m = gather(P.mass), vol = gather(P.volume), pressure = gather(P.pressure);
    const V sxx = gather(P.sxx) - pressure, syy = gather(P.syy) - pressure, sxy = gather(P.sxy);
    const V mvx = m * gather(P.vx), mvy = m * gather(P.vy);
    const V ks = -dt * vol * Dinv;
    const V s00 = ks * sxx, s01 = ks * sxy, s11 = ks * syy;
    const V q00 = m * gather(P.c00), q01 = m * gather(P.c01), q10 = m * gather(P.c10), q11 = m * gather(P.c11);
    const V dx0 = bxd * h - xp, dy0 = byd * h - yp;
    V dxp[3], u[3], v[3], wdy[3];
    for (int a = 0; a < 3; ++a) {
      dxp[a] = dx0 + a * h;
      u[a] = wx[a] * dxp[a] * s01;
      v[a] = wx[a] * s11;
      wdy[a] = wy[a] * (dy0 + a * h);
    }
    // scatter_strip's column factors U_a = wx_a (base + dxp_a colA), V_a = wx_a colB, field by field
    // for the four points, then turned into a [m vx vy vx0] vector per point (a 4x4 transpose); the
    // fifth field's u_a, v_a as a vector over a per point, for StencilRun's rows
    V Ua[3][4], Va[3][4], uT[4], vT[4];
    for (int a = 0; a < 3; ++a) {
      transpose4(wx[a] * fma4(dxp[a], zero, m), wx[a] * fma4(dxp[a], q00, mvx), wx[a] * fma4(dxp[a], q10, mvy),
                 wx[a] * fma4(dxp[a], s00, zero), Ua[a]);
      transpose4(wx[a] * zero, wx[a] * q01, wx[a] * q11, wx[a] * s01, Va[a]);
    }
    transpose4(u[0], u[1], u[2], zero, uT);
    transpose4(v[0], v[1], v[2], zero, vT);
    for (size_t l = 0; l < count; ++l) {
      run.start(nodes + Grid::index(bx[l], by[l], NY));
      for (int b = 0; b < 3; ++b) {
        const V wb = lane(wy[b], int(l)), wdb = lane(wdy[b], int(l));
        for (int a = 0; a < 3; ++a) run.four[a][b] += fma4(wb, Ua[a][l], wdb * Va[a][l]);
        run.fifth[b] += fma4(wb, uT[l], wdb * vT[l]);
      }
    }
  };
  const uint32_t k0 = strip_start_[size_t(strip)], k1 = strip_start_[size_t(strip) + 1];
  uint32_t k = k0;
  for (; k + 4 <= k1; k += 4) group(k, std::integral_constant<size_t, 4>());
  if (k < k1) group(k, size_t(k1 - k));
  run.flush();
#else
  (void)strip;
#endif
}

void Simulation::grid_update() {
  const double dt = dt_s_, gx = gravity_.x() * dt, gy = gravity_.y() * dt;
  const bool flip = flip_;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, g_.node.size(), kGridGrain), [&](const auto& r) {
    for (size_t k = r.begin(); k < r.end(); ++k) {
      GridNode& n = g_.node[k];
      if (n.m > 0.0) {
        const double inv_m = 1.0 / n.m;
        if (flip) {
          // vx0 held the force impulse; it becomes the pre-force velocity
          const double v0x = n.vx * inv_m, v0y = n.vy * inv_m;
          n.vx = v0x + n.vx0 * inv_m + gx;
          n.vy = v0y + n.vy0 * inv_m + gy;
          n.vx0 = v0x;
          n.vy0 = v0y;
        } else {
          n.vx = n.vx * inv_m + gx;
          n.vy = n.vy * inv_m + gy;
        }
      }
    }
  });
}

namespace {

// Coulomb contact of a node velocity against a surface with outward normal n moving at vb.
// Returns true if the node was in approaching contact and its velocity was changed.
inline bool contact(Vec2& v, const Vec2& vb, const Vec2& n, double mu) {
  const Vec2 rel = v - vb;
  const double vn = rel.dot(n);
  if (vn >= 0.0) return false;
  Vec2 vt = rel - vn * n;
  const double t = vt.norm();
  if (t > 0.0) vt *= std::max(0.0, t + mu * vn) / t;  // vn < 0: friction removes up to mu|vn|
  v = vb + vt;
  return true;
}

// G2P's safety net: a point that still ended inside the body is moved back onto its surface. Its
// velocity is left as it is: next step's contact takes the approach out of it at the nodes, through
// the same smooth share as everything else, and counts it in the body's force there. Removing it
// here, in one step and one point at a time, put single-step ticks of up to 13% on the force each
// time a point first reached a face (tests/README.md, 2026-12-04). Whether it acted.
inline bool put_back_on_surface(const BodyState& s, const Shape& shape, double dx, Vec2& x) {
  const Vec2 r = x - s.position_m;
  if (r.x() < s.lo_m.x() || r.y() < s.lo_m.y() || r.x() > s.hi_m.x() || r.y() > s.hi_m.y()) return false;
  const Vec2 q = s.to_body(x);
  const double d = shape_sdf(shape, q);
  if (d >= 0.0) return false;
  x -= d * s.to_world(shape_normal(shape, q, 1e-4 * dx));
  return true;
}

}  // namespace

void Simulation::bodies_and_walls() {
  if (!bodies_.empty()) (this->*contact_)();
  contact_walls();
}

// Node contact: every grid node inside a body takes the body's normal velocity (Coulomb slip
// along it). The constrained set grows by a node row each time a face crosses a node line, so
// the force steps with a period of one cell.
//
// Cell-fraction contact (Fraction): the body is also a mass field on the grid, scattered from
// sample points fixed in its frame (contact_cell_fraction), and a node takes the share
// m_body / (m_body + m_media) of the correction, as multi-field contact of the media against a
// body of finite mass would (Bardenhagen et al. 2001), scaled up to reach 1 where the field
// covers the node fully, since a driven body has no finite mass. The share is a smooth function
// of the body's position, so no node switches on at once as a face crosses a node line. The correction
// itself is the mass-weighted mean of what each media point in the node's stencil asks of it: the
// node's velocity held against the body along that point's own face normal (Coulomb slip along
// it). One normal per node flips where the node crosses a thin body's medial axis (a node row of
// a plate two cells thick, which then stopped holding the material below it: the larger part of
// the node method's comb, and of a mass-gradient normal's); the points' normals do not, since
// each point stays on its own side. Nodes act only once touched (contact_cell_fraction).
template <bool Fraction>
void Simulation::contact_nodes() {
  const double dt = dt_s_, dx = g_.dx;
  held_.resize(bodies_.size());
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const Body& body = scene_.bodies[b];
    BodyState& s = bodies_[b];
    const double mu = scene_.effects.body_friction ? body.friction : 0.0;
    const auto [i0, i1, j0, j1] = body_node_box(s, g_);
    Vec2 impulse(0.0, 0.0);
    double angular = 0.0;  // angular momentum the media gained about the body's origin
    const bool free = body.dynamics.any_free();
    // a free body: what each node's correction depends on the body's velocity (its projector)
    if (free) held_[b].assign(size_t(i1 - i0 + 1) * size_t(j1 - j0 + 1), Vec3(0.0, 0.0, 0.0));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const size_t k = g_.index(i, j);
        GridNode& n = g_.node[k];
        const Vec2 xn(i * dx, j * dx), q = s.to_body(xn);
        double share = 1.0;
        const size_t c = size_t(j - j0) * size_t(i1 - i0 + 1) + size_t(i - i0);  // index in the body's box
        if constexpr (Fraction) {
          const double m_body = body_node_mass_kg_[b][c];
          if (n.m <= 0.0 || m_body <= 0.0) {
            touched_[b][k] = 0;  // out of the body's reach: must be touched again
            continue;
          }
          if (!touched_[b][k]) continue;
          // the multi-field share m_body / (m_body + m), scaled to reach 1 where the body's field
          // covers the node fully (m_body = body_node_full_kg_): a driven body has no finite mass,
          // and a share below 1 inside it let the material under it lag it (README, "Body contact")
          share = std::min(1.0, m_body * (body_node_full_kg_ + n.m) / ((m_body + n.m) * body_node_full_kg_));
        } else if (n.m <= 0.0 || shape_sdf(body.shape, q) >= 0.0) {
          continue;
        }
        Vec2 v(n.vx, n.vy);
        const Vec2 before = v;
        if constexpr (Fraction) {
          const double m_points = stencil_mass_kg_[b][c];
          if (m_points <= 0.0) continue;
          v += share * (stencil_dv_kg_m_s_[b][c] / m_points);
        } else {
          const Vec2 normal = s.to_world(shape_normal(body.shape, q, 1e-4 * dx));
          if (!contact(v, s.velocity_at(xn), normal, mu)) continue;
          if (free) held_[b][c] = Vec3(normal.x() * normal.x(), normal.x() * normal.y(), normal.y() * normal.y());
        }
        if constexpr (Fraction)
          if (free) held_[b][c] = share * stencil_nn_[b][c] / stencil_mass_kg_[b][c];
        const Vec2 dp = n.m * (v - before);
        impulse += dp;
        if (s.turns || free) angular += (xn - s.position_m).x() * dp.y() - (xn - s.position_m).y() * dp.x();
        n.vx = v.x();
        n.vy = v.y();
      }
    if (free) respond_free_body(b, impulse, angular);
    s.force_N_per_m = -impulse / dt;
    s.torque_N = -angular / dt;
  }
}

// Cell-fraction contact acts only at nodes a material point has touched: a point whose surface is
// within kTouchCells of the body marks the nodes of its stencil, and a node stays marked while both
// the media and the body's field reach it. Without this, the body's field acts on material up to
// a cell from the surface and the body feels the bed before it meets it.
template <class K>
void Simulation::contact_cell_fraction() {
  const double dx = g_.dx, inv_dx = 1.0 / dx;
  // a point reaches the nodes of the body's box (the body's box and two cells) from 1.5 cells out
  const double reach = 3.5 * dx;
  const int strips = int(strip_start_.size()) - 1;
  touched_.resize(bodies_.size());
  body_node_mass_kg_.resize(bodies_.size());
  stencil_dv_kg_m_s_.resize(bodies_.size());
  stencil_mass_kg_.resize(bodies_.size());
  stencil_nn_.resize(bodies_.size());
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const BodyState& s = bodies_[b];
    const Shape& shape = scene_.bodies[b].shape;
    const double mu = scene_.effects.body_friction ? scene_.bodies[b].friction : 0.0;
    auto& touched = touched_[b];
    touched.resize(g_.node.size(), 0);
    // only nodes contact_nodes() visits are marked, so it also clears every mark it leaves behind
    const auto [i0, i1, j0, j1] = body_node_box(s, g_);
    const size_t width = size_t(i1 - i0 + 1), box_nodes = width * size_t(j1 - j0 + 1);
    auto& dv = stencil_dv_kg_m_s_[b];
    auto& m_points = stencil_mass_kg_[b];
    dv.assign(box_nodes, Vec2(0.0, 0.0));
    m_points.assign(box_nodes, 0.0);
    const bool free = scene_.bodies[b].dynamics.any_free();
    if (free) stencil_nn_[b].assign(box_nodes, Vec3(0.0, 0.0, 0.0));
    // Both sums below run over bands of the box's node rows in parallel. Each band visits every
    // sample and point in the same order as one pass would and adds only to its own rows, so each
    // node's sum is the same whatever the bands: results are the same for any thread count (a
    // point whose stencil spans two bands is worked out in both). Two bands per thread for balance,
    // each at least four rows high; on one thread, one band and no work twice.
    const int rows = j1 - j0 + 1, threads = tbb::this_task_arena::max_concurrency();
    const int bands = threads == 1 ? 1 : std::clamp(std::min(rows / 4, 2 * threads), 1, rows);
    auto band_rows = [&](int band) {
      return std::pair<int, int>(j0 + int(int64_t(rows) * band / bands), j0 + int(int64_t(rows) * (band + 1) / bands) - 1);
    };
    // the body's field over its node box
    auto& field = body_node_mass_kg_[b];
    field.assign(box_nodes, 0.0);
    tbb::parallel_for(0, bands, [&](int band) {
      const auto [ra, rb] = band_rows(band);
      for (const Vec2& q : body_samples_m_[b]) {
        const Vec2 x = s.position_m + s.to_world(q);
        const int base_y = K::base(x.y() * inv_dx);
        if (base_y > rb || base_y + K::N - 1 < ra) continue;
        double wx[K::N], wy[K::N], dw[K::N];
        const int bx = K::weights(x.x() * inv_dx, wx, dw, inv_dx);
        const int by = K::weights(x.y() * inv_dx, wy, dw, inv_dx);
        for (int j = std::max(by, ra); j <= std::min(by + K::N - 1, rb); ++j)
          for (int i = std::max(bx, i0); i <= std::min(bx + K::N - 1, i1); ++i)
            field[size_t(j - j0) * width + size_t(i - i0)] += wx[i - bx] * wy[j - by] * body_sample_mass_kg_;
      }
    });
    // each point in reach: marks its stencil if it touches the body, and adds to each node of its
    // stencil (weight x mass) the change that holds the node against the body along the point's
    // own face normal; points in strip order. Only nodes the body's field reaches: contact_nodes()
    // acts on no other (and clears their marks).
    const auto [first, last] = body_strip_span<K>(s, reach, inv_dx, strips);
    tbb::parallel_for(0, bands, [&](int band) {
      const auto [ra, rb] = band_rows(band);
      for (uint32_t p = strip_start_[first]; p < strip_start_[last + 1]; ++p) {
        const Vec2 r = Vec2(p_.x[p], p_.y[p]) - s.position_m;
        if (r.x() < s.lo_m.x() - reach || r.y() < s.lo_m.y() - reach || r.x() > s.hi_m.x() + reach ||
            r.y() > s.hi_m.y() + reach)
          continue;
        const int base_y = K::base(p_.y[p] * inv_dx);
        if (base_y > rb || base_y + K::N - 1 < ra) continue;
        double wx[K::N], wy[K::N], dw[K::N];
        const int bx = K::weights(p_.x[p] * inv_dx, wx, dw, inv_dx);
        const int by = K::weights(p_.y[p] * inv_dx, wy, dw, inv_dx);
        const int ja = std::max(by, j0), jb = std::min(by + K::N - 1, j1);
        const int ia = std::max(bx, i0), ib = std::min(bx + K::N - 1, i1);
        bool reached = false;  // over the whole stencil, not only this band's rows
        for (int j = ja; j <= jb; ++j)
          for (int i = ia; i <= ib; ++i) reached |= field[size_t(j - j0) * width + size_t(i - i0)] > 0.0;
        if (!reached) continue;
        const Vec2 q = s.to_body(Vec2(p_.x[p], p_.y[p]));
        const bool touching = shape_sdf(shape, q) - 0.5 * std::sqrt(p_.volume[p]) <= kTouchCells * dx;
        const Vec2 normal = s.to_world(shape_normal(shape, q, 1e-4 * dx));
        const Vec3 nn(normal.x() * normal.x(), normal.x() * normal.y(), normal.y() * normal.y());
        const double mass = double(p_.mass[p]);
        for (int j = std::max(ja, ra); j <= std::min(jb, rb); ++j)
          for (int i = ia; i <= ib; ++i) {
            const size_t k = g_.index(i, j), c = size_t(j - j0) * width + size_t(i - i0);
            if (field[c] <= 0.0) continue;
            if (touching) touched[k] = 1;
            const double wm = wx[i - bx] * wy[j - by] * mass;
            m_points[c] += wm;
            Vec2 v(g_.node[k].vx, g_.node[k].vy);
            const Vec2 v0 = v;
            if (!contact(v, s.velocity_at(Vec2(i * dx, j * dx)), normal, mu)) continue;
            dv[c] += wm * (v - v0);
            if (free) stencil_nn_[b][c] += wm * nn;
          }
      }
    });
  }
  contact_nodes<true>();
}

// Particle contact: the material points whose surface (centre + half their size) would reach a
// body within this step are held to its normal velocity (Coulomb slip along it) by impulses
// scattered onto the grid through their own weights, solved by Gauss-Seidel over the points.
// The constraint follows the points, not the node lines, so the force moves smoothly as a face
// crosses the grid, and it starts when the surfaces meet.
template <class K>
void Simulation::contact_particles() {
  find_contact_points<K>();
  solve_contact_points<K>();
}

// The points in (or about to be in) contact, with their stencils, normals and gaps; impulses
// start from the last step's (warm start).
template <class K>
void Simulation::find_contact_points() {
  const double dx = g_.dx, inv_dx = 1.0 / dx;
  const size_t nb = bodies_.size();
  const auto& P = p_;
  // candidates: points within two cells of a body's box (no point moves a cell in a step), found
  // in the strips whose points may lie there (body_strip_span), then put in (particle, body) order so
  // the list is the same for any thread count
  const double reach = 2.0 * dx;
  const int strips = int(strip_start_.size()) - 1;
  contact_chunks_.resize(size_t(strips) * nb);
  std::vector<std::pair<int, int>> spans(nb);
  for (size_t b = 0; b < nb; ++b) {
    const BodyState& s = bodies_[b];
    spans[b] = body_strip_span<K>(s, reach, inv_dx, strips);
  }
  tbb::parallel_for(size_t(0), contact_chunks_.size(), [&](size_t k) {
    const size_t b = k / size_t(strips);
    const int strip = int(k % size_t(strips));
    auto& out = contact_chunks_[k];
    out.clear();
    if (strip < spans[b].first || strip > spans[b].second) return;
    const BodyState& s = bodies_[b];
    for (uint32_t p = strip_start_[strip]; p < strip_start_[strip + 1]; ++p) {
      const Vec2 q = Vec2(P.x[p], P.y[p]) - s.position_m;
      if (q.x() < s.lo_m.x() - reach || q.y() < s.lo_m.y() - reach || q.x() > s.hi_m.x() + reach ||
          q.y() > s.hi_m.y() + reach)
        continue;
      out.push_back(p);
    }
  });
  std::vector<uint64_t> keys;
  for (size_t k = 0; k < contact_chunks_.size(); ++k)
    for (uint32_t p : contact_chunks_[k]) keys.push_back(uint64_t(p) << 32 | uint64_t(k / size_t(strips)));
  std::sort(keys.begin(), keys.end());
  std::vector<uint32_t> cand(2 * keys.size());
  for (size_t k = 0; k < keys.size(); ++k) {
    cand[2 * k] = uint32_t(keys[k] >> 32);
    cand[2 * k + 1] = uint32_t(keys[k] & 0xffffffffu);
  }
  const size_t nc = keys.size();
  // the last step's impulses start the solve (warm start): a steady contact then needs few sweeps
  std::vector<ContactPoint> previous;
  previous.swap(contacts_);
  contacts_.resize(nc);
  std::vector<uint8_t> keep(nc, 0);
  const bool friction = scene_.effects.body_friction;
  tbb::parallel_for(size_t(0), nc, [&](size_t k) {
    const uint32_t p = cand[2 * k], b = cand[2 * k + 1];
    const BodyState& s = bodies_[b];
    const Shape& shape = scene_.bodies[b].shape;
    const Vec2 q = s.to_body(Vec2(P.x[p], P.y[p]));
    const double half = 0.5 * std::sqrt(P.volume[p]);
    const double gap = shape_sdf(shape, q) - half;
    if (gap > dx) return;
    ContactPoint& c = contacts_[k];
    double wx[K::N], wy[K::N], dwx[K::N], dwy[K::N];
    const int bx = K::weights(P.x[p] * inv_dx, wx, dwx, inv_dx);
    const int by = K::weights(P.y[p] * inv_dx, wy, dwy, inv_dx);
    c.base = g_.index(bx, by);
    // the impulse goes to the nodes in proportion to the point's weights (the least mass-weighted
    // change of the node velocities that moves the point as required)
    double sum = 0.0;
    for (int j = 0; j < K::N; ++j)
      for (int i = 0; i < K::N; ++i) {
        const double w = wx[i] * wy[j];
        c.w[j * K::N + i] = w;
        const double m = g_.node[c.base + size_t(j) + size_t(i) * size_t(g_.NY)].m;
        if (m > 0.0) sum += w * w / m;
      }
    c.inv_meff = sum;
    c.n = s.to_world(shape_normal(shape, q, 1e-4 * dx));
    c.vb = s.velocity_at(Vec2(P.x[p], P.y[p]));
    c.gap_m = gap;
    c.mu = friction ? scene_.bodies[b].friction : 0.0;
    c.jn = c.jt = 0.0;
    c.particle = p;
    c.body = b;
    keep[k] = sum > 0.0;
  });
  // a point near two bodies whose faces point the same way (under the joint of touching plates)
  // is held by the nearer one only: two parallel constraints would split its impulse between the
  // bodies by the order of the sweep
  for (size_t k = 0; k + 1 < nc; ++k) {
    if (!keep[k] || !keep[k + 1] || cand[2 * k] != cand[2 * k + 2]) continue;
    const ContactPoint &a = contacts_[k], &b = contacts_[k + 1];
    if (a.n.dot(b.n) > 0.5) keep[b.gap_m < a.gap_m ? k : k + 1] = 0;
  }
  size_t m = 0;
  for (size_t k = 0; k < nc; ++k)
    if (keep[k]) contacts_[m++] = contacts_[k];
  contacts_.resize(m);
  // both lists are sorted by (particle, body)
  for (size_t k = 0, o = 0; k < contacts_.size() && o < previous.size();) {
    ContactPoint& c = contacts_[k];
    const ContactPoint& q = previous[o];
    if (q.particle < c.particle || (q.particle == c.particle && q.body < c.body)) {
      ++o;
    } else if (q.particle == c.particle && q.body == c.body) {
      c.jn = q.jn;
      c.jt = std::clamp(q.jt, -c.mu * c.jn, c.mu * c.jn);
      apply_contact_impulse<K>(c, c.impulse());
      ++k, ++o;
    } else {
      ++k;
    }
  }
}

// Adds impulse J (N s per metre) at point c to the node velocities, shared by its weights.
template <class K>
void Simulation::apply_contact_impulse(const ContactPoint& c, const Vec2& J) {
  GridNode* grid = g_.node.data();
  for (int j = 0; j < K::N; ++j)
    for (int i = 0; i < K::N; ++i) {
      GridNode& nd = grid[c.base + size_t(j) + size_t(i) * size_t(g_.NY)];
      if (nd.m <= 0.0) continue;
      const double f = c.w[j * K::N + i] / nd.m;
      nd.vx += f * J.x();
      nd.vy += f * J.y();
    }
}

// Gauss-Seidel over the points until the largest velocity change of a sweep is below 1e-5 of the
// bodies' speed; the bodies' forces are minus the impulses they gave.
template <class K>
void Simulation::solve_contact_points() {
  const double dt = dt_s_;
  const size_t nb = bodies_.size();
  const GridNode* grid = g_.node.data();
  const size_t NY = size_t(g_.NY);
  double vscale = 1e-3;
  for (const auto& s : bodies_) vscale = std::max(vscale, s.velocity_m_s.norm());
  const double tol = 1e-5 * vscale;
  constexpr int kMaxSweeps = 200;
  int sweep = 0;
  double residual = 0.0;
  for (; sweep < kMaxSweeps; ++sweep) {
    residual = 0.0;
    for (ContactPoint& c : contacts_) {
      double vx = 0.0, vy = 0.0;
      for (int j = 0; j < K::N; ++j)
        for (int i = 0; i < K::N; ++i) {
          const GridNode& nd = grid[c.base + size_t(j) + size_t(i) * NY];
          const double w = c.w[j * K::N + i];
          vx += w * nd.vx;
          vy += w * nd.vy;
        }
      const Vec2 rel = Vec2(vx, vy) - c.vb, t = c.tangent();
      const double meff = 1.0 / c.inv_meff;
      // normal: approach no faster than closes the gap in this step; impulses only push
      const double vn = rel.dot(c.n), target = -std::max(c.gap_m, 0.0) / dt;
      const double jn = std::max(0.0, c.jn + meff * (target - vn));
      // tangential: stop the slip, within the Coulomb cone of the normal impulse
      const double jt = std::clamp(c.jt - meff * rel.dot(t), -c.mu * jn, c.mu * jn);
      const Vec2 J = (jn - c.jn) * c.n + (jt - c.jt) * t;
      c.jn = jn;
      c.jt = jt;
      if (J.x() == 0.0 && J.y() == 0.0) continue;
      residual = std::max(residual, J.norm() * c.inv_meff);
      apply_contact_impulse<K>(c, J);
    }
    if (residual <= tol) break;
  }
  std::vector<Vec2> impulse(nb, Vec2(0.0, 0.0));
  std::vector<double> angular(nb, 0.0);
  for (const ContactPoint& c : contacts_) {
    impulse[c.body] += c.impulse();
    const Vec2 r = Vec2(p_.x[c.particle], p_.y[c.particle]) - bodies_[c.body].position_m, J = c.impulse();
    angular[c.body] += r.x() * J.y() - r.y() * J.x();
  }
  for (size_t b = 0; b < nb; ++b) {
    bodies_[b].force_N_per_m = -impulse[b] / dt;
    bodies_[b].torque_N = -angular[b] / dt;
  }
  stats_.contact_points = int64_t(contacts_.size());
  stats_.contact_sweeps = std::min(sweep + 1, kMaxSweeps);
  stats_.contact_residual_m_s = residual;
  stats_.contact_converged = residual <= tol;
}

// Domain walls act on the nodes on and beyond each boundary line (walls lie on node lines, so
// node contact is exact for them).
void Simulation::contact_walls() {
  const double dt = dt_s_;
  const bool wall_friction = scene_.effects.wall_friction;
  auto wall = [&](const Wall& w, int side, int i0, int i1, int j0, int j1, Vec2 n) {
    Vec2 impulse(0.0, 0.0);
    if (w.kind != Wall::Kind::Open)
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          GridNode& node = g_.node[g_.index(i, j)];
          if (node.m <= 0.0) continue;
          Vec2 v(node.vx, node.vy);
          const Vec2 before = v;
          if (w.kind == Wall::Kind::Sticky)
            v.setZero();
          else
            contact(v, Vec2(0.0, 0.0), n,
                    w.kind == Wall::Kind::Friction && wall_friction ? w.friction : 0.0);
          impulse += node.m * (v - before);
          node.vx = v.x();
          node.vy = v.y();
        }
    wall_forces_[side] = -impulse / dt;
  };
  const int P = Grid::kPad, nx = g_.nx, ny = g_.ny;
  wall(scene_.walls.left, 0, -P, 0, -P, ny + P, Vec2(1, 0));
  wall(scene_.walls.right, 1, nx, nx + P, -P, ny + P, Vec2(-1, 0));
  wall(scene_.walls.bottom, 2, -P, nx + P, -P, 0, Vec2(0, 1));
  wall(scene_.walls.top, 3, -P, nx + P, ny, ny + P, Vec2(0, -1));
}

// Friction of the front and back walls of a quasi-2D channel (scene walls.front_back): a point
// pressing on them with sigma_zz < 0 loses up to dt 2 mu |sigma_zz| V / (gap m) of its in-plane
// speed, against its motion (Coulomb: it may stop, never reverse). Applied to the points' velocities
// after G2P, so the next P2G carries the loss and the FLIP update does not add it back.
void Simulation::front_back_friction() {
  const FrontBackWalls& w = scene_.walls.front_back;
  const double k = 2.0 * w.friction * dt_s_ / w.gap_m;
  auto& P = p_;
  const Vec2 impulse = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<size_t>(0, P.size(), kGrain), Vec2(0.0, 0.0),
      [&](const tbb::blocked_range<size_t>& r, Vec2 sum) {
        for (size_t p = r.begin(); p < r.end(); ++p) {
          const double sigma_zz = double(P.szz[p]) - P.pressure[p];
          const double speed = std::hypot(P.vx[p], P.vy[p]);
          if (sigma_zz >= 0.0 || speed == 0.0) continue;
          const double keep = 1.0 - std::min(speed, k * -sigma_zz * P.volume[p] / P.mass[p]) / speed;
          sum -= double(P.mass[p]) * (1.0 - keep) * Vec2(P.vx[p], P.vy[p]);
          P.vx[p] *= keep;
          P.vy[p] *= keep;
        }
        return sum;
      },
      [](const Vec2& a, const Vec2& b) { return Vec2(a + b); });
  stats_.front_back_impulse_N_s_per_m = impulse;
}

// The default G2P (quadratic B-splines, FLIP) four points at a time, a point per lane: the
// weights and everything after the gather (affine matrix, FLIP update, advection, the margins).
// Only the gather from each point's nine nodes runs a point at a time (4-wide over the node's
// fields, as in g2p_range). Every point of the range takes this path, a range's last group with
// its empty lanes filled by its last point, so a point's bits do not depend on how the range
// was split among threads. Returns `end`, or `begin` to leave the range to g2p_range's loop.
size_t Simulation::g2p_quadratic_by_four(size_t begin, size_t end, G2PLocal& loc) {
#if !defined(__AVX__)
  return begin;  // _mm256_floor_pd: built without AVX, g2p_range's loop does it all
#else
  using V = Vec4d;
  constexpr size_t kMaxBodies = 8;  // more bodies (rare): g2p_range's loop
  const size_t nb = bodies_.size();
  if (nb > kMaxBodies) return begin;
  const double dx = g_.dx, ih = 1.0 / dx, dt = dt_s_, alpha = scene_.solver.flip_blend;
  const double sc = QuadraticKernel::inv_D(ih);
  const size_t NY = size_t(g_.NY);
  const GridNode* const grid = g_.node.data();
  // each body's box in world coordinates, a little wider: only a lane inside one goes on to the
  // safety net's own test
  double box[kMaxBodies][4];
  for (size_t b = 0; b < nb; ++b) {
    const BodyState& s = bodies_[b];
    const double pad = 1e-6 * dx;
    box[b][0] = s.position_m.x() + s.lo_m.x() - pad, box[b][1] = s.position_m.y() + s.lo_m.y() - pad;
    box[b][2] = s.position_m.x() + s.hi_m.x() + pad, box[b][3] = s.position_m.y() + s.hi_m.y() + pad;
  }
  const V zero = {0, 0, 0, 0}, lo = zero - dx, hx = zero + (scene_.domain.width_m + dx),
          hy = zero + (scene_.domain.height_m + dx);
  auto& P = p_;
  double *const X = P.x.data(), *const Y = P.y.data(), *const VX = P.vx.data(), *const VY = P.vy.data();
  const uint16_t* const home = home_strip_.data();

  // count: a std::integral_constant 4 for a full group (compiled apart: no lane tests), a size_t
  // for the last
  auto group = [&](const size_t p, const auto count) {
    auto load = [&](const double* a) {
      if (count == 4) return load4(a + p);
      V v;
      for (size_t l = 0; l < 4; ++l) v[l] = a[p + std::min(l, size_t(count) - 1)];
      return v;
    };
    auto store = [&](auto* a, const V& v) {
      using T = std::remove_reference_t<decltype(*a)>;
      if (count == 4) return store4(a + p, v);
      for (size_t l = 0; l < count; ++l) a[p + l] = T(v[l]);
    };
    const V xp = load(X), yp = load(Y);
    V wx[3], wy[3], wxd[3], wyd[3];
    int bx[4], by[4];
    const V bxd = quadratic_weights_by_four(xp, ih, wx, bx), byd = quadratic_weights_by_four(yp, ih, wy, by);
    for (int a = 0; a < 3; ++a) {
      wxd[a] = wx[a] * ((bxd + double(a)) * dx - xp);
      wyd[a] = wy[a] * ((byd + double(a)) * dx - yp);
    }
    // the gather of [vx vy vx0 vy0], as in g2p_range: per row R = sum wx g, S = sum wx dxp g
    V vel[4], ax[4], ay[4];
    for (int l = 0; l < 4; ++l) {
      V vl = zero, axl = zero, ayl = zero;
      const GridNode* const column0 = grid + Grid::index(bx[l], by[l], NY);
      const GridNode* const column[3] = {column0, column0 + NY, column0 + 2 * NY};
      for (int b = 0; b < 3; ++b) {
        V R = zero, S = zero;
        for (int a = 0; a < 3; ++a) {
          const V g = four_at(&column[a][b].vx);
          R += lane(wx[a], l) * g;
          S += lane(wxd[a], l) * g;
        }
        vl += lane(wy[b], l) * R;
        axl += lane(wy[b], l) * S;
        ayl += lane(wyd[b], l) * R;
      }
      vel[l] = vl, ax[l] = axl, ay[l] = ayl;
    }
    // back to a point per lane
    const V vx = {vel[0][0], vel[1][0], vel[2][0], vel[3][0]}, vy = {vel[0][1], vel[1][1], vel[2][1], vel[3][1]};
    const V ox = {vel[0][2], vel[1][2], vel[2][2], vel[3][2]}, oy = {vel[0][3], vel[1][3], vel[2][3], vel[3][3]};
    store(P.c00.data(), V{ax[0][0], ax[1][0], ax[2][0], ax[3][0]} * sc);
    store(P.c10.data(), V{ax[0][1], ax[1][1], ax[2][1], ax[3][1]} * sc);
    store(P.c01.data(), V{ay[0][0], ay[1][0], ay[2][0], ay[3][0]} * sc);
    store(P.c11.data(), V{ay[0][1], ay[1][1], ay[2][1], ay[3][1]} * sc);
    V x = xp + dt * vx, y = yp + dt * vy;
    V ux = vx + alpha * (load(VX) - ox), uy = vy + alpha * (load(VY) - oy);
    // the safety net (g2p_range's), for the lanes in a body's box
    for (size_t b = 0; b < nb; ++b) {
      const auto in = (x >= box[b][0]) & (y >= box[b][1]) & (x <= box[b][2]) & (y <= box[b][3]);
      for (size_t l = 0; l < count; ++l) {
        if (!in[l]) continue;
        Vec2 xl(x[l], y[l]);
        if (!put_back_on_surface(bodies_[b], scene_.bodies[b].shape, dx, xl)) continue;
        ++loc.projected;
        x[l] = xl.x(), y[l] = xl.y();
      }
    }
    // the grid margin bounds where a point may go (g2p_range's std::max / std::min)
    auto out = x < lo;
    x = out ? lo : x, ux = out ? (ux < 0.0 ? zero : ux) : ux;
    out = x > hx;
    x = out ? hx : x, ux = out ? (0.0 < ux ? zero : ux) : ux;
    out = y < lo;
    y = out ? lo : y, uy = out ? (uy < 0.0 ? zero : uy) : uy;
    out = y > hy;
    y = out ? hy : y, uy = out ? (0.0 < uy ? zero : uy) : uy;
    store(X, x);
    store(Y, y);
    store(VX, ux);
    store(VY, uy);
    const V speed2 = fma4(ux, ux, uy * uy);  // as g2p_range's: the largest sets the next dt
    for (size_t l = 0; l < count; ++l) loc.vmax2 = std::max(loc.vmax2, speed2[l]);
    // the next P2G's stencil base, by its own arithmetic: still in the point's strip window?
    V wn[3];
    int unused[4];
    const __m128i base = _mm256_cvttpd_epi32((__m256d)quadratic_weights_by_four(x, ih, wn, unused));
    __m128i strip;
    if (count == 4) {
      strip = _mm_cvtepu16_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(home + p)));
    } else {
      int h[4];
      for (size_t l = 0; l < 4; ++l) h[l] = home[p + std::min(l, size_t(count) - 1)];
      strip = _mm_loadu_si128(reinterpret_cast<const __m128i*>(h));
    }
    loc.strayed |= !StripWindow<QuadraticKernel>::holds4(strip, base);
  };
  size_t p = begin;
  for (; p + 4 <= end; p += 4) group(p, std::integral_constant<size_t, 4>());
  if (p < end) group(p, end - p);
  return end;
#endif
}

template <class K, bool Flip>
void Simulation::g2p_range(size_t begin, size_t end, G2PLocal& loc) {
  const double dx = g_.dx, inv_dx = 1.0 / dx, dt = dt_s_, alpha = scene_.solver.flip_blend;
  const double Dinv = K::inv_D(inv_dx);
  const double xmax = scene_.domain.width_m, ymax = scene_.domain.height_m;
  const size_t nb = bodies_.size();
  auto& P = p_;
  if constexpr (std::is_same_v<K, QuadraticKernel> && Flip)
    if (by_four_) begin = g2p_quadratic_by_four(begin, end, loc);
  const size_t NY = size_t(g_.NY);
  for (size_t p = begin; p < end; ++p) {
    double wx[K::N], wy[K::N], dwx[K::N], dwy[K::N];
    const double xp = P.x[p], yp = P.y[p];
    const int bx = K::weights(xp * inv_dx, wx, dwx, inv_dx);
    const int by = K::weights(yp * inv_dx, wy, dwy, inv_dx);
    double vx = 0, vy = 0, b00 = 0, b01 = 0, b10 = 0, b11 = 0, ox = 0, oy = 0;
    if constexpr (K::mls && Flip) {
      // The default path (FLIP, MLS kernels): a node's last four fields g = [vx vy vx0 vy0] are
      // read 4-wide. dxp varies along a row only and dyp down a column only, so each row b sums
      // R_b = sum_a wx_a g and S_b = sum_a wx_a dxp_a g (two FMAs a node), and the particle takes
      // [vx vy ox oy] = sum_b wy_b R_b, [b00 b10] = sum_b wy_b S_b, [b01 b11] = sum_b wy_b dyp_b R_b.
      // Same sums as the scalar path, associated differently (round-off; README, Performance).
      double wxd[K::N];
      for (int a = 0; a < K::N; ++a) wxd[a] = wx[a] * ((bx + a) * dx - xp);
      Vec4d vel = {0, 0, 0, 0}, ax = {0, 0, 0, 0}, ay = {0, 0, 0, 0};
      for (int b = 0; b < K::N; ++b) {
        const GridNode* row = &g_.node[g_.index(bx, by + b)];
        Vec4d R = {0, 0, 0, 0}, S = {0, 0, 0, 0};
        for (int a = 0; a < K::N; ++a) {
          const Vec4d g = four_at(&row[a * NY].vx);
          R += wx[a] * g;
          S += wxd[a] * g;
        }
        vel += wy[b] * R;
        ax += wy[b] * S;
        ay += (wy[b] * ((by + b) * dx - yp)) * R;
      }
      vx = vel[0], vy = vel[1], ox = vel[2], oy = vel[3];
      b00 = ax[0], b10 = ax[1], b01 = ay[0], b11 = ay[1];
    } else {
      for (int b = 0; b < K::N; ++b) {
        const GridNode* row = &g_.node[g_.index(bx, by + b)];
        const double dyp = (by + b) * dx - yp;
        for (int a = 0; a < K::N; ++a) {
          const double w = wx[a] * wy[b];
          const GridNode& n = row[a * NY];
          const double gvx = n.vx, gvy = n.vy;
          vx += w * gvx;
          vy += w * gvy;
          if constexpr (Flip) {
            ox += w * n.vx0;
            oy += w * n.vy0;
          }
          if constexpr (K::mls) {
            const double dxp = (bx + a) * dx - xp;
            b00 += w * gvx * dxp;
            b01 += w * gvx * dyp;
            b10 += w * gvy * dxp;
            b11 += w * gvy * dyp;
          } else {
            const double gxw = dwx[a] * wy[b], gyw = wx[a] * dwy[b];
            b00 += gvx * gxw;
            b01 += gvx * gyw;
            b10 += gvy * gxw;
            b11 += gvy * gyw;
          }
        }
      }
    }
    const double sc = K::mls ? Dinv : 1.0;
    P.c00[p] = b00 * sc;
    P.c01[p] = b01 * sc;
    P.c10[p] = b10 * sc;
    P.c11[p] = b11 * sc;
    // positions move with the grid velocity; FLIP keeps part of the particle's own velocity
    Vec2 x(xp + dt * vx, yp + dt * vy), v(vx, vy);
    if constexpr (Flip) v += alpha * Vec2(P.vx[p] - ox, P.vy[p] - oy);
    // the safety net: a particle that still ended inside a body is put back on its surface
    for (size_t b = 0; b < nb; ++b)
      if (put_back_on_surface(bodies_[b], scene_.bodies[b].shape, dx, x)) ++loc.projected;
    // the grid margin bounds where a particle may go; walls normally stop it well before
    if (x.x() < -dx) { x.x() = -dx; v.x() = std::max(v.x(), 0.0); }
    if (x.x() > xmax + dx) { x.x() = xmax + dx; v.x() = std::min(v.x(), 0.0); }
    if (x.y() < -dx) { x.y() = -dx; v.y() = std::max(v.y(), 0.0); }
    if (x.y() > ymax + dx) { x.y() = ymax + dx; v.y() = std::min(v.y(), 0.0); }
    P.x[p] = x.x();
    P.y[p] = x.y();
    P.vx[p] = v.x();
    P.vy[p] = v.y();
    loc.vmax2 = std::max(loc.vmax2, fma1(v.x(), v.x(), v.y() * v.y()));  // as the four-wide path's
    loc.strayed |= !StripWindow<K>::holds(home_strip_[p], K::base(x.x() * inv_dx));
  }
}

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
  std::vector<PlasticityModel<Dilatancy, Rate>> models;  // once per block of points: cheap
  for (const auto& m : materials_) models.push_back({m});
  for (size_t p = begin; p < end; ++p) constitutive_point<Dilatancy, Track, Rate>(p, models[p_.material[p]]);
}

// G2P and the constitutive update. Fused, each block of particles gets both while it is in cache
// (the same arithmetic, so the same bits; no faster on its own, README); apart
// when the front/back walls' friction must act between them, or for a profile of each phase.
void Simulation::particles_update(bool g2p, bool constitutive) {
  const size_t chunks = (p_.size() + kGrain - 1) / kGrain;
  // one G2P tally per fixed chunk, summed in order
  std::vector<G2PLocal> locals(g2p ? chunks : 0);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    const size_t begin = c * kGrain, end = std::min(p_.size(), begin + kGrain);
    for (size_t b = begin; b < end; b += kFusedBlock) {
      const size_t e = std::min(end, b + kFusedBlock);
      if (g2p) (this->*g2p_range_)(b, e, locals[c]);
      if (constitutive) (this->*constitutive_range_)(b, e);
    }
  });
  if (!g2p) return;
  stats_.projected_particles = 0;
  double vmax2 = 0.0;
  strayed_ = false;
  for (const G2PLocal& loc : locals) {
    strayed_ |= loc.strayed;
    stats_.projected_particles += loc.projected;
    vmax2 = std::max(vmax2, loc.vmax2);
  }
  stats_.max_speed_m_s = std::sqrt(vmax2);
}

// Prescribed degrees of freedom follow the motion; free ones move with the velocity the contact
// left them (respond_free_body), and must stay inside the domain.
void Simulation::advance_bodies() {
  const double t = t_s_ + dt_s_;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const Body& body = scene_.bodies[b];
    const BodyDynamics& d = body.dynamics;
    BodyState& s = bodies_[b];
    if (!d.any_free()) {
      s.position_m = body.start_m + motion_displacement_m(body.motion, t);
      s.velocity_m_s = motion_velocity_m_s(body.motion, t);
    } else {
      const Vec2 at = body.start_m + motion_displacement_m(body.motion, t), v = motion_velocity_m_s(body.motion, t);
      s.position_m.x() = d.free_x ? s.position_m.x() + dt_s_ * s.velocity_m_s.x() : at.x();
      s.position_m.y() = d.free_y ? s.position_m.y() + dt_s_ * s.velocity_m_s.y() : at.y();
      if (!d.free_x) s.velocity_m_s.x() = v.x();
      if (!d.free_y) s.velocity_m_s.y() = v.y();
    }
    if (!s.turns) continue;
    if (d.free_angle) {
      set_body_angle(b, s.angle_rad + dt_s_ * s.omega_rad_s);
    } else {
      set_body_angle(b, body.start_angle_rad + motion_rotation_rad(body.motion, t));
      s.omega_rad_s = motion_angular_velocity_rad_s(body.motion, t);
    }
  }
  for (size_t b = 0; b < bodies_.size(); ++b) {
    if (!scene_.bodies[b].dynamics.any_free()) continue;
    const BodyState& s = bodies_[b];
    const Vec2 lo = s.position_m + s.lo_m, hi = s.position_m + s.hi_m;
    const auto& dom = scene_.domain;
    if (!(lo.x() >= 0.0 && lo.y() >= 0.0 && hi.x() <= dom.width_m && hi.y() <= dom.height_m))
      throw std::runtime_error("body '" + scene_.bodies[b].name + "' left the domain at t = " + std::to_string(t) +
                               " s (its box [" + std::to_string(lo.x()) + ", " + std::to_string(lo.y()) + "] to [" +
                               std::to_string(hi.x()) + ", " + std::to_string(hi.y()) + "] m)");
  }
}

void Simulation::set_body_angle(size_t b, double angle_rad) {
  BodyState& s = bodies_[b];
  s.angle_rad = angle_rad;
  if (!s.turns) return;
  s.cos_a = std::cos(angle_rad);
  s.sin_a = std::sin(angle_rad);
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (const Vec2& c : body_corners_m_[b]) {
    const Vec2 w = s.to_world(c);
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
  // a 64-gon's sides lie inside its circle by at most 0.12% of the radius
  const double pad = 0.002 * (hi - lo).maxCoeff();
  s.lo_m = lo - Vec2::Constant(pad);
  s.hi_m = hi + Vec2::Constant(pad);
}

// Two-way coupling of a body's free degrees of freedom u = (vx, vy, omega). The contact has just
// held each node against the body moving at u0 and given the media `impulse` (and `angular`, about
// the body's origin). Had the body moved at u0 + du, each held node would have changed by a further
// P G du (P its projector, G du the body's velocity change at the node), the media gaining K du
// with K = sum m G^T P G. The body's equation, M du = -impulse + dt F_applied + dt M g - K du, is
// solved for du over the free degrees of freedom, and each node takes its P G du: the media gain
// exactly what the body loses, so media + body change momentum only by gravity and the applied
// loads, and a body light against the media it holds moves with them instead of overshooting
// (K in the denominator), a heavy one barely responds (M).
void Simulation::respond_free_body(size_t b, Vec2& impulse, double& angular) {
  const BodyDynamics& d = scene_.bodies[b].dynamics;
  BodyState& s = bodies_[b];
  const double dt = dt_s_, dx = g_.dx;
  const auto [i0, i1, j0, j1] = body_node_box(s, g_);
  const size_t width = size_t(i1 - i0 + 1);
  const std::vector<Vec3>& held = held_[b];
  auto jacobian = [](const Vec2& r) {  // body velocity change at r per du
    Eigen::Matrix<double, 2, 3> G;
    G << 1.0, 0.0, -r.y(), 0.0, 1.0, r.x();
    return G;
  };
  auto projector = [](const Vec3& h) { return (Eigen::Matrix2d() << h.x(), h.y(), h.y(), h.z()).finished(); };
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const Vec3& h = held[size_t(j - j0) * width + size_t(i - i0)];
      if (h.isZero()) continue;
      const auto G = jacobian(Vec2(i * dx, j * dx) - s.position_m);
      A += g_.node[g_.index(i, j)].m * (G.transpose() * projector(h) * G);
    }
  A(0, 0) += d.mass_kg_per_m;
  A(1, 1) += d.mass_kg_per_m;
  A(2, 2) += d.inertia_kg_m;
  const Vec2 load = d.applied_force_N_per_m + d.mass_kg_per_m * gravity_;
  const Vec3 rhs(dt * load.x() - impulse.x(), dt * load.y() - impulse.y(), dt * d.applied_torque_N - angular);
  // the free degrees of freedom only: a prescribed one does not change here
  const bool free[3] = {d.free_x, d.free_y, d.free_angle};
  int index[3], nf = 0;
  for (int k = 0; k < 3; ++k)
    if (free[k]) index[nf++] = k;
  Eigen::MatrixXd Af(nf, nf);
  Eigen::VectorXd bf(nf);
  for (int a = 0; a < nf; ++a) {
    bf[a] = rhs[index[a]];
    for (int c = 0; c < nf; ++c) Af(a, c) = A(index[a], index[c]);
  }
  const Eigen::VectorXd x = Af.ldlt().solve(bf);  // symmetric positive definite: mass > 0
  Vec3 du(0.0, 0.0, 0.0);
  for (int a = 0; a < nf; ++a) du[index[a]] = x[a];
  // the held nodes follow the body's change
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const Vec3& h = held[size_t(j - j0) * width + size_t(i - i0)];
      if (h.isZero()) continue;
      const Vec2 r = Vec2(i * dx, j * dx) - s.position_m;
      const Vec2 dv = projector(h) * (jacobian(r) * du);
      GridNode& n = g_.node[g_.index(i, j)];
      n.vx += dv.x();
      n.vy += dv.y();
      const Vec2 dp = n.m * dv;
      impulse += dp;
      angular += r.x() * dp.y() - r.y() * dp.x();
    }
  s.velocity_m_s += du.head<2>();
  s.omega_rad_s += du.z();
}

// Physically reorder particle arrays by strip, then by stencil row and column within it, so P2G and
// G2P walk memory in order, each strip's points are one range (strip_start_) and points with the
// same stencil are consecutive (P2G's StencilRun).
template <class K>
void Simulation::reorder_particles() {
  using W = StripWindow<K>;
  homes_stale_ = strayed_ = false;
  const size_t n = p_.size();
  const double inv = 1.0 / g_.dx;
  const int strips = W::count(g_.nx), rows = g_.ny + 2 * Grid::kPad + 1;
  const size_t strip_keys = size_t(rows) * W::width;
  std::vector<uint32_t> key(n), start(size_t(strips) * strip_keys + 1, 0), perm(n);
  const tbb::blocked_range<size_t> all(0, n, size_t(1) << 14);
  tbb::parallel_for(all, [&](const auto& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const int base = K::base(p_.x[i] * inv), strip = W::of_base(base, strips);
      const int column = std::clamp(base - W::width * (strip - 1), 0, W::width - 1);
      const int cy = std::clamp(K::base(p_.y[i] * inv) + Grid::kPad, 0, rows - 1);
      key[i] = uint32_t((size_t(strip) * rows + cy) * W::width + column);
    }
  });
  for (size_t i = 0; i < n; ++i) ++start[key[i] + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  strip_start_.resize(size_t(strips) + 1);
  for (int s = 0; s <= strips; ++s) strip_start_[size_t(s)] = start[size_t(s) * strip_keys];
  set_home_strips();
  for (size_t i = 0; i < n; ++i) perm[start[key[i]]++] = uint32_t(i);
  // the contact list (kept for the next step's warm start) follows its particles
  if (!contacts_.empty()) {
    for (size_t i = 0; i < n; ++i) key[perm[i]] = uint32_t(i);
    for (auto& c : contacts_) c.particle = key[c.particle];
    std::sort(contacts_.begin(), contacts_.end(), [](const ContactPoint& a, const ContactPoint& b) {
      return a.particle != b.particle ? a.particle < b.particle : a.body < b.body;
    });
  }
  // One gather buffer per element type: each array swaps its storage into it and the old storage
  // takes the next array. A fresh buffer per array page-faulted ~15 MB each at 1.84M points.
  std::vector<double> buffer_f64;
  std::vector<float> buffer_f32;
  std::vector<uint8_t> buffer_u8;
  p_.for_each_array([&](const char*, auto& a) {
    using T = typename std::decay_t<decltype(a)>::value_type;
    if (a.empty()) return;
    auto& buffer = [&]() -> std::vector<T>& {
      if constexpr (std::is_same_v<T, double>) return buffer_f64;
      else if constexpr (std::is_same_v<T, float>) return buffer_f32;
      else return buffer_u8;
    }();
    buffer.resize(n);
    tbb::parallel_for(all, [&](const auto& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) buffer[i] = a[perm[i]];
    });
    a.swap(buffer);
  });
}

template <class K>
bool Simulation::strips_hold_for() const {
  if (homes_stale_) return false;
  const double inv_dx = 1.0 / g_.dx;
  for (size_t p = 0; p < p_.size(); ++p)
    if (!StripWindow<K>::holds(home_strip_[p], K::base(p_.x[p] * inv_dx))) return false;
  return true;
}

void Simulation::set_home_strips() {
  home_strip_.resize(p_.size());
  for (size_t s = 0; s + 1 < strip_start_.size(); ++s)
    std::fill(home_strip_.begin() + strip_start_[s], home_strip_.begin() + strip_start_[s + 1], uint16_t(s));
}

namespace {

constexpr char kCheckpointMagic[8] = {'F', 'U', 'R', 'R', 'O', 'W', 'C', 'K'};
// 2: node-indexed state (cell-fraction contact marks, particle contacts' stencil base) in the
// column-major node order; version 1 (row-major) is still read and renumbered.
// 3: P2G's strip ranges (the points' home strips). Versions 1 and 2 are read and the points sorted
// into strips again before the next step.
constexpr uint32_t kCheckpointVersion = 4;  // 4: bodies carry an angle, angular velocity and torque

template <class T> void put(std::ostream& out, const T& v) {
  static_assert(std::is_trivially_destructible_v<T> && !std::is_pointer_v<T>);  // plain values (Eigen's fixed-size too)
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T> void put_vector(std::ostream& out, const std::vector<T>& v) {
  static_assert(std::is_trivially_destructible_v<T> && !std::is_pointer_v<T>);  // plain values (Eigen's fixed-size too)
  put(out, uint64_t(v.size()));
  out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
}

// Reads what put/put_vector wrote; every failure names the file and the item.
struct Reader {
  std::istream& in;
  const std::string& what;
  [[noreturn]] void fail(const std::string& item, const std::string& why) const {
    throw std::runtime_error(what + ": " + item + ": " + why);
  }
  template <class T> T get(const std::string& item) {
    T v;
    if (!in.read(reinterpret_cast<char*>(&v), sizeof v)) fail(item, "file ends early");
    return v;
  }
  // `expected`: the element count this simulation has (SIZE_MAX: any)
  template <class T> void get_vector(std::vector<T>& v, const std::string& item, size_t expected = SIZE_MAX) {
    const uint64_t n = get<uint64_t>(item);
    if (expected != SIZE_MAX && n != expected)
      fail(item, std::to_string(n) + " values where this scene has " + std::to_string(expected));
    if (n > (uint64_t(1) << 40)) fail(item, "implausible length " + std::to_string(n));
    v.resize(size_t(n));
    if (!in.read(reinterpret_cast<char*>(v.data()), std::streamsize(n * sizeof(T)))) fail(item, "file ends early");
  }
};

}  // namespace

struct BodyStateV3 {  // a body's record before bodies could turn (checkpoint versions 1 to 3)
  Vec2 position_m, velocity_m_s, force_N_per_m, lo_m, hi_m;
};

void Simulation::save_state(std::ostream& out, uint32_t version) const {
  if (version == 0) version = kCheckpointVersion;
  if (version < 2 || version > kCheckpointVersion)
    throw std::invalid_argument("save_state: writes versions 2 to " + std::to_string(kCheckpointVersion));
  out.write(kCheckpointMagic, sizeof kCheckpointMagic);
  put(out, version);
  put(out, uint64_t(p_.size()));
  p_.for_each_array([&](const char* name, const auto& a) {
    put(out, uint32_t(sizeof(a[0])));
    put(out, uint32_t(std::strlen(name)));
    out.write(name, std::streamsize(std::strlen(name)));
    put_vector(out, a);
  });
  put(out, t_s_), put(out, dt_s_), put(out, steps_), put(out, stats_), put(out, phase_s_), put(out, wall_forces_);
  if (version >= 4) {
    put_vector(out, bodies_);
  } else {
    std::vector<BodyStateV3> old;
    for (const BodyState& b : bodies_) old.push_back({b.position_m, b.velocity_m_s, b.force_N_per_m, b.lo_m, b.hi_m});
    put_vector(out, old);
  }
  put(out, uint64_t(touched_.size()));
  for (const auto& t : touched_) put_vector(out, t);
  put_vector(out, contacts_);
  if (version >= 3) {
    put_vector(out, strip_start_);
    put(out, reorders_);
  }
}

void Simulation::load_state(std::istream& in, const std::string& what) {
  Reader r{in, what};
  char magic[sizeof kCheckpointMagic];
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kCheckpointMagic, sizeof magic) != 0)
    r.fail("header", "not a Furrow checkpoint");
  const auto version = r.get<uint32_t>("version");
  if (version < 1 || version > kCheckpointVersion)
    r.fail("version", std::to_string(version) + ", this build reads 1 to " + std::to_string(kCheckpointVersion));
  const uint64_t n = r.get<uint64_t>("particle count");
  if (n != p_.size())
    r.fail("particle count", std::to_string(n) + " points where this scene seeds " + std::to_string(p_.size()));
  p_.for_each_array([&](const char* name, auto& a) {
    const auto bytes = r.get<uint32_t>(std::string(name) + " element size");
    if (bytes != sizeof(a[0]))
      r.fail(name, std::to_string(bytes) + "-byte values where this build stores " + std::to_string(sizeof(a[0])) +
                       " (written by a build with the other FURROW_FLOAT_STATE)");
    std::string stored(r.get<uint32_t>(std::string(name) + " name length"), '\0');
    if (!in.read(stored.data(), std::streamsize(stored.size())) || stored != name)
      r.fail(name, "found array '" + stored + "' in its place");
    // an array this run does not keep (no output needs it) must be absent in the file too
    r.get_vector(a, name, a.empty() ? 0 : p_.size());
  });
  t_s_ = r.get<double>("time"), dt_s_ = r.get<double>("dt"), steps_ = r.get<int64_t>("steps");
  stats_ = r.get<StepStats>("step statistics"), phase_s_ = r.get<PhaseSeconds>("phase seconds");
  wall_forces_ = r.get<std::array<Vec2, 4>>("wall forces");
  if (version >= 4) {
    r.get_vector(bodies_, "bodies", bodies_.size());
  } else {
    std::vector<BodyStateV3> old;
    r.get_vector(old, "bodies", bodies_.size());
    for (size_t b = 0; b < old.size(); ++b) {
      bodies_[b].position_m = old[b].position_m, bodies_[b].velocity_m_s = old[b].velocity_m_s;
      bodies_[b].force_N_per_m = old[b].force_N_per_m, bodies_[b].lo_m = old[b].lo_m, bodies_[b].hi_m = old[b].hi_m;
    }
  }
  const auto marks = r.get<uint64_t>("contact marks");
  if (marks > bodies_.size()) r.fail("contact marks", std::to_string(marks) + " bodies' marks");
  touched_.resize(size_t(marks));
  for (auto& t : touched_) r.get_vector(t, "contact marks", g_.node.size());
  r.get_vector(contacts_, "contact points");
  for (const auto& c : contacts_)
    if (c.particle >= p_.size() || c.body >= bodies_.size()) r.fail("contact points", "a point out of range");
  if (version == 1) {
    // written with row-major nodes: the node k = j NX + i is now i NY + j
    const size_t NX = size_t(g_.NX), NY = size_t(g_.NY);
    auto column_major = [&](size_t k) { return (k % NX) * NY + k / NX; };
    for (auto& t : touched_) {
      std::vector<uint8_t> by_row = t;
      for (size_t k = 0; k < by_row.size(); ++k) t[column_major(k)] = by_row[k];
    }
    for (auto& c : contacts_) c.base = column_major(c.base);
  }
  if (version >= 3) {
    r.get_vector(strip_start_, "strip ranges", strip_start_.size());
    for (size_t s = 0; s + 1 < strip_start_.size(); ++s)
      if (strip_start_[s] > strip_start_[s + 1]) r.fail("strip ranges", "not in order");
    if (strip_start_.front() != 0 || strip_start_.back() != p_.size()) r.fail("strip ranges", "do not cover the points");
    set_home_strips();
    reorders_ = r.get<Reorders>("reorder counts");
  } else {
    homes_stale_ = true;
  }
  if (in.peek() != std::char_traits<char>::eof()) r.fail("end", "data after the last item");
}

size_t Simulation::state_bytes() const {
  size_t b = 0;
  p_.for_each_array([&](const char*, const auto& a) { b += a.capacity() * sizeof(a[0]); });
  b += g_.node.capacity() * sizeof(GridNode);
  b += strip_start_.capacity() * sizeof(uint32_t) + home_strip_.capacity() * sizeof(uint16_t);
  return b;
}

double Simulation::total_mass() const { return std::accumulate(p_.mass.begin(), p_.mass.end(), 0.0); }

Vec2 Simulation::total_momentum() const {
  Vec2 m(0, 0);
  for (size_t p = 0; p < p_.size(); ++p) m += double(p_.mass[p]) * Vec2(p_.vx[p], p_.vy[p]);
  return m;
}

double Simulation::kinetic_energy() const {
  double e = 0.0;
  for (size_t p = 0; p < p_.size(); ++p) e += 0.5 * p_.mass[p] * (p_.vx[p] * p_.vx[p] + p_.vy[p] * p_.vy[p]);
  return e;
}

ParticleView Simulation::particle_view() const {
  rho_g_cache_.resize(p_.size());
  for (size_t p = 0; p < p_.size(); ++p) rho_g_cache_[p] = materials_[p_.material[p]].rho_g;
  ParticleView v;
  v.count = p_.size();
  v.x_m = p_.x.data();
  v.y_m = p_.y.data();
  v.mass_kg = p_.mass.data();
  v.volume_m2 = p_.volume.data();
  v.vx_m_s = p_.vx.data();
  v.vy_m_s = p_.vy.data();
  v.pressure_Pa = p_.pressure.data();
  v.strain_rate_1_s = track_plastic_ ? p_.strain_rate.data() : nullptr;
  v.plastic_strain = track_plastic_ ? p_.plastic_strain.data() : nullptr;
  v.phi_d = dilatancy_ ? p_.phi_d.data() : nullptr;
  v.grain_density_kg_m3 = rho_g_cache_.data();
  return v;
}

std::vector<BodyOutline> Simulation::body_outlines() const {
  std::vector<BodyOutline> out;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const auto loops = shape_outline(scene_.bodies[b].shape);
    for (size_t k = 0; k < loops.size(); ++k) {
      BodyOutline o;
      o.name = scene_.bodies[b].name + (k ? "#" + std::to_string(k) : "");
      for (const auto& v : loops[k]) o.outline_m.push_back(bodies_[b].position_m + bodies_[b].to_world(v));
      o.position_m = bodies_[b].position_m;
      if (k == 0) o.force_N_per_m = bodies_[b].force_N_per_m;
      out.push_back(o);
    }
  }
  return out;
}

}  // namespace furrow
