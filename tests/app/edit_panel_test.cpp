// The editor's panel, off-screen and in-process: a value typed into a key's row is checked as it
// is typed and set on Enter by the same code as the script's `set` (same messages, refused edits
// keep the scene); the preview button's run shows its stored frames in the view.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include "app/interactive/scene_editor.hpp"
#include "engine/scene/scene_io.hpp"

namespace {

using furrow::cli::EditorState;
using furrow::render::PanelChanges;
using furrow::render::SceneView;
using furrow::render::ViewInput;
using furrow::render::ViewKey;
using nlohmann::json;

// One window event: the view drawn with it, and the panel's changes handed to the editor as the
// window does. Returns panel_edit's result.
json event(EditorState& s, SceneView& view, ViewInput in) {
  PanelChanges c;
  view.render(s.scene, furrow::cli::editor_panel(s), &in, &c);
  json r = furrow::cli::panel_edit(s, c);
  if (!r.is_null() && r["ok"] == true) view.stop_editing();
  return r;
}

ViewInput typed(const std::string& text) {
  ViewInput in;
  for (char c : text) in.chars.push_back(unsigned(c));
  return in;
}

ViewInput pressed(ViewKey k) {
  ViewInput in;
  in.keys.push_back(k);
  return in;
}

TEST(EditPanel, ATypedValueIsCheckedAsTypedAndSetLikeTheScriptsSet) {
  EditorState s = furrow::cli::open_scene_for_edit("plate_intrusion");
  const json original = s.doc;
  SceneView view(1280, 720);
  view.render(s.scene, furrow::cli::editor_panel(s));
  const auto row = view.key_row_px("domain.dx_m");
  ASSERT_TRUE(row.has_value()) << "the row of domain.dx_m is not on the panel";
  EXPECT_GE(row->x(), view.panel_x0());

  // a click on the row opens its value for typing, the whole value selected
  ViewInput click;
  click.mouse_x = float(row->x()), click.mouse_y = float(row->y()), click.clicked_left = true;
  EXPECT_TRUE(event(s, view, click).is_null());
  EXPECT_EQ(view.editing_key(), "domain.dx_m");

  // an invalid value: the message is the script's, shown while typing; the scene stays
  EditorState script = furrow::cli::open_scene_for_edit("plate_intrusion");
  const json scripted = furrow::cli::apply_edit(script, furrow::cli::SetKey{"domain.dx_m=-0.5", {}}, nullptr);
  ASSERT_EQ(scripted["ok"], false);
  EXPECT_TRUE(event(s, view, typed("-0.5")).is_null());
  EXPECT_EQ(s.typing_key, "domain.dx_m");
  EXPECT_EQ(s.typing_error, scripted["error"].get<std::string>());
  EXPECT_NE(s.typing_error.find("/domain/dx_m"), std::string::npos) << s.typing_error;
  EXPECT_EQ(s.doc, original);
  // Enter: refused like `set`, with the same result; the row stays open for correcting
  json r = event(s, view, pressed(ViewKey::Enter));
  ASSERT_FALSE(r.is_null());
  EXPECT_EQ(r["action"], "set");
  EXPECT_EQ(r["ok"], false);
  EXPECT_EQ(r["error"], scripted["error"]);
  EXPECT_EQ(r["set"], scripted["set"]);
  EXPECT_EQ(s.refused, script.refused);
  EXPECT_EQ(s.doc, original);
  EXPECT_DOUBLE_EQ(s.scene.domain.dx_m, 0.01);
  EXPECT_EQ(view.editing_key(), "domain.dx_m");

  // corrected: the typed text is replaced (End, Backspace x4) and Enter sets it
  event(s, view, pressed(ViewKey::End));
  for (int k = 0; k < 4; ++k) event(s, view, pressed(ViewKey::Backspace));
  EXPECT_TRUE(event(s, view, typed("0.02")).is_null());
  EXPECT_EQ(s.typing_error, "");
  r = event(s, view, pressed(ViewKey::Enter));
  ASSERT_FALSE(r.is_null());
  EXPECT_EQ(r["ok"], true) << r.dump();
  EXPECT_EQ(r["set"], json::array({"domain.dx_m=0.02"}));
  EXPECT_DOUBLE_EQ(s.scene.domain.dx_m, 0.02);
  EXPECT_EQ(s.refused, "");
  EXPECT_EQ(view.editing_key(), "");
  // only that key changed
  const json diff = json::diff(original, s.doc);
  ASSERT_EQ(diff.size(), 1u) << diff.dump();
  EXPECT_EQ(diff[0]["path"], "/domain/dx_m");

  // Escape closes a row without setting anything
  event(s, view, click);
  event(s, view, typed("0.03"));
  event(s, view, pressed(ViewKey::Escape));
  EXPECT_EQ(view.editing_key(), "");
  EXPECT_DOUBLE_EQ(s.scene.domain.dx_m, 0.02);
}

TEST(EditPanel, PreviewCapsTheSceneAndLeavesItValid) {
  const EditorState s = furrow::cli::open_scene_for_edit("plate_intrusion");
  json capped;
  furrow::cli::PreviewCaps caps;
  caps.seconds = 0.05;
  caps.max_particles = 8000;
  const furrow::Scene p = furrow::cli::preview_scene(s.scene, caps, &capped);
  EXPECT_DOUBLE_EQ(p.solver.end_time_s, 0.05);
  EXPECT_LE(p.solver.max_steps, caps.max_steps);
  EXPECT_LE(furrow::estimate_particle_count(p), caps.max_particles);
  EXPECT_GT(p.domain.dx_m, s.scene.domain.dx_m);
  EXPECT_EQ(capped["domain.dx_m"], p.domain.dx_m);
  EXPECT_NEAR(p.outputs.frame_interval_s, 0.05 / caps.frames, 1e-15);
  EXPECT_NO_THROW(furrow::parse_scene(furrow::scene_to_json(p), "preview"));
}

}  // namespace

