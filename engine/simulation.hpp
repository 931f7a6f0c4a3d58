// Explicit plane-strain MPM over an immutable Scene. One step reads like the algorithm:
//   particles_to_grid (zeroing the grid as it goes) -> grid_and_bands (the grid update, with the
//   walls no body reaches and cell_fraction's band sums) -> bodies_and_walls
//   -> grid_to_particles -> constitutive_update -> advance_bodies
// Particles and grid are structures of arrays; the shape-function kernel and the material law are
// chosen once per scene (templates), so the hot loops carry no per-particle feature branches.
#pragma once
#include <array>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/fields.hpp"
#include "engine/materials.hpp"
#include "engine/scene/scene.hpp"
#include "engine/task_log.hpp"
#include <tbb/task_arena.h>

namespace furrow {

// Stored precision of each class of particle quantity (measured in README, Performance). The
// arithmetic is double throughout: a value is loaded into a double, updated, and rounded once when
// stored. The CMake option FURROW_FLOAT_STATE (ON by default) stores as float (4 B instead of 8)
// the quantities whose stored rounding cannot accumulate; OFF keeps double (README, "Stored
// precision": perturbed runs of both builds agree within their scatter).
#if FURROW_FLOAT_STATE
using reduced_t = float;
#else
using reduced_t = double;
#endif
using mass_t = reduced_t;      // constant per point: rounded once at seeding, the volume derived from it
using affine_t = reduced_t;    // rebuilt from the grid by every G2P, never accumulated
using stress_t = reduced_t;    // deviatoric: hypoelastic increments of ~1e-5 of it per step, with
                               // rounding of ~6e-8 of it (a random walk); the return clamps it to mu P
using pressure_t = reduced_t;  // recomputed from the volume every step, P = K ln(phi / phi_d)
using rate_t = reduced_t;      // plastic strain rate: an output, recomputed every step
// Kept double: positions and velocities (integrated every step; the media's momentum balances the
// bodies' forces to double round-off), volume (integrated every step, and the pressure is K times
// its log strain: elastic strains are ~1e-3, so float's 6e-8 would be percent-level errors at
// shallow depth), phi_d and plastic strain (integrated every step).

struct Particles {
  std::vector<double> x, y, vx, vy;            // position (m), velocity (m/s)
  std::vector<affine_t> c00, c01, c10, c11;    // affine velocity field = velocity gradient (1/s)
  std::vector<mass_t> mass;                    // kg per metre out of plane
  std::vector<double> volume;                  // m^2 per metre out of plane
  std::vector<stress_t> sxx, syy, sxy, szz;    // deviatoric stress (Pa)
  std::vector<pressure_t> pressure;            // Pa
  std::vector<double> phi_d;                   // DPM dense-state packing; empty without dilatancy
  std::vector<double> plastic_strain;          // only when an output field needs it
  std::vector<rate_t> strain_rate;             // (1/s) only when an output field needs it
  std::vector<uint8_t> material;               // index into Scene::materials
  size_t size() const { return x.size(); }
  // Calls f(name, array) on every per-point array: the one list of them, for what treats them
  // alike (the reorder, the byte count, the stability suite's finiteness check).
  template <class F> void for_each_array(F&& f) { each(*this, f); }
  template <class F> void for_each_array(F&& f) const { each(*this, f); }

