// Accuracy against cost (`furrow study`): a scene run over a ladder of settings (dx, shape function,
// particles per cell, ...), one quantity read from each rung, and how far each rung is from the
// finest one and from a Richardson extrapolation in dx, against the wall time it took.
// The command (child runs, resume, progress) is app/cmd_study.cpp; this is the arithmetic and the
// table, kept free of I/O so it can be tested on made-up numbers.
#pragma once
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/sweep.hpp"
#include "render/plot.hpp"

namespace furrow::study {

struct StudyError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

enum class Quantity { DragMean, LiftMean, PeakForce, WedgeAngle, Fluctuation };

// "drag_mean" | "lift_mean" | "peak_force" | "wedge_angle" | "fluctuation"; throws StudyError naming the choices.
Quantity parse_quantity(const std::string& name);
std::string quantity_name(Quantity q);
std::string quantity_unit(Quantity q);     // "N/m", "deg" or "of the mean"
std::string quantity_column(Quantity q);   // e.g. "drag_mean_N_per_m"
std::string quantity_meaning(Quantity q);  // one sentence for study.md and --help

// Why `scene` cannot produce q for `body` (empty: it can). body "" means the scene's lead body.
std::string cannot_produce(const Scene& scene, Quantity q, const std::string& body);

// The quantity of one finished run; NaN with *why set when the run did not produce it.
double extract(Quantity q, const sweep::RunMetrics& metrics, const nlohmann::json& run_json, const std::string& body,
               std::string* why);

// Richardson extrapolation from three rungs h1 > h2 > h3 (not necessarily a constant ratio):
// q(h) = q0 + C h^p fitted through the three points.
struct Richardson {
  bool ok = false;
  double order = 0.0;         // observed order p
  double extrapolated = 0.0;  // q0
  std::string note;           // why not, when !ok
};
Richardson richardson(double h1, double q1, double h2, double q2, double h3, double q3);

// One rung of the ladder.
struct Rung {
  std::string dir;                  // run directory name inside the study directory
  std::vector<std::string> values;  // one per ladder
  std::string group;                // the values of the ladders other than dx ("" when only dx varies)
  double dx_m = 0.0;
  double estimated_particle_steps = 0.0;  // estimate_particle_count * estimate_step_count
  // filled by the command
  double predicted_wall_s = 0.0;    // NaN: nothing to predict from yet
  std::string predicted_from;       // which rungs the prediction used
  bool ok = false, reused = false;  // reused: complete from an earlier invocation
  std::string error;
  double value = 0.0;               // the quantity (NaN when not produced)
  double wall_s = 0.0, particle_steps = 0.0, particles = 0.0, steps = 0.0;
  double peak_resident_bytes = 0.0, state_bytes = 0.0;
  int threads = 0;
  // filled by analyse()
  double diff_finest = 0.0;         // value - value of the finest rung of its group
  double extrapolated = 0.0;        // the group's Richardson value (NaN when it has none)
  double diff_extrapolated = 0.0;   // value - extrapolated
  double order = 0.0;               // observed order of this rung and the next two finer of its group
  double error_relative = 0.0;      // |value - reference| / |reference|
};

// What analyse() concluded over all rungs.
struct Summary {
  double reference = 0.0;           // the best estimate of the converged value
  std::string reference_from;       // how it was obtained
  std::vector<std::pair<std::string, Richardson>> groups;  // per group, from its three finest rungs
};

// Fills each rung's derived fields. The reference is the Richardson value of the group that holds
// the most expensive finished rung, or that rung's value when the group has no extrapolation.
Summary analyse(std::vector<Rung>& rungs);

// Predicted wall time of `r` from the finished rungs: a line wall = a + b * particle-steps fitted
// through the rungs of its group (proportional with one), else proportional to the most expensive
// finished rung of any group. NaN when nothing has finished.
double predict_wall_s(const std::vector<Rung>& rungs, const Rung& r, std::string* basis);

// Rung wall times span milliseconds to hours: seconds with decimals below a minute, else h:mm:ss.
std::string wall_text(double seconds);

// The outputs: a CSV with units in the header, a Markdown report, the figure.
std::string study_csv(const std::vector<sweep::Vary>& ladders, Quantity q, const std::vector<Rung>& rungs);
std::string study_markdown(const std::string& scene_name, const std::vector<sweep::Vary>& ladders, Quantity q,
                           const std::string& body, const std::vector<Rung>& rungs, const Summary& s);
render::PlotFigure study_figure(const std::string& scene_name, Quantity q, const std::vector<Rung>& rungs,
                                const Summary& s);

}  // namespace furrow::study
