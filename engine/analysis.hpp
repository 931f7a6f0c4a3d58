// Post-processing of a run's physics (paper cases 3 and 4), used by run_scene for run.json and by
// the tests:
//   - drag-signal statistics over a window of body travel (mean, fluctuation amplitude, period);
//   - the rigid wedge ("no-shear zone") under a vertically intruding plate, from a velocity frame.
//
// Drag statistics, precisely (drag_statistics):
//   1. samples (travel s_k, drag F_k) with s_k inside [from_m, to_m] are box-averaged into bins of
//      `bin_m` travel (default: one grid cell). The plate's cell-crossing noise has period dx in
//      travel, so a box of one cell removes it; the box also anti-aliases the even resampling.
//      Empty bins are filled by linear interpolation between their neighbours.
//   2. mean drag = mean of the bins (a travel average).
//   3. the bins are detrended by a least-squares line in travel (the drag of a plow grows as the
//      spoil ahead of it accumulates; that growth is not a fluctuation).
//   4. fluctuation amplitude = RMS of the detrended bins; relative amplitude = RMS / |mean|.
//      (For F = F0 + a s + A sin(2 pi s / p): RMS = A / sqrt 2.)
//   5. dominant period = travel per cycle of the largest peak of the periodogram of the detrended
//      bins, if that peak passes Fisher's g-test for a periodic component in white noise at
//      significance `alpha`, and the window holds at least `min_cycles` periods; NaN otherwise.
//      The peak frequency is refined by Gaussian (log-parabolic) interpolation of the
//      Hann-windowed spectrum around the peak bin.
//
// Wedge, precisely (measure_wedge):
//   region = active cells strictly below the plate's bottom face whose velocity v satisfies
//            |v - v_plate| < tolerance |v_plate|, 4-connected to such cells in the first
//            `seed_rows` rows under the face, and within one cell of the face's x-range;
//   per row of the region, its left and right edges x_L(z), x_R(z) at depth z below the face,
//            placed where the mismatch crosses the tolerance (linear between the last cell in and
//            the first cell out; the cell edge at a free surface);
//   flanks = least-squares lines x_L = a_L + tan(alpha_L) z and x_R = a_R - tan(alpha_R) z over
//            the rows at least 3 cells wide (the 1-2 cell apex rows are quantisation), starting at
//            the widest of the first `seed_rows` rows (a layer sliding along the face is not the
//            zone's outline);
//   apex angle = alpha_L + alpha_R: the full angle between the flanks (degrees), whether they meet
//            inside the region (a wedge) or not (a trapezoid, the early stage);
//   height = depth of the deepest region row's lower edge below the face.
// The tolerance 0.1 sits between the noise of the rigid core (a few % of the plate speed in a
// rasterized frame) and the material compacting below the wedge (20-35% slower than the plate in
// the loose bed of case 4); the angle falls as the tolerance grows (that slower material joins
// the region), so compare runs at one tolerance. Per-frame scatter is several degrees at 15-20
// cells across the plate: compare medians over frames. The solver's body constrains only grid
// nodes inside it, so as the face descends through a cell the layer under it slows (half the
// plate's speed 0.1 cell above the next node line, nearly at rest just before it) and catches up
// once the face passes the node line; frames taken then may lose the zone, so the per-frame
// entries carry the face's offset above the node line below it.
//
// The quantity compared with the paper's pi/2 - atan(mu) is the FULL apex angle. Slip-line
// theory for a plate pressed into a frictional half-space (Prandtl's mechanism) bounds the rigid
// zone by slip lines at pi/4 + phi/2 from the horizontal, so the angle between them is
// pi - 2 (pi/4 + phi/2) = pi/2 - phi, with tan(phi) = mu; the paper's section 3.2 calls
// pi/2 - atan(mu) the wedge's "acute angle" and section 3.4 its "apex angle". Its last sentence
// says "half-angle"; taken literally that is Terzaghi's rough-footing wedge (sides at phi to the
// horizontal), a wedge (L/2) tan(phi) deep: 11 mm for the 40 mm plate, against the 30-35 mm deep
// zones the simulations show. (With Drucker-Prager in plane strain, mu = sin(phi) strictly,
// which would put the apex at 90 - asin(0.53) = 58 deg instead of 62 for mu_c = 0.53.)
#pragma once
#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "engine/fields.hpp"
#include "engine/scene/scene.hpp"