 private:
  template <class Self, class F> static void each(Self& p, F& f) {
    f("x", p.x), f("y", p.y), f("vx", p.vx), f("vy", p.vy);
    f("c00", p.c00), f("c01", p.c01), f("c10", p.c10), f("c11", p.c11);
    f("mass", p.mass), f("volume", p.volume);
    f("sxx", p.sxx), f("syy", p.syy), f("sxy", p.sxy), f("szz", p.szz), f("pressure", p.pressure);
    f("phi_d", p.phi_d), f("plastic_strain", p.plastic_strain), f("strain_rate", p.strain_rate);
    f("material", p.material);
  }
};

// One grid node, interleaved so a particle's 3x3 stencil touches few cache lines.
struct GridNode {
  double m;         // mass (kg per metre)
  double vx, vy;    // momentum during transfer, velocity after the grid update
  double vx0, vy0;  // FLIP only: force impulse during transfer, pre-force velocity after
};

// Dense node grid over the domain plus a margin of kPad nodes on every side.
struct Grid {
  static constexpr int kPad = 3;
  int nx = 0, ny = 0;      // cells over the domain
  int NX = 0, NY = 0;      // nodes including padding
  double dx = 0.0;
  std::vector<GridNode> node;
  // Column-major (a column of nodes is contiguous): the particles of a strip, walked row by row,
  // then touch kStripCells + 2 columns each read in order, which the prefetchers follow; row-major,
  // every new row of a strip is a cache miss once the grid is out of cache (README, Performance).
  size_t index(int i, int j) const { return index(i, j, size_t(NY)); }
  // the same with the column length held by the caller (a local the hot loops keep in a register);
  // it is also the step from a node to its neighbour in x
  static size_t index(int i, int j, size_t NY) { return size_t(i + kPad) * NY + size_t(j + kPad); }
  double node_x(size_t k) const { return (int(k / NY) - kPad) * dx; }
  double node_y(size_t k) const { return (int(k % NY) - kPad) * dx; }
};

struct BodyState {
  Vec2 position_m{0, 0};
  Vec2 velocity_m_s{0, 0};
  Vec2 force_N_per_m{0, 0};  // reaction of the media on the body in the last step
  Vec2 lo_m{0, 0}, hi_m{0, 0};  // bounds of the body at its angle, world axes, about position_m
  double angle_rad = 0.0, omega_rad_s = 0.0;  // counter-clockwise, about position_m
  double torque_N = 0.0;  // N m per metre, of the media on the body about position_m, counter-clockwise
  double cos_a = 1.0, sin_a = 0.0;  // of angle_rad
  bool turns = false;  // the body may ever have an angle: contact then works in its frame
  // a point x (world) in the body's frame, and a body-frame direction in world axes
  Vec2 to_body(const Vec2& x) const {
    const Vec2 r = x - position_m;
    return turns ? Vec2(cos_a * r.x() + sin_a * r.y(), -sin_a * r.x() + cos_a * r.y()) : r;
  }
  Vec2 to_world(const Vec2& n) const {
    return turns ? Vec2(cos_a * n.x() - sin_a * n.y(), sin_a * n.x() + cos_a * n.y()) : n;
  }
  // velocity of the body's material at x (world): v + omega z x r
  Vec2 velocity_at(const Vec2& x) const {
    return turns ? Vec2(velocity_m_s.x() - omega_rad_s * (x.y() - position_m.y()),
                        velocity_m_s.y() + omega_rad_s * (x.x() - position_m.x()))
                 : velocity_m_s;
  }
};

struct StepStats {
  int64_t projected_particles = 0;  // particles pushed out of bodies by the safety projection
  double max_speed_m_s = 0.0;
  int64_t contact_points = 0;       // material points in contact with a body (particle contact)
  int contact_sweeps = 0;           // Gauss-Seidel sweeps the contact solve took
  double contact_residual_m_s = 0.0;  // largest velocity correction in the last sweep
  bool contact_converged = true;      // the solve met its tolerance within its sweep limit
  Vec2 front_back_impulse_N_s_per_m{0, 0};  // momentum the front/back walls' friction took this step
};

// Wall-clock seconds spent in each phase of step(), summed over the run (for profiles: where a
// step's time goes; they never feed back into the results).
struct PhaseSeconds {
  double p2g = 0, grid = 0, contact = 0, g2p = 0, constitutive = 0, reorder = 0;
  double g2p_constitutive = 0;  // G2P and constitutive update fused into one pass (the default)
  double total() const { return p2g + grid + contact + g2p + constitutive + g2p_constitutive + reorder; }
};

// A material point near a body's surface and its contact impulses (particle contact).
struct ContactPoint {
  size_t base;            // grid index of the first node of the point's stencil
  double w[16];           // stencil weights, row-major (Kernel::N^2 used)
  Vec2 n;                 // body's outward normal at the point
  Vec2 vb;                // body velocity
  double gap_m;           // surface-to-surface distance (negative: overlap)
  double inv_meff;        // velocity response of the point to a unit impulse there (1/kg)
  double mu;              // Coulomb friction
  double jn = 0, jt = 0;  // accumulated normal and tangential impulses (N s per metre)
  uint32_t particle, body;
  Vec2 tangent() const { return Vec2(-n.y(), n.x()); }
  Vec2 impulse() const { return jn * n + jt * tangent(); }
};

class Simulation {
 public:
  explicit Simulation(const Scene& scene);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  void step();
  bool finished() const;

