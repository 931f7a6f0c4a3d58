// Material points drawn as discs coloured by their own value, as the paper's figures draw them:
// each point of a points file (engine/io/point_store.hpp) becomes a disc of its own area (radius
// sqrt(V / pi)) on a grid `sub` times finer than the frame's cells, which the renderer then draws
// flat. Later points cover earlier ones where discs overlap (the solver's order).
#pragma once
#include <string>
#include <vector>

#include "engine/fields.hpp"
#include "engine/io/point_store.hpp"

namespace furrow::render {

// The points as a FieldFrame over `grid`'s domain (its nx, ny, dx and origin; time, step and
// bodies from the points file), `sub` texels per cell along each axis, holding `fields` (display
// names: velocity and its components, pressure, strain_rate, plastic_strain, packing_fraction,
// phi_d). Throws std::runtime_error naming `source` for a field the points file does not hold.
FieldFrame splat_points(const PointFrame& points, const FieldFrame& grid, int sub,
                        const std::vector<std::string>& fields, const std::string& source);

// The points file beside a frame file: frames/frame_00042.vdb -> frames/points_00042.vdb.
std::string points_path_for(const std::string& frame_path);

}  // namespace furrow::render
