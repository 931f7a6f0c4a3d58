#include "app/interactive/inspector.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <imgui.h>

#include "engine/io/field_store.hpp"
#include "render/field_movie.hpp"
#include "render/force_series.hpp"
#include "render/imgui_offscreen.hpp"
#include "render/script.hpp"

namespace fs = std::filesystem;

namespace furrow::render {

// ---- script --------------------------------------------------------------------------------------
const char* const kInspectScriptHelp =
    "One action per line; '#' starts a comment. Coordinates in metres, times in seconds.\n"
    "  field NAME                       select the field that profile and screenshot show\n"
    "  frame N                          go to stored frame N (frame_000NN.vdb)\n"
    "  time T_S                         go to the stored frame nearest to time T_S\n"
    "  probe X Y                        every stored field's value in the cell holding (X, Y)\n"
    "  profile X0 Y0 X1 Y1 [N]          the selected field at N points (default 50, 2..10000) along the segment\n"
    "  angle AX AY BX BY CX CY          the angle ABC at B (degrees)\n"
    "  length X0 Y0 X1 Y1               the distance (m)\n"
    "  screenshot PATH                  PNG of the view: the frame + the inspector panel\n"
    "  wedge                            the frame's rigid wedge as run.json's analysis stored it\n"
    "  wedge on|off                     show or hide the wedge overlay (flank lines, apex angle)\n"
    "  plot torque|depth|speed|angle    plot this against time for the bodies that turn or are free\n"
    "                                   (torque N m/m, depth below the start mm, speed m/s, angle deg)\n";


std::optional<InspectAction> parse_inspect_line(const std::string& line, std::string* error) {
  error->clear();
  const std::vector<std::string> w = script_words(line);
  if (w.empty()) return std::nullopt;
  const std::string& verb = w[0];
  std::vector<double> v;
  if (verb == "field") {
    if (w.size() != 2) return *error = "expected 'field NAME'", std::nullopt;
    if (!find_field(w[1])) {
      std::string known;
      for (const auto& f : field_registry()) known += (known.empty() ? "" : ", ") + f.name;
      return *error = "unknown field '" + w[1] + "' (fields: " + known + ")", std::nullopt;
    }
    return SelectField{w[1]};
  }
  if (verb == "frame") {
    if (!script_numbers(w, 1, 0, &v, "frame N", error) || v[0] < 0 || v[0] != std::floor(v[0]))
      return *error = "expected 'frame N' with N a frame number (0, 1, ...)", std::nullopt;
    return GoToFrame{int64_t(v[0])};
  }
  if (verb == "time") {
    if (!script_numbers(w, 1, 0, &v, "time T_S", error)) return std::nullopt;
    return GoToTime{v[0]};
  }
  if (verb == "probe") {
    if (!script_numbers(w, 2, 0, &v, "probe X Y", error)) return std::nullopt;
    return Probe{{v[0], v[1]}};
  }
  if (verb == "profile") {
    if (!script_numbers(w, 4, 1, &v, "profile X0 Y0 X1 Y1 [N]", error)) return std::nullopt;
    Profile p{{v[0], v[1]}, {v[2], v[3]}, 50};
    if (v.size() == 5) {
      if (v[4] < 2 || v[4] > 10000 || v[4] != std::floor(v[4]))
        return *error = "expected 'profile X0 Y0 X1 Y1 [N]' with N a whole number in 2..10000", std::nullopt;
      p.samples = int(v[4]);
    }
    if ((p.b_m - p.a_m).norm() == 0) return *error = "expected two different end points for 'profile'", std::nullopt;
    return p;
  }
  if (verb == "angle") {
    if (!script_numbers(w, 6, 0, &v, "angle AX AY BX BY CX CY", error)) return std::nullopt;
    const Angle a{{v[0], v[1]}, {v[2], v[3]}, {v[4], v[5]}};
    if ((a.a_m - a.b_m).norm() == 0 || (a.c_m - a.b_m).norm() == 0)
      return *error = "expected A and C away from the vertex B for 'angle'", std::nullopt;
    return a;
  }
  if (verb == "length") {
    if (!script_numbers(w, 4, 0, &v, "length X0 Y0 X1 Y1", error)) return std::nullopt;
    return Length{{v[0], v[1]}, {v[2], v[3]}};
  }
  if (verb == "screenshot") {
    if (w.size() != 2) return *error = "expected 'screenshot PATH' (a path without spaces)", std::nullopt;
    return Screenshot{w[1]};
  }
  if (verb == "wedge") {
    if (w.size() == 1) return ReportWedge{};
    if (w.size() == 2 && (w[1] == "on" || w[1] == "off")) return ShowWedge{w[1] == "on"};
    return *error = "expected 'wedge' or 'wedge on|off'", std::nullopt;
  }
  if (verb == "plot") {
    if (w.size() != 2 || (w[1] != "torque" && w[1] != "depth" && w[1] != "speed" && w[1] != "angle"))
      return *error = "expected 'plot torque|depth|speed|angle'", std::nullopt;
    return PlotMotion{w[1]};
  }
  *error = "expected one of field, frame, time, probe, profile, angle, length, screenshot, wedge, plot";
  return std::nullopt;
}

std::vector<ScriptStep> parse_inspect_script(const std::string& path) {
  std::vector<ScriptStep> steps;
  parse_script_lines(path, [&](int n, const std::string& line) {
    std::string error;
    if (auto a = parse_inspect_line(line, &error)) steps.push_back({n, *a});
    return error;
  });
  return steps;
}

// ---- state ---------------------------------------------------------------------------------------
namespace {
int64_t number_of(const std::string& frame_path) {
  const std::string stem = fs::path(frame_path).stem().string();  // frame_00042
  return std::stoll(stem.substr(stem.find('_') + 1));
}


std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

void go_to(InspectorState& s, size_t index) {
  s.frame = read_frame(s.frame_paths[index]);
  s.current = index;
}

void select_field(InspectorState& s, const std::string& name) {
  if (std::find(s.fields.begin(), s.fields.end(), name) == s.fields.end())
    throw std::runtime_error("field '" + name + "' is not stored in " + s.run_dir + " (stored: " + joined(s.fields) + ")");
  s.field = name;
}
}  // namespace

std::vector<std::string> stored_fields(const FieldFrame& f) {
  std::vector<std::string> names;
  for (const auto& info : field_registry())
    if (info.vector ? !f.velocity_x.empty() : f.scalars.count(info.name) > 0) names.push_back(info.name);
  return names;
}

std::string default_field(const std::vector<std::string>& stored) {
  for (const char* pick : {"strain_rate", "pressure", "velocity"})
    if (std::find(stored.begin(), stored.end(), pick) != stored.end()) return pick;
  return stored.empty() ? "" : stored.front();
}

namespace {
// run.json's analysis.wedge.frames: run_scene appends entry k as it writes frame k, so entry k
// belongs to frame number k; its time must agree (else the entry is not that frame's and is left out).
void read_wedge_analysis(InspectorState& s) {
  const fs::path path = fs::path(s.run_dir) / "run.json";
  if (!fs::exists(path)) return;
  std::ifstream in(path);
  nlohmann::json run;
  try {
    run = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path.string() + ": not valid JSON (" + e.what() + ")");
  }
  const nlohmann::json* frames = nullptr;
  if (run.contains("analysis") && run["analysis"].is_object() && run["analysis"].contains("wedge"))
    frames = &run["analysis"]["wedge"]["frames"];
  if (!frames) return;
  if (!frames->is_array()) throw std::runtime_error(path.string() + ": analysis.wedge.frames is not an array");
  s.wedge_analysis = true;
  for (size_t k = 0; k < s.frame_numbers.size(); ++k) {
    const auto n = size_t(s.frame_numbers[k]);
    if (n >= frames->size()) continue;
    const nlohmann::json& e = (*frames)[n];
    if (e.contains("t_s") && std::abs(e["t_s"].get<double>() - s.times_s[k]) <= 1e-9 * std::max(1.0, s.times_s[k]))
      s.wedge[s.frame_numbers[k]] = e;
  }
}
}  // namespace