  const Scene& scene() const { return scene_; }
  const Particles& particles() const { return p_; }
  // tests and initial-condition tweaks only; the next step sorts the points into strips again
  Particles& mutable_particles() {
    homes_stale_ = true;
    return p_;
  }
  const Grid& grid() const { return g_; }
  const std::vector<BodyState>& bodies() const { return bodies_; }
  // walls: reaction force on each wall in the last step (left, right, bottom, top)
  const std::array<Vec2, 4>& wall_forces() const { return wall_forces_; }
  double time_s() const { return t_s_; }
  int64_t step_count() const { return steps_; }
  double last_dt_s() const { return dt_s_; }
  double next_dt_s() const;
  const StepStats& stats() const { return stats_; }
  const PhaseSeconds& phase_seconds() const { return phase_s_; }
  // reorders so far: on schedule (every kReorderSteps) and because a point strayed from its strip
  struct Reorders {
    int64_t scheduled = 0, strayed = 0;
    int64_t by_groups = 0;  // reorders sorted by groups of strips in parallel (of these and any others)
  };
  const Reorders& reorders() const { return reorders_; }
  static constexpr int kReorderSteps = 64;
  // every point's stencil within its home strip's window (what P2G's race-free scatter needs)
  bool strips_hold() const { return (this->*strips_hold_)(); }
  // G2P and the constitutive update as one pass (default) or two (to time each; same results)
  void set_fused_particle_passes(bool fused) { fuse_particle_passes_ = fused; }
  // The default P2G and G2P and NDPM's update four points at a time (the default) or a point at
  // a time: the same bits (tested).
  void set_by_four(bool by_four) { by_four_ = by_four; }
  // Each parallel region of the default path times its tasks into `log` (nullptr: none), for the
  // bench's account of what more threads would give (task_log.hpp). The same results either way.
  void set_task_log(TaskLog* log) { task_log_ = log; }
  double wave_speed_m_s() const { return wave_speed_; }
  // distance travelled by the first moving body (m), for end_displacement and averaging windows
  double lead_body_travel_m() const;

  // Checkpoint: everything a later step depends on (particles in their current order, bodies,
  // time, the dt limiter's last speed, contact warm starts and marks), so a simulation built from
  // the same scene and loaded continues bit-identically. load_state throws std::runtime_error
  // naming `what` when the stream is not a checkpoint of this build and scene size.
  // `version` below the current writes an older layout (2: no strip ranges; 3: bodies without
  // angles; 4: no strip rows), for the tests that check old checkpoints are still read
  void save_state(std::ostream& out, uint32_t version = 0) const;
  void load_state(std::istream& in, const std::string& what);

  // diagnostics
  size_t state_bytes() const;  // particle, grid and sorting arrays actually allocated
  double total_mass() const;
  Vec2 total_momentum() const;
  double kinetic_energy() const;

  ParticleView particle_view() const;
  std::vector<BodyOutline> body_outlines() const;

