#include "app/interactive/scene_editor.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "app/scene_summary.hpp"
#include "engine/io/atomic_file.hpp"
#include "engine/io/field_store.hpp"
#include "engine/scene/scene_io.hpp"
#include "app/interactive/inspector.hpp"
#include "render/script.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

const char* const kEditScriptHelp =
    "One action per line; '#' starts a comment. Lengths in metres; BODY and BED are a name or an index.\n"
    "  set KEY.PATH VALUE [; KEY VALUE ...]  as --set KEY.PATH=VALUE (VALUE is JSON, else a string); several\n"
    "                                      keys after ';' are set together, all or none (a free DOF and its mass)\n"
    "  move BODY X Y                       the body's start position (bodies.BODY.start_m)\n"
    "  resize BODY W H                     a box body's full width and height (shape.size_m)\n"
    "  bed BED X0 Y0 X1 Y1                 a bed's lower-left and upper-right corners\n"
    "  validate                            the summary of 'furrow validate'\n"
    "  save PATH [--overwrite]             the resolved scene JSON (never over a file without --overwrite)\n"
    "  screenshot PATH                     PNG of the view: the scene drawing + the panel (never overwrites)\n"
    "  preview DIR [SECONDS]               a short run of the scene as edited into the new run directory DIR\n"
    "                                      (default 0.2 s simulated; dx coarsened to ~20k particles, at most\n"
    "                                      4000 steps); the view then shows its last stored frame\n"
    "An edit that makes the scene invalid is refused (\"ok\": false, the validation message) and the\n"
    "scene stays as it was; the script goes on and furrow edit exits 1 at the end.\n";

namespace {
std::string json_pair(const Vec2& v) { return nlohmann::json::array({v.x(), v.y()}).dump(); }
}  // namespace

std::vector<std::string> split_assignments(const std::string& key, const std::string& text, std::string* error) {
  std::vector<std::string> parts(1);
  bool in_string = false;
  for (size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (c == '"' && (k == 0 || text[k - 1] != '\\')) in_string = !in_string;
    if (c == ';' && !in_string) parts.emplace_back();
    else parts.back() += c;
  }
  auto trim = [](std::string t) {
    t.erase(0, t.find_first_not_of(" \t"));
    t.erase(t.find_last_not_of(" \t\r") + 1);
    return t;
  };
  std::vector<std::string> out = {key + "=" + trim(parts[0])};
  for (size_t k = 1; k < parts.size(); ++k) {
    const std::string part = trim(parts[k]);
    const size_t gap = part.find_first_of(" \t");
    if (part.empty() || gap == std::string::npos) {
      *error = "expected 'KEY.PATH VALUE' after ';' (got '" + part + "')";
      return {};
    }
    out.push_back(part.substr(0, gap) + "=" + trim(part.substr(gap)));
  }
  return out;
}

std::optional<EditAction> parse_edit_line(const std::string& line, std::string* error) {
  error->clear();
  const std::vector<std::string> w = render::script_words(line);
  if (w.empty()) return std::nullopt;
  const std::string& verb = w[0];
  std::vector<double> v;
  if (verb == "set") {
    // the value is the rest of the line, so JSON with spaces works
    if (w.size() < 3) return *error = "expected 'set KEY.PATH VALUE'", std::nullopt;
    const std::string body = line.substr(0, line.find('#'));
    const size_t key_at = body.find(w[1], body.find("set") + 3);
    std::vector<std::string> all = split_assignments(w[1], body.substr(key_at + w[1].size()), error);
    if (all.empty()) return std::nullopt;
    return SetKey{all.front(), std::vector<std::string>(all.begin() + 1, all.end())};
  }
  if (verb == "move" || verb == "resize") {
    const std::string expected = verb == "move" ? "move BODY X Y" : "resize BODY W H";
    if (w.size() != 4) return *error = "expected '" + expected + "'", std::nullopt;
    std::vector<std::string> nums = {w[0], w[2], w[3]};
    if (!render::script_numbers(nums, 2, 0, &v, expected, error)) return std::nullopt;
    if (verb == "move") return MoveBody{w[1], {v[0], v[1]}};
    return ResizeBody{w[1], {v[0], v[1]}};
  }
  if (verb == "bed") {
    if (w.size() != 6) return *error = "expected 'bed BED X0 Y0 X1 Y1'", std::nullopt;
    std::vector<std::string> nums = {w[0], w[2], w[3], w[4], w[5]};
    if (!render::script_numbers(nums, 4, 0, &v, "bed BED X0 Y0 X1 Y1", error)) return std::nullopt;
    return SetBed{w[1], {v[0], v[1]}, {v[2], v[3]}};
  }
  if (verb == "validate") {
    if (w.size() != 1) return *error = "expected 'validate' alone", std::nullopt;
    return Validate{};
  }
  if (verb == "save") {
    if (w.size() == 2) return Save{w[1], false};
    if (w.size() == 3 && w[2] == "--overwrite") return Save{w[1], true};
    return *error = "expected 'save PATH [--overwrite]' (a path without spaces)", std::nullopt;
  }
  if (verb == "screenshot") {
    if (w.size() != 2) return *error = "expected 'screenshot PATH' (a path without spaces)", std::nullopt;
    return EditScreenshot{w[1]};
  }
  if (verb == "preview") {
    const std::string expected = "preview DIR [SECONDS]";
    if (w.size() != 2 && w.size() != 3) return *error = "expected '" + expected + "'", std::nullopt;
    RunPreview p{w[1], 0.2};
    if (w.size() == 3) {
      std::vector<std::string> nums = {w[0], w[2]};
      if (!render::script_numbers(nums, 1, 0, &v, expected, error)) return std::nullopt;
      if (!(v[0] > 0 && v[0] <= 10)) return *error = "expected '" + expected + "' with 0 < SECONDS <= 10", std::nullopt;
      p.seconds = v[0];
    }
    return p;
  }
  *error = "expected one of set, move, resize, bed, validate, save, screenshot, preview";
  return std::nullopt;
}