std::optional<FrameOverlay> wedge_overlay(const nlohmann::json& e) {
  for (const char* key : {"face_y_m", "left_flank_x_m", "right_flank_x_m", "left_flank_deg", "right_flank_deg",
                          "apex_angle_deg", "height_m"})
    if (!e.contains(key) || !e[key].is_number()) return std::nullopt;
  const double y0 = e["face_y_m"], xl = e["left_flank_x_m"], xr = e["right_flank_x_m"], h = e["height_m"];
  const double tl = std::tan(e["left_flank_deg"].get<double>() * M_PI / 180.0),
               tr = std::tan(e["right_flank_deg"].get<double>() * M_PI / 180.0);
  // to the apex when the flanks meet near the region's bottom, else over the region's depth
  double z = h;
  if (e.contains("apex_depth_m") && e["apex_depth_m"].is_number()) {
    const double apex = e["apex_depth_m"];
    if (apex > 0 && apex <= 1.5 * h) z = apex;
  }
  FrameOverlay o;
  const Eigen::Vector2d left_end(xl + tl * z, y0 - z), right_end(xr - tr * z, y0 - z);
  o.segments_m.push_back({Eigen::Vector2d(xl, y0), left_end});
  o.segments_m.push_back({Eigen::Vector2d(xr, y0), right_end});
  char label[48];
  std::snprintf(label, sizeof label, "apex %.1f\u00b0", e["apex_angle_deg"].get<double>());
  o.label = label;
  // under the lower ends, a fifth of the face's width below
  o.label_m = Eigen::Vector2d(0.5 * (left_end.x() + right_end.x()), y0 - z - 0.2 * std::abs(xr - xl));
  return o;
}

