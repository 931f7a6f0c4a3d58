// A Simulation's set-up, step() (the algorithm, phase by phase), the grid update, the
// bodies' motion, and what the run reads back. The phases' own files: engine/README.md, "A step,
// phase by phase".
#include "engine/simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <type_traits>

#include "engine/bodies.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/shape_functions.hpp"
#include "engine/simulation_detail.hpp"

namespace furrow {

namespace {

// grid nodes per task of the grid update: 2048 x 40 B = 80 kB, so the 34k nodes
// of the bench bed (dx 5 mm) make 17 tasks; at 16384 they made 3, two threads split them 2:1
// (at 1024, the bench's task ceiling on 16 threads did not move: the bands bound it)
constexpr size_t kGridGrain = 2048;
// particles per task of G2P and the constitutive update: 113 tasks on the 115k bench bed, so
// sixteen threads share them to within a task of 7 (at 4096, 29 tasks of uneven cost: the bench's
// task ceiling gave 11.2x on 16 threads). A multiple of kFusedBlock; the tasks' tallies are a
// count, a flag and maxima, so the bits do not depend on it.
constexpr size_t kG2PGrain = 1024;
// particles G2P and the constitutive update take in turn when fused: their ~20 arrays of a block
// stay in L2 (256 points x 20 x 8 B = 40 kB). Measured alone this gains nothing (README,
// Performance); it is the shape a fused G2P + constitutive + next P2G pass would take.
constexpr size_t kFusedBlock = 256;

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
    body_boundaries_m_.push_back(shape_boundary(b.shape));  // once: a union's contour costs ~10 ms
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
      case ContactMethod::CellFraction:
        contact_ = &Simulation::contact_nodes<true>;
        plan_bands_ = &Simulation::plan_cell_fraction<K>;
        band_sums_ = &Simulation::cell_fraction_band<K>;
        break;
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
    (this->*p2g_)();  // zeroes the grid as it scatters
    lap(phase_s_.p2g);
    const bool walls_first = walls_apart_from_bodies();  // then the walls act in the grid update
    if (plan_bands_ && !bodies_.empty()) {
      // cell_fraction's band sums in the grid update's region where the bodies' boxes are apart
      const bool apart = (this->*plan_bands_)();
      lap(phase_s_.contact);
      grid_and_bands(walls_first, true, apart);
      lap(phase_s_.grid);
      if (!apart) grid_and_bands(false, false, true);
    } else {
      grid_and_bands(walls_first, true, false);
      lap(phase_s_.grid);
    }
    bodies_and_walls(walls_first);
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

// One parallel region: with `grid`, the grid update (momentum to velocity and gravity), column by
// column, each column's wall nodes held as soon as it is done when `walls` (contact_walls); with
// `bands`, cell_fraction's bands (cell_fraction_band), which with `grid` update their own nodes
// first while the columns' tasks skip them. A node's update is its own, so the bits are the same
// whichever task does it.
void Simulation::grid_and_bands(bool walls, bool grid, bool bands) {
  const double gx = gravity_.x() * dt_s_, gy = gravity_.y() * dt_s_;
  const bool flip = flip_;
  const size_t NY = size_t(g_.NY);
  const int per_task = int(std::max<size_t>(1, kGridGrain / NY));
  const int band_tasks = bands ? int(band_tasks_.size()) : 0;
  const int grid_tasks = grid ? (g_.NX + per_task - 1) / per_task : 0;
  if (grid && walls) wall_impulse_.resize(size_t(g_.NX));
  // the bodies' boxes (apart) from the bottom: the rows a column's task leaves to the bands
  std::vector<const FieldPlan*> boxes;
  if (grid && bands)
    for (const FieldPlan& p : field_plans_) boxes.push_back(&p);
  std::sort(boxes.begin(), boxes.end(), [](const FieldPlan* a, const FieldPlan* b) { return a->j0 < b->j0; });
  // the bands spread evenly over the tasks (band k at task k n / bands): the range is split in
  // halves, so each thread starts on a band and the columns' small tasks even out the rest
  const int tasks = band_tasks + grid_tasks;
  constexpr int kColumns = std::numeric_limits<int>::max();
  std::vector<int> task_of(size_t(tasks), kColumns);  // band k as -1 - k, else the columns' task
  for (int k = 0; k < band_tasks; ++k) task_of[size_t(int64_t(k) * tasks / band_tasks)] = -1 - k;
  for (int t = 0, c = 0; t < tasks; ++t)
    if (task_of[size_t(t)] == kColumns) task_of[size_t(t)] = c++;
  for_tasks(task_log_, grid ? StepPhase::Grid : StepPhase::Contact, size_t(tasks), [&](size_t t) {
    const int task = task_of[t];
    if (task < 0) {
      (this->*band_sums_)(size_t(-1 - task), grid);
      return;
    }
    const int c0 = task * per_task, c1 = std::min(g_.NX, c0 + per_task);
    for (int c = c0; c < c1; ++c) {
      GridNode* const column = g_.node.data() + size_t(c) * NY;
      GridNode* from = column;
      const int i = c - Grid::kPad;
      for (const FieldPlan* box : boxes)
        if (box->i0 <= i && i <= box->i1) {
          update_nodes(from, column + (box->j0 + Grid::kPad), gx, gy, flip);
          from = column + (box->j1 + Grid::kPad + 1);
        }
      update_nodes(from, column + NY, gx, gy, flip);
      if (walls) walls_on_column(i, wall_impulse_[size_t(c)]);
    }
  });
  if (grid && walls) sum_wall_impulses();
}

// G2P and the constitutive update. Fused, each block of particles gets both while it is in cache
// (the same arithmetic, so the same bits; no faster on its own, README); apart
// when the front/back walls' friction must act between them, or for a profile of each phase.
void Simulation::particles_update(bool g2p, bool constitutive) {
  static_assert(kG2PGrain % kFusedBlock == 0, "a task's blocks are those of one pass");
  const size_t chunks = (p_.size() + kG2PGrain - 1) / kG2PGrain;
  // one G2P tally per fixed chunk, summed in order
  std::vector<G2PLocal> locals(g2p ? chunks : 0);
  for_tasks(task_log_, StepPhase::G2PConstitutive, chunks, [&](size_t c) {
    const size_t begin = c * kG2PGrain, end = std::min(p_.size(), begin + kG2PGrain);
    for (size_t b = begin; b < end; b += kFusedBlock) {
      const size_t e = std::min(end, b + kFusedBlock);
      if (g2p) (this->*g2p_range_)(b, e, locals[c]);
      if (constitutive) (this->*constitutive_range_)(b, e);
    }
  });
  if (!g2p) return;
  stats_.projected_particles = 0;
  double vmax2 = 0.0, dy_max_m = 0.0;
  strayed_ = false;
  for (const G2PLocal& loc : locals) {
    strayed_ |= loc.strayed;
    stats_.projected_particles += loc.projected;
    vmax2 = std::max(vmax2, loc.vmax2);
    dy_max_m = std::max(dy_max_m, loc.dy_max_m);
  }
  drift_y_m_ += dy_max_m;
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
    const auto& loops = body_boundaries_m_[b];
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