std::vector<EditStep> parse_edit_script(const std::string& path) {
  std::vector<EditStep> steps;
  render::parse_script_lines(path, [&](int n, const std::string& line) {
    std::string error;
    if (auto a = parse_edit_line(line, &error)) steps.push_back({n, *a});
    return error;
  });
  return steps;
}

EditorState open_scene_for_edit(const std::string& arg) {
  EditorState s;
  std::string text;
  if (fs::is_regular_file(arg)) {
    std::ifstream in(arg, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    if (!in) throw std::runtime_error(arg + ": cannot read the scene");
    text = ss.str(), s.source = arg;
  } else if (const SceneTemplate* t = find_scene_template(arg)) {
    text = t->text, s.source = "template " + t->name;
  } else {
    throw std::runtime_error(arg + ": neither a scene file nor a template name (see 'furrow templates')");
  }
  // parse_scene_text checks the text (duplicate keys, depth) and the scene; the raw document is
  // what gets edited, so a shape's type can still change later
  s.scene = parse_scene_text(text, s.source);
  s.doc = nlohmann::json::parse(text);
  return s;
}

namespace {
// The overrides applied to a copy of the document and validated: the edited copy and its scene,
// or the SceneError that refuses them. The one check behind script edits, drags and typed values.
struct Attempt {
  nlohmann::json doc;
  Scene scene;
  std::optional<SceneError> error;
};
Attempt attempt(const EditorState& s, const std::vector<std::string>& assignments) {
  Attempt a;
  try {
    a.doc = s.doc;
    for (const auto& x : assignments) apply_override(a.doc, x, s.source);
    a.scene = parse_scene(a.doc, s.source);
  } catch (const SceneError& e) {
    a.error = e;
  }
  return a;
}

// Applies the overrides when valid; otherwise the state stays as it was.
nlohmann::json edit(EditorState& s, const std::string& action, const std::vector<std::string>& assignments) {
  nlohmann::json r = {{"action", action}, {"set", assignments}};
  Attempt a = attempt(s, assignments);
  if (a.error) {
    r["ok"] = false, r["error"] = a.error->what(), r["key"] = a.error->path;
    s.refused = std::string("refused ") + action + ": " + a.error->what();
    return r;
  }
  s.doc = std::move(a.doc), s.scene = std::move(a.scene), s.refused.clear();
  s.preview_frame.reset();  // the view shows the scene as edited again, not an older preview
  r["ok"] = true;
  s.notes.push_back(action + ": " + assignments.front() + (assignments.size() > 1 ? " ..." : ""));
  return r;
}

std::string body_key(const std::string& body) { return "bodies." + body; }

const Body* find_body(const Scene& scene, const std::string& name_or_index) {
  for (size_t k = 0; k < scene.bodies.size(); ++k)
    if (scene.bodies[k].name == name_or_index || std::to_string(k) == name_or_index) return &scene.bodies[k];
  return nullptr;
}

// A refused action; only a refused edit marks the panel's status (a failed save or preview leaves
// the scene as valid as it was).
nlohmann::json refused(EditorState& s, const std::string& action, const std::string& message) {
  if (action != "save" && action != "screenshot" && action != "preview") s.refused = "refused " + action + ": " + message;
  else s.notes.push_back(action + " failed: " + message);
  return {{"action", action}, {"ok", false}, {"error", message}};
}
}  // namespace

nlohmann::json apply_edit(EditorState& s, const EditAction& action, render::SceneView* view) {
  nlohmann::json r;
  if (auto* a = std::get_if<SetKey>(&action)) {
    std::vector<std::string> all = {a->assignment};
    all.insert(all.end(), a->more.begin(), a->more.end());
    r = edit(s, "set", all);
  } else if (auto* a = std::get_if<MoveBody>(&action)) {
    r = edit(s, "move", {body_key(a->body) + ".start_m=" + json_pair(a->start_m)});
  } else if (auto* a = std::get_if<ResizeBody>(&action)) {
    const Body* b = find_body(s.scene, a->body);
    if (b && b->shape.kind != Shape::Kind::Box)
      r = refused(s, "resize", "body '" + a->body + "' is not a box; set its shape keys instead");
    else
      r = edit(s, "resize", {body_key(a->body) + ".shape.size_m=" + json_pair(a->size_m)});
  } else if (auto* a = std::get_if<SetBed>(&action)) {
    r = edit(s, "bed", {"beds." + a->bed + ".min_m=" + json_pair(a->min_m), "beds." + a->bed + ".max_m=" + json_pair(a->max_m)});
  } else if (std::get_if<Validate>(&action)) {
    r = {{"action", "validate"}, {"ok", true}, {"valid", true}, {"summary", scene_summary(s.scene, s.source)}};
    s.notes.push_back("valid");
  } else if (auto* a = std::get_if<Save>(&action)) {
    try {
      write_text_atomically(a->path, format_scene(s.scene), a->overwrite, "add --overwrite to replace it");
      r = {{"action", "save"}, {"ok", true}, {"path", a->path}};
      s.notes.push_back("saved " + a->path);
    } catch (const std::runtime_error& e) {
      r = refused(s, "save", e.what());
    }
  } else if (auto* a = std::get_if<RunPreview>(&action)) {
    r = start_preview(s, *a);
    if (r.is_null()) r = finish_preview(s, true);
  } else if (auto* a = std::get_if<EditScreenshot>(&action)) {
    if (!view) throw std::logic_error("screenshot needs a SceneView");
    try {
      const render::PreviewFrame* shown = s.preview_frame ? &*s.preview_frame : nullptr;
      render::write_png(view->render(s.scene, editor_panel(s), nullptr, nullptr, shown), a->path, false);
      const render::SceneLayout l = view->layout(s.scene);
      r = {{"action", "screenshot"}, {"ok", true}, {"path", a->path}, {"width", view->width()},
           {"height", view->height()}, {"panel_x0", view->panel_x0()},
           {"origin_px", {l.origin_x_px, l.origin_y_px}}, {"px_per_m", l.px_per_m}};
    } catch (const std::runtime_error& e) {
      r = refused(s, "screenshot", e.what());
    }
  }
  if (s.notes.size() > 6) s.notes.erase(s.notes.begin(), s.notes.end() - 6);
  return r;
}

namespace {
void flatten(const nlohmann::json& j, const std::string& prefix, std::vector<std::pair<std::string, std::string>>* out) {
  // short numeric arrays ([x, y]) read better on one line
  const bool leaf_array = j.is_array() && j.size() <= 4 &&
                          std::all_of(j.begin(), j.end(), [](const nlohmann::json& e) { return e.is_primitive(); });
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) flatten(it.value(), prefix.empty() ? it.key() : prefix + "." + it.key(), out);
  } else if (j.is_array() && !leaf_array && !j.empty()) {
    for (size_t k = 0; k < j.size(); ++k) flatten(j[k], prefix + "." + std::to_string(k), out);
  } else {
    out->push_back({prefix, j.dump()});
  }
}
}  // namespace

