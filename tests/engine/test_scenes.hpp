// Small programmatic scenes for engine tests (no JSON involved).
#pragma once
#include "engine/scene/scene.hpp"

namespace furrow::test_scenes {

inline Material glass_beads(double mu = 0.4) {
  Material m;
  m.name = "glass_beads";
  m.model = MaterialModel::NDPM;
  m.grain_density_kg_m3 = 2520.0;
  m.phi_c = 0.60;
  m.mu = mu;
  m.youngs_modulus_Pa = 5.0e6;
  m.poisson_ratio = 0.3;
  return m;
}

// A bed of material m, width w and depth h at packing phi filling the bottom of a domain
// (w x h+air): slip side walls, friction floor, open top.
inline Scene bed_scene(const Material& m, double w, double h, double air, double dx, double end_time_s,
                       double packing_fraction) {
  Scene s;
  s.name = "test_bed";
  s.domain = {w, h + air, dx};
  s.solver.end_time_s = end_time_s;
  s.materials.push_back(m);
  Bed b;
  b.material = m.name;
  b.min_m = Vec2(0.0, 0.0);
  b.max_m = Vec2(w, h);
  b.packing_fraction = packing_fraction;
  s.beds.push_back(b);
  s.walls.left = {Wall::Kind::Slip, 0.0};
  s.walls.right = {Wall::Kind::Slip, 0.0};
  s.walls.bottom = {Wall::Kind::Friction, 0.4};
  s.walls.top = {Wall::Kind::Open, 0.0};
  return s;
}

// The same with NDPM glass beads at phi_c.
inline Scene bed_scene(double w, double h, double air, double dx, double end_time_s) {
  return bed_scene(glass_beads(), w, h, air, dx, end_time_s, 0.60);
}

// A box plate of size (L, t) starting with its bottom `gap` above the bed surface, moving at v.
inline Body plate(double L, double t, double x_center, double bottom_y, Vec2 velocity) {
  Body b;
  b.name = "plate";
  b.shape.kind = Shape::Kind::Box;
  b.shape.size_m = Vec2(L, t);
  b.start_m = Vec2(x_center, bottom_y + 0.5 * t);
  b.motion.velocity_m_s = velocity;
  b.friction = 0.35;
  return b;
}

}  // namespace furrow::test_scenes