InspectorState open_run(const std::string& run_dir, const std::string& field) {
  InspectorState s;
  s.run_dir = run_dir;
  s.frame_paths = list_frames(run_dir);
  if (s.frame_paths.empty()) throw std::runtime_error(run_dir + "/frames holds no frame_*.vdb files");
  for (const auto& p : s.frame_paths) s.frame_numbers.push_back(number_of(p));
  go_to(s, 0);
  s.fields = stored_fields(s.frame);
  const std::vector<FrameScan> scans = scan_frames(s.frame_paths, s.fields);
  for (size_t k = 0; k < s.fields.size(); ++k) s.ranges[s.fields[k]] = scans[k].range;
  s.times_s = scans.empty() ? std::vector<double>{} : scans.front().times_s;
  if (!field.empty()) select_field(s, field);
  else s.field = default_field(s.fields);
  read_wedge_analysis(s);
  const fs::path forces = fs::path(run_dir) / "forces.csv";
  if (fs::exists(forces)) {
    ForcePanel panel = read_force_panel(forces.string());
    if (!panel.series.empty()) s.forces = panel;
    if (!panel.series.empty() && !panel.rows.empty()) s.motion = panel.rows.front().key;
  }
  return s;
}

// ---- measurements --------------------------------------------------------------------------------
bool cell_at(const FieldFrame& f, const Eigen::Vector2d& p_m, int* i, int* j) {
  const double u = (p_m.x() - f.origin_m.x()) / f.dx_m, v = (p_m.y() - f.origin_m.y()) / f.dx_m;
  if (!(u >= 0 && v >= 0 && u < f.nx && v < f.ny)) return false;
  *i = int(u), *j = int(v);
  return true;
}

std::string body_at(const FieldFrame& f, const Eigen::Vector2d& p) {
  for (const auto& b : f.bodies) {
    // even-odd rule over the outline polygon
    bool inside = false;
    const auto& o = b.outline_m;
    for (size_t k = 0, l = o.size() - 1; k < o.size(); l = k++)
      if ((o[k].y() > p.y()) != (o[l].y() > p.y()) &&
          p.x() < o[l].x() + (p.y() - o[l].y()) * (o[k].x() - o[l].x()) / (o[k].y() - o[l].y()))
        inside = !inside;
    if (inside) return b.name;
  }
  return "";
}