nlohmann::json start_preview(EditorState& s, const RunPreview& a) {
  if (s.preview && !s.preview->done())
    return refused(s, "preview", "a preview is running into " + s.preview->out_dir() + "; wait for it to end");
  finish_preview(s, true);  // a finished one's result is dropped: a new one starts
  PreviewCaps caps;
  caps.seconds = a.seconds;
  nlohmann::json capped;
  try {
    s.preview = std::make_shared<PreviewRun>(preview_scene(s.scene, caps, &capped), a.out_dir);
  } catch (const std::runtime_error& e) {  // SceneError too
    return refused(s, "preview", e.what());
  }
  s.preview_capped = capped;
  s.preview_shown = -1;
  s.preview_range.reset();
  s.preview_frame.reset();
  s.notes.push_back("preview into " + a.out_dir);
  return nullptr;
}

bool follow_preview(EditorState& s) {
  if (!s.preview) return false;
  const auto [number, path] = s.preview->latest();
  if (number < 0 || number == s.preview_shown) return false;
  FieldFrame f;
  try {
    f = read_frame(path);
  } catch (const std::runtime_error&) {
    return false;  // renamed into place just now: read from the run directory next time
  }
  const std::vector<std::string> stored = render::stored_fields(f);
  const std::string field =
      std::find(stored.begin(), stored.end(), "pressure") != stored.end() ? "pressure" : render::default_field(stored);
  if (field.empty()) return false;
  if (!s.preview_range || (s.preview_frame && s.preview_frame->field != field)) s.preview_range.emplace(field);
  s.preview_range->add(f);
  render::FieldRange range;
  try {
    range = s.preview_range->range();
  } catch (const std::runtime_error&) {
    return false;  // no material with a value yet
  }
  s.preview_frame = render::PreviewFrame{std::move(f), field, range};
  s.preview_shown = number;
  return true;
}

