// The force panel's data from a run's forces.csv (header t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m;
// F is the force of the media on the body, per metre out of plane).
//
// Per body: displacement = distance from its first recorded position (mm); force = the resisting
// component, -F . d, with d the unit direction of the body's overall travel (first to last
// position). For a plate pushed down that is Fy; for a body dragged along +x it is -Fx (drag).
// If no body moves, the panel plots |F| against time instead.
//
// A forces.csv with the motion columns (torque_N_m_per_m, angle_deg, vx_m_s, vy_m_s, omega_rad_s)
// also gives ForcePanel::rows for each body that turns or has a free DOF (scene.json beside
// forces.csv says which; without it a body turns when its angle or angular velocity is ever
// nonzero): torque (N m/m) of every such body and depth below its start (mm, positive down) of a
// body with free y, both drawn under the force chart; speed (m/s) of a body with free x or y and
// its angle (deg), for the inspector. An older forces.csv, or a run whose bodies all follow a
// motion without turning, has no rows and renders as before.
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
