// Scene: the validated, immutable description of a run (SI units throughout).
// Built from JSON by engine/scene/scene_io; the solver never changes it.
#pragma once
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace furrow {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

enum class ShapeFunction { Linear, Quadratic, Cubic };
enum class MaterialModel { NDPM, DPM };
// How bodies act on the media: on the grid nodes inside them (the force steps each time a face
// crosses a node line), on the material points touching their surface (smooth, but the constraint
// spreads over the points' B-spline stencils: a body acts about a cell larger), or as a mass field
// sharing each node's correction (smooth; a scene file's default). engine/README.md compares them.
enum class ContactMethod { Node, Particle, CellFraction };
// The scene file's name of a contact method ("node", "particle", "cell_fraction").
const char* contact_method_name(ContactMethod method);

struct Material {
  std::string name = "sand";
  MaterialModel model = MaterialModel::NDPM;
  double grain_density_kg_m3 = 2520.0;  // rho_g
  double phi_c = 0.60;                  // close-packed (NDPM) / critical-state (DPM) packing fraction
  double mu = 0.40;                     // NDPM: mu_s; DPM: mu_c (friction at phi_d = phi_c)
  double chi = 0.0;                     // DPM dilatancy scale; 0 reduces DPM to NDPM
  double phi_min = 0.45;                // DPM: phi_d resets here when material opens below it
  double youngs_modulus_Pa = 5.0e6;     // small elastic part: "just stiff enough"
  double poisson_ratio = 0.3;
  // mu(I) rheology, used only with effects.rate_dependence: the friction gains
  // (mu_2 - mu) / (1 + I0 / I), I = gamma_dot_p d / sqrt(P / rho_g) (Jop, Forterre & Pouliquen 2006;
  // defaults: their glass beads, mu_2 - mu_s = 0.26, I0 = 0.279, d = 0.53 mm)
  double mu_2 = 0.66;
  double inertial_I0 = 0.279;
  double grain_diameter_m = 0.53e-3;
};

struct Bed {
  std::string material;  // name of an entry in Scene::materials
  Vec2 min_m{0.0, 0.0};  // region (axis-aligned box)
  Vec2 max_m{0.0, 0.0};
  double packing_fraction = 0.60;  // initial phi (DPM: initial phi_d too)
  double k0 = -1.0;                // lateral earth-pressure ratio; < 0 means Jaky: 1 - sin(atan mu)
  bool geostatic = true;           // start in geostatic equilibrium instead of stress-free
};

struct Shape {
  enum class Kind { Circle, Box, Polygon, Union };
  Kind kind = Kind::Box;
  double radius_m = 0.0;               // circle
  Vec2 size_m{0.0, 0.0};               // box: full width and height
  std::vector<Vec2> vertices_m;        // polygon: convex, counter-clockwise, body frame
  std::vector<Shape> parts;            // union
  Vec2 offset_m{0.0, 0.0};             // position of this shape in its parent's frame
};

// Prescribed motion of a body's origin, and its rotation about it (counter-clockwise positive).
struct Motion {
  enum class Kind { ConstantVelocity, Path };
  Kind kind = Kind::ConstantVelocity;
  Vec2 velocity_m_s{0.0, 0.0};
  double angular_velocity_rad_s = 0.0;
  // piecewise-linear velocity in time: (t_s, vx, vy, omega) knots; held constant after the last knot
  struct Knot {
    double t_s;
    Vec2 velocity_m_s;
    double angular_velocity_rad_s = 0.0;
  };
  std::vector<Knot> path;
};

// Degrees of freedom of a body that respond to the media (two-way coupling) instead of following
// its motion; the motion then gives only their starting velocities.
struct BodyDynamics {
  bool free_x = false, free_y = false, free_angle = false;
  double mass_kg_per_m = 0.0;    // per metre out of plane
  double inertia_kg_m = 0.0;     // moment of inertia about the origin, kg m^2 per metre
  Vec2 applied_force_N_per_m{0.0, 0.0};  // a constant load (a wheel's weight on its axle)
  double applied_torque_N = 0.0;         // N m per metre: a motor's torque, counter-clockwise
  double load_ramp_s = 0.0;  // the applied force and torque rise linearly from 0 over this time (0: at once)
  bool any_free() const { return free_x || free_y || free_angle; }
};

struct Body {
  std::string name = "body";
  Shape shape;
  Vec2 start_m{0.0, 0.0};  // position of the shape's origin (box/circle centre) at t = 0
  double start_angle_rad = 0.0;  // counter-clockwise
  Motion motion;
  BodyDynamics dynamics;
  double friction = 0.35;  // mu_f, Coulomb, body against media
  bool rotates() const;    // a start angle, an angular velocity or a free angle
};

struct Wall {
  enum class Kind { Slip, Friction, Sticky, Open };
  Kind kind = Kind::Slip;
  double friction = 0.0;
};

// The two walls parallel to the simulated plane of a quasi-2D channel (glass plates gap_m apart):
// Coulomb friction on them, 2 mu |sigma_zz| / gap per unit volume against the in-plane motion.
// Absent (gap_m 0): plane strain, no such walls.
struct FrontBackWalls {
  double gap_m = 0.0;
  double friction = 0.0;
  bool present() const { return gap_m > 0.0; }
};

struct Walls {
  Wall left, right, bottom, top{Wall::Kind::Open, 0.0};
  FrontBackWalls front_back;
};

struct Effects {
  bool gravity = true;
  Vec2 gravity_m_s2{0.0, -9.81};
  bool dilatancy = false;        // DPM state evolution; forced off for NDPM materials
  bool separation = true;        // stress-free when open (rho < rho_d)
  bool rate_dependence = false;  // mu(I): friction grows with the inertial number (off: the paper's models)
  bool body_friction = true;
  bool wall_friction = true;
};

// A movie layout, as the paper's supplementary movies show a case: several fields side by side,
// optionally in a body's frame of reference and dimensionless. `furrow run` renders it to
// movies/<name>.mp4; `furrow render RUN --layout` renders it again (of several runs too).
struct MovieLayout {
  std::string name;                 // movies/<name>.mp4; "" when the scene has no layout
  std::vector<std::string> fields;  // field names, or the velocity's components velocity_x / velocity_y; a
                                    // run that does not store them all renders no layout movie
  std::string frame_of;             // a body's name: the body stays still in the image; "" for none
  double zoom = 1.0;                // with frame_of: the view enlarged about the body
  bool normalize = false;           // velocity / v, strain rate / (v/L), time t v/L (first moving body)
};

struct Outputs {
  double frame_interval_s = 0.0;   // 0: no frames
  std::vector<std::string> fields; // e.g. "pressure", "strain_rate", "packing_fraction", "velocity"
  std::vector<std::string> movies; // subset of fields rendered to movies/<field>.mp4
  bool points = false;             // also store the material points with each frame (points_NNNNN.vdb)
  MovieLayout layout;              // the paper's layout of this case's movie (none when name is "")
  double force_interval_s = 0.0;   // 0: one forces.csv row per body per step
  // summary window for mean forces: by time, or by body displacement when set (> 0)
  double average_from_s = 0.0, average_to_s = -1.0;
  double average_from_m = -1.0, average_to_m = -1.0;
};

struct Solver {
  ShapeFunction shape_function = ShapeFunction::Quadratic;
  int particles_per_cell_1d = 2;   // 2 -> 4 particles per cell
  double cfl = 0.4;
  // FLIP share of the particle velocity update (0 = pure APIC). APIC alone damps non-affine
  // motion once per step, a viscosity ~ dx^2/dt that grows as dt shrinks.
  double flip_blend = 0.99;
  // Scenes built in code get Node; a scene file without solver.contact gets CellFraction (scene_io.cpp).
  ContactMethod contact = ContactMethod::Node;
  double end_time_s = 1.0;
  double end_displacement_m = -1.0;  // stop when the first moving body has travelled this far (> 0)
  int threads = 0;                   // 0: all hardware threads
  int max_steps = 50'000'000;        // guard against runaway scenes
};

struct Domain {
  double width_m = 1.0, height_m = 1.0;
  double dx_m = 0.01;
};

struct Scene {
  int schema_version = 1;
  std::string name = "scene";
  std::string description;
  Domain domain;
  Solver solver;
  std::vector<Material> materials;
  std::vector<Bed> beds;
  std::vector<Body> bodies;
  Walls walls;
  Effects effects;
  Outputs outputs;

  const Material* find_material(const std::string& name) const {
    for (const auto& m : materials)
      if (m.name == name) return &m;
    return nullptr;
  }
};

}  // namespace furrow