// A body is drawn at its start angle, as the solver places it: plate_intrusion's 0.1 x 0.02 m plate
// turned 90 degrees covers 40 mm above its centre and not 40 mm beside it; unturned, the reverse.
TEST(EditPanel, ABodyIsDrawnAtItsStartAngle) {
  EditorState s = furrow::cli::open_scene_for_edit("plate_intrusion");
  SceneView view(1280, 720);
  const auto body_px = [&](const furrow::Scene& scene, const Eigen::Vector2d& offset_m) {
    const furrow::render::RgbImage img = view.render(scene, furrow::cli::editor_panel(s));
    const Eigen::Vector2d p = view.layout(scene).to_px(scene.bodies[0].start_m + offset_m);
    const uint8_t* c = img.at(int(p.x()), int(p.y()));
    return c[0] == 90 && c[1] == 96 && c[2] == 110;  // the body's fill
  };
  furrow::Scene scene = s.scene;
  ASSERT_NEAR(scene.bodies[0].shape.size_m.x(), 0.1, 1e-12);
  ASSERT_NEAR(scene.bodies[0].shape.size_m.y(), 0.02, 1e-12);
  EXPECT_TRUE(body_px(scene, {0.04, 0.0}));
  EXPECT_FALSE(body_px(scene, {0.0, 0.04}));
  scene.bodies[0].start_angle_rad = M_PI / 2;
  EXPECT_FALSE(body_px(scene, {0.04, 0.0}));
  EXPECT_TRUE(body_px(scene, {0.0, 0.04}));
}

// Rotation and response from the panel: a body that neither turns nor responds still lists its
// start angle, angular velocity and free DOFs (the resolved scene leaves them out); a free DOF
// typed alone is refused for want of a mass, and typed with its mass after ';' is set, both at once.
TEST(EditPanel, RotationAndFreeDofsCanBeTypedIn) {
  EditorState s = furrow::cli::open_scene_for_edit("plate_intrusion");
  const auto panel = furrow::cli::editor_panel(s);
  auto value_of = [&](const std::string& key) -> std::string {
    for (const auto& kv : panel.keys)
      if (kv.first == key) return kv.second;
    return "(absent)";
  };
  EXPECT_EQ(value_of("bodies.0.start_angle_deg"), "0");
  EXPECT_EQ(value_of("bodies.0.motion.angular_velocity_rad_s"), "0");
  EXPECT_EQ(value_of("bodies.0.free"), "[]");
  SceneView view(1280, 720);
  view.render(s.scene, panel);
  ASSERT_TRUE(view.key_row_px("bodies.0.free").has_value());

  PanelChanges alone;
  alone.key = "bodies.0.free", alone.text = "[\"y\"]", alone.committed = true;
  const json refused = furrow::cli::panel_edit(s, alone);
  EXPECT_EQ(refused["ok"], false);
  EXPECT_NE(refused["error"].get<std::string>().find("mass"), std::string::npos) << refused["error"];
  EXPECT_FALSE(s.scene.bodies[0].dynamics.free_y);

  PanelChanges with_mass = alone;
  with_mass.text = "[\"y\"]; bodies.0.mass_kg_per_m 5";
  const json set = furrow::cli::panel_edit(s, with_mass);
  ASSERT_EQ(set["ok"], true) << set.dump();
  EXPECT_TRUE(s.scene.bodies[0].dynamics.free_y);
  EXPECT_DOUBLE_EQ(s.scene.bodies[0].dynamics.mass_kg_per_m, 5.0);
  // now from the resolved scene, with its value
  bool listed = false;
  for (const auto& kv : furrow::cli::editor_panel(s).keys) listed |= kv.first == "bodies.0.free" && kv.second == "[\"y\"]";
  EXPECT_TRUE(listed);
  // a part after ';' that is not KEY VALUE names itself
  std::string error;
  EXPECT_TRUE(furrow::cli::split_assignments("k", "1; bodies.0.mass_kg_per_m", &error).empty());
  EXPECT_NE(error.find("bodies.0.mass_kg_per_m"), std::string::npos) << error;
}