double angle_deg(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d u = a - b, v = c - b;
  return std::atan2(std::abs(u.x() * v.y() - u.y() * v.x()), u.dot(v)) * 180.0 / M_PI;
}

namespace {
nlohmann::json point(const Eigen::Vector2d& p) { return nlohmann::json::array({p.x(), p.y()}); }

nlohmann::json where(const InspectorState& s) {
  return {{"frame", s.frame_numbers[s.current]}, {"time_s", s.frame.time_s}};
}

// A cell value as JSON: null without material (and for NaN).
nlohmann::json cell_value(const FieldFrame& f, const std::string& field, size_t k) {
  const bool material = f.active.size() != size_t(f.nx) * size_t(f.ny) || f.active[k];
  if (!material) return nullptr;
  if (field == "velocity") return nlohmann::json::array({f.velocity_x[k], f.velocity_y[k]});
  const float v = f.scalars.at(field)[k];
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json probe(const InspectorState& s, const Probe& a) {
  nlohmann::json r = {{"action", "probe"}, {"x_m", a.p_m.x()}, {"y_m", a.p_m.y()}};
  r.update(where(s));
  int i = 0, j = 0;
  const bool in_grid = cell_at(s.frame, a.p_m, &i, &j);
  const size_t k = in_grid ? s.frame.index(i, j) : 0;
  r["cell"] = in_grid ? nlohmann::json::array({i, j}) : nlohmann::json(nullptr);
  r["material"] = in_grid && (s.frame.active.empty() || s.frame.active[k]);
  nlohmann::json values = nlohmann::json::object(), units = nlohmann::json::object();
  for (const auto& field : s.fields) {
    values[field] = in_grid ? cell_value(s.frame, field, k) : nlohmann::json(nullptr);
    units[field] = find_field(field)->unit;
  }
  r["values"] = values;
  r["units"] = units;
  const std::string body = body_at(s.frame, a.p_m);
  r["inside_body"] = body.empty() ? nlohmann::json(nullptr) : nlohmann::json(body);
  return r;
}

nlohmann::json profile(const InspectorState& s, const Profile& a) {
  nlohmann::json r = {{"action", "profile"}, {"field", s.field}, {"unit", find_field(s.field)->unit},
                      {"from", point(a.a_m)}, {"to", point(a.b_m)}, {"samples", a.samples}};
  r.update(where(s));
  const std::vector<float> v = field_values(s.frame, s.field);  // |v| for velocity, NaN without material
  nlohmann::json x = nlohmann::json::array(), y = nlohmann::json::array(), d = nlohmann::json::array(),
                 values = nlohmann::json::array();
  const double len = (a.b_m - a.a_m).norm();
  for (int n = 0; n < a.samples; ++n) {
    const double t = double(n) / (a.samples - 1);
    const Eigen::Vector2d p = a.a_m + t * (a.b_m - a.a_m);
    int i = 0, j = 0;
    const float val = cell_at(s.frame, p, &i, &j) ? v[s.frame.index(i, j)] : NAN;
    x.push_back(p.x()), y.push_back(p.y()), d.push_back(t * len);
    values.push_back(std::isfinite(val) ? nlohmann::json(val) : nlohmann::json(nullptr));
  }
  r["s_m"] = d, r["x_m"] = x, r["y_m"] = y, r["values"] = values;
  return r;
}

size_t nearest_time(const InspectorState& s, double t) {
  size_t best = 0;
  for (size_t k = 1; k < s.times_s.size(); ++k)
    if (std::abs(s.times_s[k] - t) < std::abs(s.times_s[best] - t)) best = k;
  return best;
}

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}
}  // namespace