nlohmann::json finish_preview(EditorState& s, bool wait) {
  if (!s.preview || (!wait && !s.preview->done())) return nullptr;
  nlohmann::json r = {{"action", "preview"}};
  r.update(s.preview->finish());
  follow_preview(s);  // the last frame, from the run directory
  r["capped"] = s.preview_capped;
  if (s.preview_frame)
    r["shown"] = {{"frame", s.preview_shown}, {"field", s.preview_frame->field}, {"time_s", s.preview_frame->frame.time_s}};
  if (r.value("ok", false))
    s.notes.push_back("preview: " + std::to_string(r["frames"].get<int64_t>()) + " frames in " + r["path"].get<std::string>());
  else
    s.notes.push_back("preview failed: " + r.value("error", std::string()));
  s.preview.reset();
  return r;
}

std::string preview_dir_for(const std::string& scene) {
  fs::path p(scene);
  const fs::path base = fs::is_regular_file(p) ? p.parent_path() / (p.stem().string() + ".preview")
                                               : fs::path(p.filename().string() + ".preview");
  if (!fs::exists(base)) return base.string();
  for (int k = 2;; ++k) {
    const fs::path cand = base.string() + "_" + std::to_string(k);
    if (!fs::exists(cand)) return cand.string();
  }
}

nlohmann::json panel_edit(EditorState& s, const render::PanelChanges& e) {
  s.typing_key = e.key;
  if (e.key.empty()) {
    s.typing_error.clear();
    return nullptr;
  }
  std::string split_error;
  const std::vector<std::string> all = split_assignments(e.key, e.text, &split_error);
  if (all.empty()) {
    s.typing_error = split_error;
    return nullptr;
  }
  if (!e.committed) {
    const Attempt a = attempt(s, all);
    s.typing_error = a.error ? a.error->what() : "";
    return nullptr;
  }
  nlohmann::json r = apply_edit(s, SetKey{all.front(), std::vector<std::string>(all.begin() + 1, all.end())}, nullptr);
  s.typing_error = r["ok"] == true ? "" : r["error"].get<std::string>();
  return r;
}

render::ScenePanel editor_panel(const EditorState& s) {
  render::ScenePanel p;
  p.title = s.source;
  p.valid = s.refused.empty();
  p.status = p.valid ? "valid (furrow validate)" : s.refused;
  p.notes = s.notes;
  p.typing_key = s.typing_key, p.typing_error = s.typing_error;
  p.preview_running = s.preview && !s.preview->done();
  if (s.preview_frame) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "preview%s: frame %lld, t = %.3f s", p.preview_running ? " running" : "",
                  (long long)s.preview_shown, s.preview_frame->frame.time_s);
    p.preview_status = buf;
  } else if (p.preview_running) {
    p.preview_status = "preview starting";
  }
  flatten(scene_to_json(s.scene), "", &p.keys);
  // the rotation and response keys a body does not use yet (the resolved scene leaves them out),
  // after the body's own keys, so they can be typed into like the rest; a free DOF needs its mass
  // in the same edit: ["y"]; bodies.0.mass_kg_per_m 5
  for (size_t b = 0; b < s.scene.bodies.size(); ++b) {
    const Body& body = s.scene.bodies[b];
    const std::string prefix = "bodies." + std::to_string(b) + ".";
    std::vector<std::pair<std::string, std::string>> absent;
    if (body.start_angle_rad == 0.0) absent.push_back({prefix + "start_angle_deg", "0"});
    if (body.motion.kind == Motion::Kind::ConstantVelocity && body.motion.angular_velocity_rad_s == 0.0)
      absent.push_back({prefix + "motion.angular_velocity_rad_s", "0"});
    if (!body.dynamics.any_free()) absent.push_back({prefix + "free", "[]"});
    auto last = std::find_if(p.keys.rbegin(), p.keys.rend(), [&](const auto& kv) { return kv.first.rfind(prefix, 0) == 0; });
    p.keys.insert(last.base(), absent.begin(), absent.end());
  }
  return p;
}

}  // namespace furrow::cli
