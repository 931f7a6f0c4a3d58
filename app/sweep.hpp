// Parameter sweeps: `--vary` specifications, their cartesian product, per-run directory names, and
// the per-body force summary of a run in the paper's normalized forms (sweep.csv). The command
// itself (parallel runs, progress, atomic output) is app/cmd_sweep.cpp; the figure is
// app/sweep_plot.cpp.
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/run.hpp"
#include "engine/scene/scene.hpp"

namespace furrow::sweep {

// A malformed --vary (bad syntax, range or step). Unknown key paths are SceneErrors instead.
struct VaryError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// One `--vary`: KEYS=VALUES.
//   KEYS   a key path as for --set (domain.dx_m, bodies.plate.shape.size_m.0, /json/pointer), or
//          several joined by '+', which all take the same value (e.g. the widths of two plates)
//   VALUES a:b:step (numbers; b included when the steps land on it within 1e-9 of a step) or a
//          comma-separated list v1,v2,... of JSON values or plain strings (commas inside [] {} or
//          quotes do not split); with several KEYS a list value may give one value per key,
//          separated by ';' (two plates' start points at each separation of a pair)
struct Vary {
  std::string spec;                 // as given
  std::string column;               // KEYS as given: the sweep.csv column name
  std::vector<std::string> keys;    // KEYS split at '+'
  std::vector<std::string> values;  // value texts, in sweep order
  // per_key[v][k]: what key k is set to for values[v]
  std::vector<std::vector<std::string>> per_key;
};

Vary parse_vary(const std::string& spec);

// All combinations, the last --vary varying fastest: combos[r][k] indexes varies[k].values.
std::vector<std::vector<size_t>> combinations(const std::vector<Vary>& varies);

// The --set overrides of one run: each key of each Vary assigned its value.
std::vector<std::string> run_overrides(const std::vector<Vary>& varies, const std::vector<size_t>& combo);

// "<scene>_<key>=<value>_..." with characters outside [A-Za-z0-9._=+-] replaced by '_'; long
// names are cut and numbered so each run of a sweep gets a distinct directory.
std::vector<std::string> run_dir_names(const std::string& scene_name, const std::vector<Vary>& varies,
                                       const std::vector<std::vector<size_t>>& combos);

// ---- per-body summary ---------------------------------------------------------------------------

// One forces.csv sample of one body.
struct ForceSample {
  double t_s = 0.0;
  Vec2 position_m{0, 0};
  Vec2 force_N_per_m{0, 0};
  double torque_N = 0.0;  // N m per metre about the body's origin (0 in files written before torque)
};

// Reads a run's forces.csv: samples[b] for each body b of the scene, in time order.
std::vector<std::vector<ForceSample>> read_forces_csv(const std::string& path, const Scene& scene);

// What sweep.csv reports for one body of one run. Drag is the force component against the body's
// direction of motion, d = -F.u (u the unit start velocity); lift the component along u rotated
// +90 degrees (for motion in +x that is Fy, for a plate moving down it is Fx). A body that does not
// move takes u = (1, 0): drag -Fx, lift Fy.
struct BodyMetrics {
  std::string name;
  std::string kind;               // "circle", "box", "polygon", "union"
  bool moving = false;
  Vec2 mean_N_per_m{0, 0};        // over the averaging window (run_scene's summary)
  double mean_drag_N_per_m = 0.0, mean_lift_N_per_m = 0.0;
  // initial peak of the drag (see initial_peak(); NaN when the drag never gives) and the largest
  // smoothed drag of the run
  double peak_drag_N_per_m = 0.0, peak_drag_travel_m = 0.0, max_drag_N_per_m = 0.0;
  // moving boxes: the drag at the start of penetration, F(z -> 0), from a straight line fitted to
  // the drag against the bottom's depth z over [dx, L/2] (bearing capacity: F = rho_d g L (N_q z +
  // N_gamma L / 2), so this is the L^2 part); NaN when the run did not reach L/2 or for other shapes
  double onset_drag_N_per_m = 0.0;
  double size_m = 0.0;            // circle: D; box: width L (x extent); others: x extent
  double depth_m = 0.0;           // see sweep.csv docs (circle: centre; box: bottom at window mid)
  double F0_N_per_m = 0.0;        // characteristic force of the normalized columns (NaN if undefined)
  double mean_torque_N = 0.0;     // N m per metre over the window, counter-clockwise about the origin
  double sinkage_m = 0.0;         // mean over the window of how far the origin is below its start
};

// The pair quantities of the paper's case 2 (first two moving boxes, left to right).
struct RunMetrics {
  std::vector<BodyMetrics> bodies;
  double rho_d_kg_m3 = 0.0, g_m_s2 = 0.0, surface_y_m = 0.0;
  double window_from_s = 0.0, window_to_s = 0.0;  // the averaging window in time
  double L_avg_m = 0.0;           // mean width of the moving boxes (NaN: none)
  double z_m = 0.0;               // mid-window depth of the moving boxes' bottoms (NaN: none)
  double gap_m = 0.0;             // inner-edge gap of the first two moving boxes at the start (NaN: < 2)
  double total_mean_drag_N_per_m = 0.0;  // sum over moving boxes (NaN: none)
  double total_F0_N_per_m = 0.0;  // rho_d g z L_avg w
  // a released column (run.json "collapse"): H0 / L0, (Lf - L0) / L0, Hf / H0, whether its front
  // had stopped, and the final surface in units of L0 (NaN / empty for other runs)
  bool collapse = false, settled = false;
  double aspect_ratio = std::nan(""), runout_relative = std::nan(""), final_height_relative = std::nan("");
  std::vector<double> surface_x_over_L0, surface_height_over_L0;
};

// Initial peak of a drag trace: the trace is smoothed by a moving average over `smooth_m` of
// travel (cell-crossing noise has a period of one cell); the peak is the first local maximum of
// the smoothed trace that the smoothed drag later falls below by more than `drop` of it (5%: the
// force "gives" once the material fails).
// Returns {peak, travel at peak}; {NaN, NaN} when the smoothed drag never falls by `drop`.
std::pair<double, double> initial_peak(const std::vector<double>& travel_m, const std::vector<double>& drag_N_per_m,
                                       double smooth_m, double drop = 0.05);
// The largest value of the same smoothed trace.
double smoothed_max(const std::vector<double>& travel_m, const std::vector<double>& drag_N_per_m, double smooth_m);

// Metrics of a finished run from its scene, summary and force samples. The window means are
// computed from the samples (time-weighted), with a missing window end meaning the end of the run.
RunMetrics run_metrics(const Scene& scene, const RunSummary& summary,
                       const std::vector<std::vector<ForceSample>>& samples);

// ---- the sweep table ----------------------------------------------------------------------------

struct SweepRow {
  std::string dir;                  // run directory name (inside the sweep directory)
  std::vector<std::string> values;  // one per Vary
  bool ok = false;
  std::string error;                // why the run failed
  double wall_s = 0.0;
  RunMetrics metrics;
};

// A CSV cell: quoted (with doubled quotes) when it holds a comma, quote or newline.
std::string csv_quote(const std::string& s);

// sweep.csv: a header with units, one row per run (see the column list in cmd_sweep's help).
std::string sweep_csv(const std::vector<Vary>& varies, const std::vector<SweepRow>& rows);

// The columns of sweep.csv with their meaning (written to sweep.json).
std::vector<std::pair<std::string, std::string>> sweep_columns(const std::vector<Vary>& varies,
                                                               const std::vector<SweepRow>& rows);

}  // namespace furrow::sweep
