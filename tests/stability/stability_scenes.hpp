// Scenes of the stability suite: small beds of the templates' glass beads, one thread each (ctest
// runs the cases side by side), and the templates themselves with coarsening overrides.
#pragma once
#include <string>
#include <vector>

#include "engine/scene/scene.hpp"
#include "engine/scene/scene_io.hpp"
#include "tests/engine/test_scenes.hpp"

namespace furrow::stability {

constexpr double kG = 9.81;

// A bed w x h with `air_m` above it, dx, slip sides, friction floor, open top, one thread.
inline Scene bed(double w_m, double h_m, double air_m, double dx_m, double end_time_s) {
  Scene s = test_scenes::bed_scene(w_m, h_m, air_m, dx_m, end_time_s);
  s.name = "stability";
  s.solver.threads = 1;
  return s;
}

inline Body box(const char* name, Vec2 size_m, Vec2 centre_m, Vec2 velocity_m_s) {
  Body b = test_scenes::plate(size_m.x(), size_m.y(), centre_m.x(), centre_m.y() - 0.5 * size_m.y(), velocity_m_s);
  b.name = name;
  return b;
}

inline Body rod(const char* name, double radius_m, Vec2 centre_m, Vec2 velocity_m_s) {
  Body b;
  b.name = name;
  b.shape.kind = Shape::Kind::Circle;
  b.shape.radius_m = radius_m;
  b.start_m = centre_m;
  b.motion.velocity_m_s = velocity_m_s;
  b.friction = 0.35;
  return b;
}

// A shipped template with --set style overrides, always on one thread.
inline Scene from_template(const std::string& name, std::vector<std::string> overrides) {
  const SceneTemplate* t = find_scene_template(name);
  if (!t) throw std::runtime_error("no template " + name);
  overrides.push_back("solver.threads=1");
  return parse_scene_text(t->text, "<template " + name + ">", overrides);
}

inline const char* contact_name(ContactMethod c) { return contact_method_name(c); }
inline const char* shape_name(ShapeFunction f) {
  return f == ShapeFunction::Linear ? "linear" : f == ShapeFunction::Quadratic ? "quadratic" : "cubic";
}

}  // namespace furrow::stability
