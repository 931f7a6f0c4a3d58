// The force panel's data from a run's forces.csv (header t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m;
// F is the force of the media on the body, per metre out of plane).
//
// Per body: displacement = distance from its first recorded position (mm); force = the resisting
// component, -F . d, with d the unit direction of the body's overall travel (first to last
// position). For a plate pushed down that is Fy; for a body dragged along +x it is -Fx (drag).
// If no body moves, the panel plots |F| against time instead.
#pragma once
#include <string>

#include "render/frame_renderer.hpp"

namespace furrow::render {

// Throws std::runtime_error naming the file and line for a missing column or a malformed row.
ForcePanel read_force_panel(const std::string& forces_csv_path);

// Each series' running mean over `window` of travel (in the panel's x units; one cell, so what is
// left of the cell's own ripple averages out) drawn over the raw trace, which stays as a faint line
// behind it (`furrow render --force-mean`). The title says so. A panel against time (no body
// moves) or window <= 0 is returned unchanged.
ForcePanel with_running_mean(const ForcePanel& panel, double window, const std::string& window_text);

}  // namespace furrow::render
