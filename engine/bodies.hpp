// Kinematic rigid intruders: signed-distance shapes with prescribed motion.
#pragma once
#include <vector>

#include "engine/scene.hpp"

namespace furrow {

// Signed distance (m) from point q (body frame) to the shape; negative inside.
double shape_sdf(const Shape& s, const Vec2& q);
// Outward unit normal of the shape at q (body frame), from the distance field's gradient.
Vec2 shape_normal(const Shape& s, const Vec2& q, double h);
// Axis-aligned bounds of the shape in the body frame.
void shape_bounds(const Shape& s, Vec2& lo, Vec2& hi);
// Outline polygon(s) of the shape in the body frame, flattened into one closed loop per part.
std::vector<std::vector<Vec2>> shape_outline(const Shape& s, int circle_segments = 48);
// Smallest feature size (circle diameter, box min side, polygon min extent).
double shape_min_size(const Shape& s);

// Body velocity at time t and displacement over [0, t] (exact for piecewise-linear paths).
Vec2 body_velocity(const Motion& m, double t_s);
Vec2 body_displacement(const Motion& m, double t_s);

}  // namespace furrow