 private:
  void seed_beds();
  void sample_body_fields();
  void weigh_rim(size_t b);
  template <class Kernel, bool Flip> void particles_to_grid();
  void grid_and_bands(bool walls, bool grid, bool bands);
  bool walls_apart_from_bodies() const;
  void bodies_and_walls(bool walls_done);
  template <class Kernel> void contact_particles();
  template <class Kernel> void find_contact_points();
  template <class Kernel> void solve_contact_points();
  template <class Kernel> void apply_contact_impulse(const ContactPoint& c, const Vec2& J);
  template <bool Fraction> void contact_nodes();
  template <class Kernel> bool plan_cell_fraction();
  template <class Kernel> void cell_fraction_band(size_t task, bool update_nodes);
  void contact_walls();
  void walls_on_column(int i, std::array<Vec2, 4>& impulse);
  void sum_wall_impulses();
  void front_back_friction();
  struct G2PLocal {
    int64_t projected = 0;
    double vmax2 = 0.0;
    double dy_max_m = 0.0;  // largest move in y (strip_rows_of_bases' drift)
    bool strayed = false;  // a point left its strip's window (the step ends with a reorder)
  };
  template <class Kernel, bool Flip> void g2p_range(size_t begin, size_t end, G2PLocal& loc);
  size_t g2p_quadratic_by_four(size_t begin, size_t end, G2PLocal& loc);
  void p2g_strip_quadratic_by_four(int strip);
  template <bool Dilatancy, bool Track, bool Rate> void constitutive_range(size_t begin, size_t end);
  template <bool Dilatancy, bool Track, bool Rate>
  void constitutive_point(size_t p, const PlasticityModel<Dilatancy, Rate>& model);
  template <bool Dilatancy, bool Track> size_t constitutive_by_four(size_t begin, size_t end);
  void particles_update(bool g2p, bool constitutive);
  void advance_bodies();
  void set_body_angle(size_t b, double angle_rad);
  // free bodies: the contact's linearisation in the body's velocity (contact_nodes)
  void respond_free_body(size_t b, Vec2& impulse, double& angular);
  template <class Kernel> void reorder_particles();
  void set_home_strips();