nlohmann::json write_screenshot(const InspectorState& s, const std::string& path, const RgbImage& img,
                                const InspectorView& view) {
  write_png(img, path, false);
  // where the bed landed (bed_origin_px: the pixel of the frame's origin), so a reader can find
  // world points in the image
  const FrameLayout& L = view.frame_layout();
  nlohmann::json r = {{"action", "screenshot"}, {"path", path}, {"width", img.width}, {"height", img.height},
                      {"panel_x0", view.panel_x0()}, {"field", s.field}, {"bed_origin_px", {L.bed_x0, L.bed_y1}},
                      {"px_per_m", L.px_per_m}};
  r.update(where(s));
  return r;
}

nlohmann::json apply_action(InspectorState& s, const InspectAction& action, InspectorView* view) {
  nlohmann::json r;
  if (auto* a = std::get_if<PlotMotion>(&action)) {
    const MotionRow* row = nullptr;
    std::string have;
    if (s.forces)
      for (const MotionRow& m : s.forces->rows) {
        if (m.key == a->key) row = &m;
        have += (have.empty() ? "" : ", ") + m.key;
      }
    if (!row)
      throw std::runtime_error(s.run_dir + "/forces.csv has no " + a->key + " to plot (" +
                               (have.empty() ? "no body turns or is free, or forces.csv predates torque and angle"
                                             : "it has " + have) + ")");
    s.motion = a->key;
    // each body's value at the current frame's time
    nlohmann::json values = nlohmann::json::object();
    for (const ForceSeries& ser : row->series) values[ser.label] = value_at_time(ser, ser.y, s.frame.time_s);
    r = {{"action", "plot"}, {"quantity", a->key}, {"label", row->y_label}, {"values", values}};
    r.update(where(s));
    s.notes.push_back("plot " + row->y_label);
  } else if (auto* a = std::get_if<SelectField>(&action)) {
    select_field(s, a->name);
    const FieldRange& range = s.ranges.at(s.field);
    r = {{"action", "field"}, {"field", s.field}, {"unit", find_field(s.field)->unit},
         {"range", {range.lo, range.hi}}, {"log", range.log}};
    s.notes.push_back("field " + s.field);
  } else if (auto* a = std::get_if<GoToFrame>(&action)) {
    auto it = std::find(s.frame_numbers.begin(), s.frame_numbers.end(), a->number);
    if (it == s.frame_numbers.end())
      throw std::runtime_error("frame " + std::to_string(a->number) + " is not stored in " + s.run_dir + " (frames " +
                               std::to_string(s.frame_numbers.front()) + ".." + std::to_string(s.frame_numbers.back()) + ")");
    go_to(s, size_t(it - s.frame_numbers.begin()));
    r = {{"action", "frame"}};
    r.update(where(s));
  } else if (auto* a = std::get_if<GoToTime>(&action)) {
    go_to(s, nearest_time(s, a->t_s));
    r = {{"action", "time"}, {"requested_s", a->t_s}};
    r.update(where(s));
  } else if (auto* a = std::get_if<Probe>(&action)) {
    r = probe(s, *a);
    const auto& v = r["values"][s.field];
    s.notes.push_back("probe (" + short_number(a->p_m.x()) + ", " + short_number(a->p_m.y()) + ") m: " + s.field + " " +
                      (v.is_number() ? short_number(v.get<double>()) + " " + find_field(s.field)->unit : "no material"));
  } else if (auto* a = std::get_if<Profile>(&action)) {
    r = profile(s, *a);
    s.notes.push_back("profile of " + s.field + ", " + std::to_string(a->samples) + " points");
  } else if (auto* a = std::get_if<Angle>(&action)) {
    r = {{"action", "angle"}, {"a", point(a->a_m)}, {"b", point(a->b_m)}, {"c", point(a->c_m)},
         {"deg", angle_deg(a->a_m, a->b_m, a->c_m)}};
    s.notes.push_back("angle " + short_number(r["deg"].get<double>()) + " deg");
  } else if (auto* a = std::get_if<Length>(&action)) {
    r = {{"action", "length"}, {"from", point(a->a_m)}, {"to", point(a->b_m)}, {"m", (a->b_m - a->a_m).norm()}};
    s.notes.push_back("length " + short_number(r["m"].get<double>()) + " m");
  } else if (auto* a = std::get_if<Screenshot>(&action)) {
    if (!view) throw std::logic_error("screenshot needs an InspectorView");
    r = write_screenshot(s, a->path, view->render(s), *view);
  } else if (std::get_if<ReportWedge>(&action) || std::get_if<ShowWedge>(&action)) {
    if (!s.wedge_analysis)
      throw std::runtime_error(s.run_dir + "/run.json holds no wedge analysis (analysis.wedge: runs of a plate moving "
                                           "vertically that store velocity frames have one)");
    if (auto* a = std::get_if<ShowWedge>(&action)) s.show_wedge = a->on;
    r = {{"action", "wedge"}, {"overlay", s.show_wedge}};
    const auto it = s.wedge.find(s.frame_numbers[s.current]);
    r["stored"] = it != s.wedge.end();
    r["lines"] = it != s.wedge.end() && wedge_overlay(it->second).has_value();
    if (std::get_if<ReportWedge>(&action) && it != s.wedge.end()) r.update(it->second);
    r.update(where(s));
    const nlohmann::json angle = it != s.wedge.end() ? it->second.value("apex_angle_deg", nlohmann::json()) : nullptr;
    s.notes.push_back(std::string("wedge") + (s.show_wedge ? "" : " (hidden)") + ": " +
                      (angle.is_number() ? "apex " + short_number(angle.get<double>()) + " deg" : "none in this frame"));
  }
  if (s.notes.size() > 8) s.notes.erase(s.notes.begin(), s.notes.end() - 8);
  return r;
}