namespace furrow {

// ---------------------------------------------------------------- drag signal statistics
struct DragStatsOptions {
  double from_m = 0.0;       // window of travel
  double to_m = -1.0;        // < 0: to the last sample
  double bin_m = 0.0;        // resampling box; <= 0: (window length) / 1024
  double alpha = 1e-3;       // significance of the periodicity test
  double min_cycles = 2.0;   // a period must fit this many times in the window
};

struct DragStats {
  int64_t samples = 0;          // raw samples inside the window
  int bins = 0;                 // evenly spaced resampled values
  double from_m = 0.0, to_m = 0.0, bin_m = 0.0;
  double mean_N_per_m = 0.0;    // NaN when no sample falls in the window
  // NaN (like the period) when the window holds fewer than 3 bins
  double trend_N_per_m2 = 0.0;  // slope of the removed linear trend (per metre of travel)
  double rms_N_per_m = 0.0;     // RMS of the detrended signal
  double relative_fluctuation = 0.0;  // rms / |mean|
  double period_m = 0.0;        // dominant period in travel; NaN when there is no clear peak
  double period_p_value = 1.0;  // Fisher g-test p-value of the largest periodogram peak
};

// travel_m and drag_N_per_m: one sample each (e.g. one per step), travel non-decreasing.
DragStats drag_statistics(const std::vector<double>& travel_m, const std::vector<double>& drag_N_per_m,
                          const DragStatsOptions& options);

// ---------------------------------------------------------------- grid artifacts in a force trace
// How far a per-step force trace departs from its own average over one cell of travel: the
// signature of contact that steps as a body face crosses node lines. Over samples with travel in
// [from_m, to_m]:
//   running mean M_k = mean of the samples within half a cell of travel of sample k;
//   peak_ratio = max F_k / M_k; rms_relative = RMS(F_k - M_k) / mean F;
//   cell_amplitude_relative = amplitude of the component of period `cell_m` (least-squares sine
//   and cosine) in the force binned every `bin_m` of travel and detrended, over its mean;
//   tick_max_relative = max |F_k - (F_(k-1) + F_(k+1)) / 2| / mean F over samples whose
//   neighbours are in the window too: a single-step kick, which no flow makes (a flow changes the
//   force over many steps, so this reads a few tenths of a percent at most where no step kicks).
struct ForceSmoothness {
  int64_t samples = 0;
  double mean_N_per_m = 0.0;
  double peak_ratio = 0.0;
  double peak_at_m = 0.0;  // travel of the peak
  double rms_relative = 0.0;
  double cell_amplitude_relative = 0.0;
  double tick_max_relative = 0.0;
};
// travel_m non-decreasing; NaN fields when the window holds no sample.
ForceSmoothness force_smoothness(const std::vector<double>& travel_m, const std::vector<double>& force_N_per_m,
                                 double cell_m, double from_m, double to_m, double bin_m = 0.001);

// Whether a step at time t_s with lead-body travel travel_m lies in the scene's averaging window
// (outputs.average_window: by displacement when from_m >= 0, else by time; a negative "to" means
// the end of the run).
// JSON has no NaN: a NaN is written as null (nlohmann's dump) and read back here as NaN; finite
// doubles round-trip exactly (17 significant digits). For run checkpoints.
double double_from_json(const nlohmann::json& j);
std::vector<double> doubles_from_json(const nlohmann::json& j);

bool in_average_window(const Outputs& out, double t_s, double travel_m);

// ---------------------------------------------------------------- holes in a flowing zone
// How continuous a stored field reads: among active cells whose active neighbours (of the 8 around
// them, at least 3) average above `flow_threshold`, the `holes` that hold less than
// `hole_threshold` themselves (a flowing zone's cell that reads as still: a speck in the movie).
struct FlowHoles {
  int64_t flowing = 0, holes = 0;
  double fraction() const { return flowing > 0 ? double(holes) / double(flowing) : 0.0; }
};
// Throws std::invalid_argument when the frame does not hold the scalar `field`.
FlowHoles count_flow_holes(const FieldFrame& frame, const std::string& field, double flow_threshold = 0.05,
                           double hole_threshold = 1e-3);

// ---------------------------------------------------------------- rigid wedge under a plate
struct WedgeOptions {
  double tolerance = 0.1;   // |v - v_plate| < tolerance |v_plate| counts as moving with the plate
  int seed_rows = 3;        // the region grows from cells in this many rows under the face
  int min_fit_rows = 3;     // fewer flank rows than this: no angle (NaN)
};

struct WedgeMeasure {
  bool found = false;        // a region under the plate exists
  int cells = 0;             // cells in the region
  int rows = 0;              // rows spanned
  int fit_rows = 0;          // rows used by the flank fits
  double apex_angle_deg = 0.0;   // alpha_L + alpha_R; NaN when not measurable
  double left_flank_deg = 0.0;   // alpha_L, from the vertical, positive when converging
  double right_flank_deg = 0.0;  // alpha_R
  double height_m = 0.0;         // deepest region row's lower edge below the plate face
  double apex_depth_m = 0.0;     // where the fitted flanks meet (NaN if parallel/diverging)
  // x of each fitted flank line at the face (a_L, a_R above; NaN when not measurable): with the
  // face's y and the flank angles, what draws the lines (the inspector's overlay)
  double left_flank_x_m = 0.0, right_flank_x_m = 0.0;
  double face_y_m = 0.0, face_x0_m = 0.0, face_x1_m = 0.0;  // the plate's bottom face
  std::vector<uint8_t> mask;     // nx*ny, 1 in the region (for plots and tests)
};

// frame: a FieldFrame with velocity; plate: the intruder's outline in world coordinates.
// Throws std::invalid_argument when the frame has no velocity or the plate velocity is zero.
WedgeMeasure measure_wedge(const FieldFrame& frame, const BodyOutline& plate, const Vec2& plate_velocity_m_s,
                           const WedgeOptions& options = {});

// Median of the finite values (NaN when there are none): per-frame angles scatter.
double median_finite(std::vector<double> values);

// The slip-line wedge apex angle pi/2 - atan(mu) in degrees (see the header comment).
double slip_line_apex_angle_deg(double mu);

// ---------------------------------------------------------------- column collapse
// A released column: a scene with no bodies whose beds leave a side free. The column's back is the
// wall its beds touch (both sides free: it spreads both ways and lengths are half-widths from its
// centre line); L0 and H0 are the beds' extent. At each sample:
//   front  = distance from the back to the point beyond which 0.5% of the material points lie,
//            plus half a point's seeded spacing (a few grains thrown ahead do not count, as in experiments
//            that read the front off the continuous deposit);
//   height = highest top of the material resting on the floor: in each cell column, points are
//            followed up from the floor while the gap to the next is under two cells (a loose
//            deposit holds voids of a cell; a grain in flight above it does not count).
// Runout (Lf - L0) / L0 and Hf / H0 from the last sample; "settled" when the front moved less than
// 1% of L0 over the last tenth of the run; the final deposit's surface as the highest point top in
// each cell column.
struct CollapseGeometry {
  bool active = false;
  int side = 0;  // +1: spreads toward +x from a wall at back_x_m; -1: toward -x; 0: both ways
  double back_x_m = 0.0, floor_y_m = 0.0, L0_m = 0.0, H0_m = 0.0;
  double cell_m = 0.0;        // column width of the surface
  double point_half_m = 0.0;  // half the points' seeded spacing: their extent (a dilute point's volume
                              // keeps growing in flight, so its current size would not do)
};
CollapseGeometry collapse_geometry(const Scene& scene);

// The material's surface: (column centre x, height of the material resting on the floor) per cell
// column that holds points, left to right.
std::vector<std::pair<double, double>> collapse_surface(const ParticleView& p, const CollapseGeometry& g);

struct CollapseSample {
  double t_s = 0.0, front_m = 0.0, height_m = 0.0;
};
// `surface`, when given, receives the collapse_surface the height was taken from.
CollapseSample measure_collapse(const ParticleView& p, const CollapseGeometry& g, double t_s,
                                std::vector<std::pair<double, double>>* surface = nullptr);

class CollapseAnalysis {
 public:
  explicit CollapseAnalysis(const Scene& scene);
  bool active() const { return g_.active; }
  // samples every `interval_s` of simulated time (frame interval, else end time / 100); `last`:
  // the run's final state, sampled unless it just was
  void add_step(double t_s, const ParticleView& p, bool last = false);
  nlohmann::json to_json() const;
  const std::vector<CollapseSample>& samples() const { return samples_; }
  // what a resumed run needs to continue the same samples (run checkpoints)
  nlohmann::json state() const;
  void restore(const nlohmann::json& state);

