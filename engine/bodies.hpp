// Kinematic rigid intruders: signed-distance shapes with prescribed motion.
#pragma once
#include <vector>

#include "engine/scene/scene.hpp"

namespace furrow {

// Signed distance (m) from point q (body frame) to the shape; negative inside.
double shape_sdf(const Shape& s, const Vec2& q);
// Outward unit normal of the shape at q (body frame), from the distance field's gradient.
Vec2 shape_normal(const Shape& s, const Vec2& q, double h);
// Outline polygon(s) of the shape in the body frame, flattened into one closed loop per part.
std::vector<std::vector<Vec2>> shape_outline(const Shape& s, int circle_segments = 48);
// The shape's boundary as drawn (body frame, closed counter-clockwise loops, holes clockwise): the
// outline for a circle, box or polygon; for a union, the zero contour of its distance field on a
// lattice of `cells` along its longer side (the parts' inner edges are not boundary).
std::vector<std::vector<Vec2>> shape_boundary(const Shape& s, int cells = 256);
// Smallest feature size (circle diameter, box min side, polygon min extent).
double shape_min_size(const Shape& s);
// Area (m^2 per metre) and second moment of area about the body's origin (m^4 per metre), by
// midpoint quadrature on a 512 x 512 grid over its bounds: a union's overlaps count once. Relative
// error ~1e-4 for a circle (its edge cells).
struct ShapeMass {
  double area_m2 = 0.0, second_moment_m4 = 0.0;
};
ShapeMass shape_mass_properties(const Shape& s);
// (bounds and prescribed motion: shape_bounds_m, motion_velocity_m_s, motion_displacement_m in
// engine/scene/scene_io.hpp, shared with scene validation)

}  // namespace furrow
