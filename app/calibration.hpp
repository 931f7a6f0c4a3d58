// This machine's solver throughput, measured by `furrow bench` and stored where `furrow validate`,
// `furrow run` and `furrow study` find it, so they can say what a scene will cost before it runs.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"

namespace furrow::cli {

struct CalibrationEntry {
  std::string shape_function;  // "linear", "quadratic", "cubic"
  std::string model;           // "ndpm" or "dpm"
  int threads = 1;
  double particle_steps_per_s = 0.0;
};

struct Calibration {
  std::string host, cpu, date;
  size_t particles = 0;        // size of the bench scene
  // Larger beds run slower (their particle and grid arrays leave the caches): the rate falls as
  // (N / particles)^size_exponent, measured between the bench scene and one 16 times larger
  // (quadratic NDPM, all threads). 0 when not measured (calibrations before 2026-12-01). Stored as
  // measured (a noisy bench can read it above 0); predictions use it clamped to [-0.5, 0].
  double size_exponent = 0.0;
  // the larger bed's measurement the exponent came from (0 when not measured)
  size_t large_particles = 0;
  double large_particle_steps_per_s = 0.0;
  std::vector<CalibrationEntry> entries;
  std::string path;            // where it was read from / is written to
};

// $FURROW_CALIBRATION, else $XDG_CONFIG_HOME/furrow/calibration.json, else
// ~/.config/furrow/calibration.json.
std::string calibration_path();

// The stored calibration; nullopt when there is none (or it cannot be read: *why says which).
std::optional<Calibration> load_calibration(std::string* why = nullptr);
void save_calibration(const Calibration& c);  // atomic; creates the directory

// Threads a run of `scene` will use (solver.threads, or every core when 0).
int run_threads(const Scene& scene);

// Predicted solver wall time of a whole run of `scene` (s): estimated particle-steps over the
// calibrated rate for its shape function, model and threads (interpolated in threads between the
// measured counts), scaled to the scene's bed by the size exponent (beds larger than the bench's only). NaN when the calibration has no figure for it; *how says what was used.
double predict_run_wall_s(const Calibration& c, const Scene& scene, std::string* how = nullptr);

// One line for people: "~1 h 50 min on this machine (2 threads)" or how to get a calibration.
std::string predicted_wall_text(const Scene& scene);

}  // namespace furrow::cli