// ---- view ----------------------------------------------------------------------------------------
namespace {
// Force at evenly spaced displacements (PlotLines spaces its values evenly).
std::vector<float> resample(const ForceSeries& s, int n, double x0, double x1) {
  std::vector<float> out;
  size_t k = 0;
  for (int m = 0; m < n; ++m) {
    const double x = x0 + (x1 - x0) * m / (n - 1);
    while (k + 1 < s.x.size() && s.x[k + 1] < x) ++k;
    if (k + 1 >= s.x.size() || s.x[k + 1] <= s.x[k]) {
      out.push_back(float(s.y[k]));
      continue;
    }
    const double w = std::clamp((x - s.x[k]) / (s.x[k + 1] - s.x[k]), 0.0, 1.0);
    out.push_back(float(s.y[k] + w * (s.y[k + 1] - s.y[k])));
  }
  return out;
}

// Linear interpolation of a series' x at time t.
double x_at_time(const ForceSeries& s, double t) {
  if (s.t_s.empty()) return 0;
  if (t <= s.t_s.front()) return s.x.front();
  for (size_t k = 1; k < s.t_s.size(); ++k)
    if (t <= s.t_s[k])
      return s.x[k - 1] + (s.x[k] - s.x[k - 1]) * (t - s.t_s[k - 1]) / std::max(1e-300, s.t_s[k] - s.t_s[k - 1]);
  return s.x.back();
}
}  // namespace