  Scene scene_;
  Particles p_;
  Grid g_;
  std::vector<BodyState> bodies_;
  std::array<Vec2, 4> wall_forces_{Vec2::Zero(), Vec2::Zero(), Vec2::Zero(), Vec2::Zero()};  // Eigen does not zero on {}
  std::vector<std::array<Vec2, 4>> wall_impulse_;  // per node column: what each wall gave it this step
  std::vector<MaterialParams> materials_;
  double t_s_ = 0.0, dt_s_ = 0.0, wave_speed_ = 0.0;
  int64_t steps_ = 0;
  StepStats stats_;
  PhaseSeconds phase_s_;
  Vec2 gravity_{0, 0};
  bool dilatancy_ = false;
  bool flip_ = false;
  bool track_plastic_ = false;
  // P2G's strips (simulation_detail.hpp, StripWindow): the reorder sorts the points by strip, strip s
  // holding points [strip_start_[s], strip_start_[s + 1]) until the next reorder (each point's
  // home strip, home_strip_), and P2G scatters each home strip in two colours without sorting
  // again. G2P reports a point that strayed so far that two strips of a colour could share a node
  // (strayed_) and the step then reorders.
  std::vector<uint32_t> strip_start_;
  std::vector<uint16_t> home_strip_;
  // Within a strip the reorder sorts the points by stencil row: row r of strip s starts at
  // strip_row_start_[s * strip_rows_ + r]. No point has moved more than drift_y_m_ in y since
  // (G2P adds each step's largest move), so a search for the points of a band of y need only walk
  // the rows that band could have held then (strip_rows_of_bases).
  std::vector<uint32_t> strip_row_start_;
  int strip_rows_ = 0;
  double drift_y_m_ = 0.0;
  std::pair<uint32_t, uint32_t> strip_rows_of_bases(int strip, int base_lo, int base_hi) const;
  bool strayed_ = false, homes_stale_ = false;
  Reorders reorders_;
  void (Simulation::*reorder_)() = nullptr;
  template <class Kernel> bool strips_hold_for() const;
  bool (Simulation::*strips_hold_)() const = nullptr;
  mutable std::vector<double> rho_g_cache_;
  void (Simulation::*p2g_)() = nullptr;
  void (Simulation::*g2p_range_)(size_t, size_t, G2PLocal&) = nullptr;
  void (Simulation::*constitutive_range_)(size_t, size_t) = nullptr;
  bool fuse_particle_passes_ = true;
  bool by_four_ = true;
  void (Simulation::*contact_)() = nullptr;
  std::vector<ContactPoint> contacts_;
  // cell-fraction contact: per body, the nodes a point has touched; its field's sample points
  // (body frame, m) and their mass (kg per metre); the field's nodal mass over the body's node box
  std::vector<std::vector<uint8_t>> touched_;
  // A body with a free angle has no one direction across its travel: its side inset turns with
  // the local velocity of its material. Samples nearer its surface than the side inset (the rim)
  // keep their depth and chord across each of kInsetDirections directions over half a turn (body
  // frame), and each step weigh in by how far they lie inside the inset across their own velocity.
  static constexpr int kInsetDirections = 32;
  // a body's field samples lie on a lattice in its frame: sample k at (column_x_m[column[k]],
  // row_y_m[row[k]]), in rows from the bottom
  struct BodySamples {
    std::vector<Vec2> q_m;
    std::vector<double> column_x_m, row_y_m;
    std::vector<uint32_t> column, row;
    std::vector<uint32_t> row_start;  // row c's samples are [row_start[c], row_start[c + 1]), by column
    std::vector<uint32_t> rim;                      // samples whose weight turns (free angle)
    std::vector<double> rim_across_m;               // rim.size() x kInsetDirections: nearer side
    std::vector<double> rim_chord_m;                // and the chord through the sample
    Vec2 rest_direction{0.0, 0.0};                  // body frame: where the rim looks at rest
    std::vector<double> weight;                     // this step's, per sample (free angle)
  };
  std::vector<BodySamples> body_samples_;
  std::vector<std::vector<Vec2>> body_corners_m_;  // outline corners, body frame (bounds at any angle)
  std::vector<std::vector<std::vector<Vec2>>> body_boundaries_m_;  // shape_boundary, body frame (drawn)
  // free bodies, per node of the body's box: the part of the node's correction that follows the
  // body's velocity (a symmetric 2x2 projector times the share: xx, xy, yy), and (cell_fraction)
  // its stencil sums of mass x n n^T
  std::vector<std::vector<Vec3>> held_, stencil_nn_;
  double body_sample_mass_kg_ = 0.0;
  double body_node_full_kg_ = 0.0;
  std::vector<std::vector<double>> body_node_mass_kg_;
  std::vector<std::vector<double>> band_field_;  // cell_fraction: each band's own copy of the field (scratch)
  // cell_fraction this step (plan_cell_fraction): per body its node box, how many bands cut it,
  // and its field's lattice weights (a body that never turns); one task per band
  struct FieldPlan {
    int i0 = 0, i1 = 0, j0 = 0, j1 = 0;
    int bands = 1;
    std::vector<int> column_base, row_base;
    std::vector<double> column_w, row_w;
  };
  struct BandTask {
    size_t body;
    int i0, i1, j0, j1;  // the nodes it adds to (and in the grid update's region updates)
  };
  std::vector<FieldPlan> field_plans_;
  std::vector<BandTask> band_tasks_;
  bool (Simulation::*plan_bands_)() = nullptr;
  void (Simulation::*band_sums_)(size_t, bool) = nullptr;
  // cell-fraction contact, per body over its node box: the points' summed velocity changes (kg m/s)
  // and the mass they came with (kg), both weighted by the points' weights
  std::vector<std::vector<Vec2>> stencil_dv_kg_m_s_;
  std::vector<std::vector<double>> stencil_mass_kg_;
  std::vector<std::vector<uint32_t>> contact_chunks_;
  std::unique_ptr<tbb::task_arena> arena_;
  TaskLog* task_log_ = nullptr;
};

// The instruction set this engine was compiled for (CMake picks the build machine's widest):
// --version and run.json say it, since the sums' round-off depends on it.
const char* instruction_set();

}  // namespace furrow
