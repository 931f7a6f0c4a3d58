// The inspector over a stored run (frames/*.vdb + forces.csv): one InspectorState (run, frame,
// field, colour ranges, last results), user actions as small data values (SelectField{"pressure"},
// Probe{{x, y}}), one function that applies an action and returns its result as JSON, and one
// view that draws the state (the frame as movies draw it + a Dear ImGui panel). The headless
// script, the tests and a window would drive the same path.
#pragma once
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "render/frame_renderer.hpp"

namespace furrow::render {

// ---- actions (one per script line) ---------------------------------------------------------------
struct SelectField { std::string name; };
struct GoToFrame { int64_t number = 0; };  // frame_00042.vdb is 42
struct GoToTime { double t_s = 0; };       // the stored frame nearest in time
struct Probe { Eigen::Vector2d p_m{0, 0}; };
struct Profile {
  Eigen::Vector2d a_m{0, 0}, b_m{0, 0};
  int samples = 50;
};
struct Angle { Eigen::Vector2d a_m{0, 0}, b_m{0, 0}, c_m{0, 0}; };  // at b
struct Length { Eigen::Vector2d a_m{0, 0}, b_m{0, 0}; };
struct Screenshot { std::string path; };
struct ReportWedge {};               // the current frame's wedge as run.json stored it
struct ShowWedge { bool on = true; };  // the wedge overlay on or off
// The quantity plotted against time under the force plot for the bodies that turn or are free:
// torque, depth, speed or angle (ForcePanel::rows)
struct PlotMotion { std::string key; };
using InspectAction = std::variant<SelectField, GoToFrame, GoToTime, Probe, Profile, Angle, Length, Screenshot,
                                   ReportWedge, ShowWedge, PlotMotion>;

// One script line as an action. Returns an error text (what was expected, what was found) instead
// when the line is not one; blank lines and '#' comments give std::nullopt with an empty error.
std::optional<InspectAction> parse_inspect_line(const std::string& line, std::string* error);

struct ScriptStep {
  int line = 0;
  InspectAction action;
};
// All actions of a script file, parsed before any runs. Throws std::runtime_error
// "FILE:LINE: expected ..., got '...'" for the first bad line, or naming a file it cannot read.
std::vector<ScriptStep> parse_inspect_script(const std::string& path);
// The grammar, for --help and the README.
extern const char* const kInspectScriptHelp;

// ---- state ---------------------------------------------------------------------------------------
struct InspectorState {
  std::string run_dir;
  std::vector<std::string> frame_paths;  // sorted by frame number
  std::vector<int64_t> frame_numbers;
  std::vector<double> times_s;
  std::vector<std::string> fields;               // stored in the run (registry order)
  std::map<std::string, FieldRange> ranges;      // colour range per field, fixed over the run
  std::optional<ForcePanel> forces;              // from forces.csv when present
  std::string motion;  // the key of the forces->rows entry plotted against time ("" when it has none)
  size_t current = 0;                            // index into frame_paths
  std::string field;
  FieldFrame frame;                              // the current frame
  std::vector<std::string> notes;                // last results, for the panel
  // run.json's analysis.wedge.frames entry of each stored frame that has one (frame number ->
  // entry); wedge_analysis says whether run.json has that analysis at all
  std::map<int64_t, nlohmann::json> wedge;
  bool wedge_analysis = false;
  bool show_wedge = true;  // the overlay, on by default where a frame has one
};

// The fields a frame holds, in registry order.
std::vector<std::string> stored_fields(const FieldFrame& f);
// The first stored of strain_rate, pressure, velocity, else the first stored field: what a view
// shows before the user picks.
std::string default_field(const std::vector<std::string>& stored);

// The wedge overlay of one run.json wedge entry: both flank lines from the face down to where they
// meet (to the region's depth when they meet far below it: the early, trapezoidal zone) and the
// apex angle as a label under them. std::nullopt when the entry has no lines (no angle in that
// frame, or a run.json written before the lines were stored).
std::optional<FrameOverlay> wedge_overlay(const nlohmann::json& entry);

// Reads every frame once (times, ranges) and loads the first. `field` empty: the first stored of
// strain_rate, pressure, velocity, ... Throws naming the run directory, file or field.
InspectorState open_run(const std::string& run_dir, const std::string& field = "");

// ---- measurements on a frame (SI units) -----------------------------------------------------------
// Cell (i, j) holding a point; false when outside the grid.
bool cell_at(const FieldFrame& f, const Eigen::Vector2d& p_m, int* i, int* j);
// The name of the body whose outline holds the point, or "".
std::string body_at(const FieldFrame& f, const Eigen::Vector2d& p_m);
double angle_deg(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c);

class InspectorView;

// Applies one action and returns its result (an object with "action" and SI-unit keys; a value
// where there is no material is null). Throws std::runtime_error for what the run cannot do
// (a frame or field it has not stored). Screenshot needs a view.
nlohmann::json apply_action(InspectorState& s, const InspectAction& a, InspectorView* view);
// Writes a screenshot of `view` (never over an existing file) and returns its result line.
nlohmann::json write_screenshot(const InspectorState& s, const std::string& path, const RgbImage& img,
                                const InspectorView& view);

// ---- view ---------------------------------------------------------------------------------------
// Keys a text field needs, whatever the window system calls them.
enum class ViewKey { Enter, Escape, Backspace, Delete, Left, Right, Home, End, Tab };
// The mouse and keys over the view (pixels from its top-left corner), for a window; none off-screen.
struct ViewInput {
  float mouse_x = -1, mouse_y = -1;
  bool mouse_down[3] = {false, false, false};
  float wheel = 0;
  bool clicked_left = false;        // pressed since the last frame (maybe released already)
  bool ctrl = false;                // held while `keys` were pressed
  std::vector<ViewKey> keys;        // pressed since the last frame
  std::vector<unsigned> chars;      // typed since the last frame (Unicode code points)
};

// The frame drawn by a FrameRenderer (colorbar, time, outlines; no VTK force plot) on the left and
// the ImGui panel (field and frame pickers, force against displacement with the current frame
// marked, last results) on the right, off-screen.
class InspectorView {
 public:
  InspectorView(int width, int height, bool smooth = true);
  ~InspectorView();
  InspectorView(const InspectorView&) = delete;
  InspectorView& operator=(const InspectorView&) = delete;

  // With `input`, the panel sees the mouse and `changes` receives what the user picked.
  RgbImage render(const InspectorState& s, const ViewInput* input = nullptr,
                  std::vector<InspectAction>* changes = nullptr);
  int width() const { return width_; }
  int height() const { return height_; }
  int panel_x0() const { return width_ - panel_w_; }  // the ImGui panel's left edge
  const FrameLayout& frame_layout() const;

 private:
  int width_, height_, panel_w_;
  bool smooth_;
  std::string renderer_field_;
  std::unique_ptr<FrameRenderer> frame_;
  std::unique_ptr<class ImGuiOffscreen> ui_;
  // the last field image and what it showed: redrawn only when the frame or field changes
  RgbImage field_image_;
  std::string drawn_field_;
  std::string drawn_path_;
  bool drawn_overlay_ = false;
};

// Draws the inspector panel as ImGui calls inside the current frame (window at x0, full height,
// `width` wide) and returns what the user changed (a field or frame picked).
std::vector<InspectAction> draw_inspector_panel(const InspectorState& s, float x0, float width, float height);

}  // namespace furrow::render