std::vector<InspectAction> draw_inspector_panel(const InspectorState& s, float x0, float width, float height) {
  std::vector<InspectAction> changes;
  ImGui::SetNextWindowPos(ImVec2(x0, 0));
  ImGui::SetNextWindowSize(ImVec2(width, height));
  ImGui::Begin("Inspector", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  ImGui::TextUnformatted(fs::path(s.run_dir).filename().string().c_str());
  // field picker
  int field_index = int(std::find(s.fields.begin(), s.fields.end(), s.field) - s.fields.begin());
  if (ImGui::BeginCombo("field", s.field.c_str())) {
    for (size_t k = 0; k < s.fields.size(); ++k)
      if (ImGui::Selectable(s.fields[k].c_str(), int(k) == field_index)) changes.push_back(SelectField{s.fields[k]});
    ImGui::EndCombo();
  }
  // frame picker
  int index = int(s.current);
  if (ImGui::SliderInt("frame", &index, 0, int(s.frame_paths.size()) - 1, "%d") && index != int(s.current))
    changes.push_back(GoToFrame{s.frame_numbers[size_t(index)]});
  ImGui::Text("frame %lld   t = %.4f s", (long long)s.frame_numbers[s.current], s.frame.time_s);
  if (s.wedge_analysis) {
    bool on = s.show_wedge;
    if (ImGui::Checkbox("wedge overlay", &on)) changes.push_back(ShowWedge{on});
    const auto it = s.wedge.find(s.frame_numbers[s.current]);
    const nlohmann::json angle = it != s.wedge.end() ? it->second.value("apex_angle_deg", nlohmann::json()) : nullptr;
    ImGui::SameLine();
    if (angle.is_number()) ImGui::Text("apex %.1f deg", angle.get<double>());
    else ImGui::TextUnformatted("no wedge in this frame");
  }
  ImGui::Separator();
  // force against displacement, the current frame marked
  if (s.forces) {
    const ForcePanel& fp = *s.forces;
    for (const ForceSeries& ser : fp.series) {
      if (ser.x.size() < 2) continue;
      // the movie panel's axes (a start-up impulse off the chart, named below)
      const ForceAxes axes = force_axes(&ser, 1);
      const double lo = axes.y_lo, hi = axes.y_hi, xmin = axes.x_lo, xmax = axes.x_hi;
      const std::vector<float> ys = resample(ser, 120, xmin, xmax);
      ImGui::Text("%s: %s", ser.label.c_str(), fp.y_label.c_str());
      ImGui::PlotLines("##force", ys.data(), int(ys.size()), 0, nullptr, float(lo), float(hi),
                       ImVec2(width - 20, 0.28f * height));
      const ImVec2 r0 = ImGui::GetItemRectMin(), r1 = ImGui::GetItemRectMax();
      const ImVec2 pad = ImGui::GetStyle().FramePadding;
      const double x_now = x_at_time(ser, s.frame.time_s);
      const double u = (xmax > xmin) ? (x_now - xmin) / (xmax - xmin) : 0.0;
      const float px = r0.x + pad.x + float(u) * (r1.x - r0.x - 2 * pad.x);
      ImGui::GetWindowDrawList()->AddLine(ImVec2(px, r0.y), ImVec2(px, r1.y), IM_COL32(255, 200, 0, 255), 2.0f);
      ImGui::Text("%s: %.4g .. %.4g", fp.x_label.c_str(), xmin, xmax);
      ImGui::Text("force %.4g .. %.4g", lo, hi);
      if (std::isfinite(axes.clipped_hi)) ImGui::Text("peak %.4g off the chart", axes.clipped_hi);
      if (std::isfinite(axes.clipped_lo)) ImGui::Text("low %.4g off the chart", axes.clipped_lo);
    }
    ImGui::Separator();
    // bodies that turn or are free: the picked quantity against time, the current time marked
    if (!fp.rows.empty()) {
      const MotionRow* row = &fp.rows.front();
      for (const MotionRow& m : fp.rows)
        if (m.key == s.motion) row = &m;
      if (ImGui::BeginCombo("plot", row->key.c_str())) {
        for (const MotionRow& m : fp.rows)
          if (ImGui::Selectable(m.key.c_str(), &m == row)) changes.push_back(PlotMotion{m.key});
        ImGui::EndCombo();
      }
      for (const ForceSeries& ser : row->series) {
        if (ser.x.size() < 2) continue;
        const ForceAxes axes = motion_row_axes(*row, &ser, 1);
        const std::vector<float> ys = resample(ser, 120, axes.x_lo, axes.x_hi);
        ImGui::Text("%s: %s", ser.label.c_str(), row->y_label.c_str());
        ImGui::PushID(&ser);
        ImGui::PlotLines("##motion", ys.data(), int(ys.size()), 0, nullptr, float(axes.y_lo), float(axes.y_hi),
                         ImVec2(width - 20, 0.16f * height));
        ImGui::PopID();
        const ImVec2 r0 = ImGui::GetItemRectMin(), r1 = ImGui::GetItemRectMax();
        const ImVec2 pad = ImGui::GetStyle().FramePadding;
        const double u = (axes.x_hi > axes.x_lo) ? (s.frame.time_s - axes.x_lo) / (axes.x_hi - axes.x_lo) : 0.0;
        const float px = r0.x + pad.x + float(std::clamp(u, 0.0, 1.0)) * (r1.x - r0.x - 2 * pad.x);
        ImGui::GetWindowDrawList()->AddLine(ImVec2(px, r0.y), ImVec2(px, r1.y), IM_COL32(255, 200, 0, 255), 2.0f);
        ImGui::Text("time (s): %.4g .. %.4g   now %.4g", axes.x_lo, axes.x_hi, value_at_time(ser, ser.y, s.frame.time_s));
      }
      ImGui::Separator();
    }
  }
  for (const auto& n : s.notes) ImGui::TextWrapped("%s", n.c_str());
  ImGui::End();
  return changes;
}

InspectorView::InspectorView(int width, int height, bool smooth)
    : width_(width), height_(height), panel_w_(std::clamp(width / 3, 200, 420)), smooth_(smooth) {
  if (width - panel_w_ < 64 || height < 64)
    throw std::invalid_argument("inspector view " + std::to_string(width) + "x" + std::to_string(height) +
                                " is too small (at least " + std::to_string(panel_w_ + 64) + "x64)");
}

InspectorView::~InspectorView() = default;

const FrameLayout& InspectorView::frame_layout() const {
  if (!frame_) throw std::logic_error("the view has not drawn a frame yet");
  return frame_->layout();
}

RgbImage InspectorView::render(const InspectorState& s, const ViewInput* input, std::vector<InspectAction>* changes) {
  if (!frame_ || renderer_field_ != s.field) {
    FrameStyle style;
    style.field = s.field;
    style.width = width_ - panel_w_, style.height = height_;
    style.range = s.ranges.at(s.field);
    style.smooth = smooth_;
    style.time_decimals = time_decimals_for(s.times_s);
    frame_ = std::make_unique<FrameRenderer>(style);
    renderer_field_ = s.field;
    drawn_path_.clear();
  }
  std::optional<FrameOverlay> overlay;
  if (s.show_wedge) {
    const auto it = s.wedge.find(s.frame_numbers[s.current]);
    if (it != s.wedge.end()) overlay = wedge_overlay(it->second);
  }
  if (drawn_path_ != s.frame_paths[s.current] || drawn_field_ != s.field || drawn_overlay_ != overlay.has_value()) {
    field_image_ = frame_->render(s.frame, overlay ? &*overlay : nullptr);
    drawn_path_ = s.frame_paths[s.current], drawn_field_ = s.field, drawn_overlay_ = overlay.has_value();
  }
  RgbImage out(width_, height_);
  out.blit(field_image_, 0, 0);
  const bool first = !ui_;
  if (first) ui_ = std::make_unique<ImGuiOffscreen>(panel_w_, height_);
  const float clear[3] = {1.0f, 1.0f, 1.0f};
  auto draw = [&] {
    std::vector<InspectAction> c = draw_inspector_panel(s, 0.0f, float(panel_w_), float(height_));
    if (changes) changes->insert(changes->end(), c.begin(), c.end());
  };
  if (first) ui_->frame(draw, clear);  // the first frame lays the windows out
  if (input) {
    ImGuiContext* previous = ImGui::GetCurrentContext();
    ImGui::SetCurrentContext(ui_->context());
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = input->mouse_x >= panel_x0() ? ImVec2(input->mouse_x - float(panel_x0()), input->mouse_y)
                                               : ImVec2(-FLT_MAX, -FLT_MAX);
    for (int b = 0; b < 3; ++b) io.MouseDown[b] = input->mouse_down[b] && input->mouse_x >= panel_x0();
    io.MouseWheel = input->wheel;
    ImGui::SetCurrentContext(previous);
  }
  out.blit(ui_->frame(draw, clear), panel_x0(), 0);
  return out;
}

}  // namespace furrow::render