 private:
  CollapseGeometry g_;
  double interval_s_ = 0.0, next_s_ = 0.0;
  std::vector<CollapseSample> samples_;
  std::vector<double> profile_x_m_, profile_height_m_;  // the last sample's surface, one per cell column
};

// ---------------------------------------------------------------- run.json hook
// Collects what the "analysis" section of run.json needs while a run goes, at no cost when the
// scene has no moving body. Drag of the lead body = -(force . unit velocity), the media's
// resistance to its motion (N/m).
class RunAnalysis {
 public:
  explicit RunAnalysis(const Scene& scene);
  bool active() const { return lead_ >= 0; }
  int lead_index() const { return lead_; }  // index in Scene::bodies; -1 when none moves
  // after each step: the lead body's force and velocity, time and travel
  void add_step(double t_s, double travel_m, const Vec2& force_N_per_m, const Vec2& velocity_m_s);
  // whether frames should be handed to add_frame (velocity stored and the lead body moves
  // vertically)
  bool wants_frames() const { return wedge_; }
  // The same condition before a run: whether run.json will hold a wedge analysis for `scene`.
  static bool measures_wedge(const Scene& scene);
  // a frame just rasterized; bodies as in frame.bodies, lead body's velocity
  void add_frame(const FieldFrame& frame, double travel_m, const Vec2& velocity_m_s);
  nlohmann::json to_json() const;
  nlohmann::json state() const;
  void restore(const nlohmann::json& state);

 private:
  int lead_ = -1;
  std::string lead_name_;
  const Outputs* out_ = nullptr;
  double dx_m_ = 0.0;
  bool wedge_ = false;
  std::vector<double> travel_m_, drag_N_per_m_;
  nlohmann::json frames_ = nlohmann::json::array();
};

}  // namespace furrow
