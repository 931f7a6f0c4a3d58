// Scene files: JSON -> validated Scene, Scene -> resolved JSON, `--set key.path=value` overrides,
// and the cost estimates (time step, particles, steps) that validation and the solver share.
// Every key is consumed or reported with its JSON pointer path (see scenes/README.md).
#pragma once
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace furrow {

// A scene that cannot be run. what() reads
//   FILE: /json/pointer: got VALUE, expected EXPECTATION[ (NOTE)]
// or, for text that is not JSON,
//   FILE:LINE:COLUMN (byte B): got SNIPPET, expected valid JSON (DETAIL)
struct SceneError : std::runtime_error {
  SceneError(std::string file, std::string path, std::string value, std::string expected,
             std::string note = "", int line = 0, int column = 0, size_t byte = 0);
  std::string file;      // scene file (or "<string>", "<template NAME>")
  std::string path;      // JSON pointer, "" for the whole document
  std::string value;     // short dump of the offending value ("(missing)" for a missing key)
  std::string expected;  // what would have been accepted
  std::string note;      // provenance, e.g. "set by --set domain.dx_m=0"
  int line = 0, column = 0;  // 1-based, JSON syntax errors only
  size_t byte = 0;
};

struct ValidationOptions {
  // `--yes`: accept scenes estimated at more than kMaxParticles particles or kMaxSteps steps.
  bool allow_large = false;
};

constexpr double kMaxParticles = 2e7;
constexpr double kMaxSteps = 2e6;

// Validates and resolves a parsed document (defaults filled in). `source` names it in errors.
Scene parse_scene(const nlohmann::json& j, const std::string& source,
                  const ValidationOptions& options = {});

// Parses scene text (duplicate keys and nesting deeper than 64 are errors), applies the
// overrides in order, then parse_scene. Errors at a path an override wrote name the override.
Scene parse_scene_text(const std::string& text, const std::string& source,
                       const std::vector<std::string>& overrides = {},
                       const ValidationOptions& options = {});

// Reads `path` and calls parse_scene_text. Nothing is written anywhere.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {},
                 const ValidationOptions& options = {});

// The resolved scene, every key present: parse_scene(scene_to_json(s)) reproduces s for any s
// that parse_scene returned. Keys sorted (nlohmann::json); use format_scene for files.
nlohmann::json scene_to_json(const Scene& scene);
// Pretty JSON text in schema order (the order of scenes/README.md), ending in a newline.
std::string format_scene(const Scene& scene);

// Applies one `key.path=value` to a document. Segments are object keys or array indices (an
// array element may also be named by its "name"); a leading '/' means a JSON pointer instead.
// The value is parsed as JSON when it parses, else taken as a string. A key missing from the
// document is created only when the schema allows it there; otherwise, and for a bad index,
// SceneError names the nearest valid keys. An index equal to the array size appends, when it is
// the last segment.
void apply_override(nlohmann::json& j, const std::string& assignment, const std::string& source);

// The keys the schema allows in the object at `pointer` of `root` (empty if that is not an
// object position). For variant objects (material model, shape/motion/wall type) the variant
// named in `root` decides; all variants' keys when it names none.
std::vector<std::string> schema_keys(const nlohmann::json& root, const std::string& pointer);

// ---- estimates shared with the solver ----
// Elastic P-wave speed of a material: sqrt((K + 4G/3) / (rho_g phi)), phi = phi_c (NDPM) or
// min(phi_c, phi_min) (DPM: dense material may be that loose). The solver's CFL uses it too.
double wave_speed_m_s(const Material& m);
// dt = cfl dx / (c + v_body_max), c the fastest material's wave speed.
double estimate_time_step_s(const Scene& scene);
// Sum over beds of area / dx^2 * ppc^2 (particles inside bodies are not subtracted).
size_t estimate_particle_count(const Scene& scene);
// Simulated time: end_time_s, or earlier when the reference body reaches end_displacement_m.
double estimate_end_time_s(const Scene& scene);
// ceil(estimate_end_time_s / estimate_time_step_s).
int64_t estimate_step_count(const Scene& scene);
// What a run costs: particles x steps, the steps capped by solver.max_steps (cost predictions).
double estimate_particle_steps(const Scene& scene);
// A body's direction of travel (its velocity halfway through the run, unit; for a free body that
// starts at rest, its load along its free axes), or zero if it does not move then.
Vec2 travel_direction(const Scene& scene, const Body& body);
// A body's extent across its direction of travel, in cells; its smallest extent if it does not move.
double body_cells_across(const Scene& scene, const Body& body);
// How far a body's mean force at `cells_across` tends to sit from its converged value with each
// contact method (relative, + = larger): ~ c / cells, c fitted to a plate at 8, 16 and 32 cells
// (engine/README.md, "Body contact"): node and cell_fraction act smaller, particle larger.
double contact_size_bias(ContactMethod method, double cells_across);

// ---- body kinematics (prescribed motion) ----
Vec2 motion_velocity_m_s(const Motion& motion, double t_s);
// Displacement from the start position after t_s (exact for piecewise-linear velocity).
Vec2 motion_displacement_m(const Motion& motion, double t_s);
// Angular velocity (counter-clockwise) and the angle turned since the start, likewise.
double motion_angular_velocity_rad_s(const Motion& motion, double t_s);
double motion_rotation_rad(const Motion& motion, double t_s);
// Largest speed the motion ever has.
double motion_max_speed_m_s(const Motion& motion);
double motion_max_angular_speed_rad_s(const Motion& motion);
// Index of the body whose straight-line distance from its start ends the run when
// solver.end_displacement_m > 0: the first body in `bodies` that moves. -1 when none moves.
int reference_body_index(const Scene& scene);
// First time the motion's |displacement| reaches distance_m, searched up to t_max_s; +inf if not.
double time_to_displacement_s(const Motion& motion, double distance_m, double t_max_s);
// Axis-aligned bounds of a shape in its body frame (union parts included), {min, max}.
std::pair<Vec2, Vec2> shape_bounds_m(const Shape& shape);

// ---- templates (scenes/*.json embedded at build time; engine/scene/scene_templates.cpp) ----
struct SceneTemplate {
  std::string name;         // file stem, e.g. "plate_intrusion"
  std::string description;  // the scene's "description"
  std::string text;         // the file's JSON text
};
const std::vector<SceneTemplate>& scene_templates();
// Exact name, or with '-' for '_'; nullptr if unknown.
const SceneTemplate* find_scene_template(const std::string& name);

}  // namespace furrow
