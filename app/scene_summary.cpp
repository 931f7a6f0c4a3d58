#include "app/scene_summary.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "app/calibration.hpp"
#include "engine/fields.hpp"
#include "engine/scene/scene_io.hpp"

namespace furrow::cli {

namespace {

std::string fmt(const char* f, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

const char* kShapeNames[] = {"circle", "box", "polygon", "union"};
const char* kShapeFunctionNames[] = {"linear", "quadratic", "cubic"};

}  // namespace

// What a run of this scene will cost and produce, for people (stderr of `furrow validate`).
std::string scene_summary(const Scene& s, const std::string& source) {
  std::ostringstream os;
  const double dx = s.domain.dx_m, dt = estimate_time_step_s(s), t_end = estimate_end_time_s(s);
  const size_t particles = estimate_particle_count(s);
  const int64_t steps = estimate_step_count(s);
  os << "scene \"" << s.name << "\" (" << source << ") is valid\n";
  os << "  grid       " << long(std::ceil(s.domain.width_m / dx - 1e-9)) << " x "
     << long(std::ceil(s.domain.height_m / dx - 1e-9)) << " cells of " << fmt("%g", dx) << " m, "
     << kShapeFunctionNames[int(s.solver.shape_function)] << " B-splines\n";
  os << "  particles  ~" << particles << " (" << s.solver.particles_per_cell_1d << " x "
     << s.solver.particles_per_cell_1d << " per cell)\n";
  for (const auto& m : s.materials)
    os << "  material   " << m.name << ": " << (m.model == MaterialModel::DPM ? "DPM" : "NDPM")
       << ", wave speed " << fmt("%.3g", wave_speed_m_s(m)) << " m/s\n";
  for (const auto& b : s.bodies) {
    const double cells = body_cells_across(s, b), bias = contact_size_bias(s.solver.contact, cells);
    const double omega = motion_max_angular_speed_rad_s(b.motion);
    os << "  body       " << b.name << ": " << kShapeNames[int(b.shape.kind)] << ", " << fmt("%.3g", cells)
       << " cells across its travel, max speed " << fmt("%g", motion_max_speed_m_s(b.motion)) << " m/s";
    if (omega > 0.0) os << ", turning at up to " << fmt("%g", omega) << " rad/s";
    os << ", " << contact_method_name(s.solver.contact) << " contact";
    // a body driven to turn has no side inset to its field (engine/README.md); the plate bias was
    // measured on plates that do not turn
    if (omega > 0.0 && s.solver.contact == ContactMethod::CellFraction)
      os << " (driven to turn: its field acts up to a cell beyond its surface)";
    else if (cells < 8.0)
      os << " (under 8 cells across: its force depends strongly on dx and the contact method)";
    else if (omega == 0.0 && !b.dynamics.free_angle && std::abs(bias) >= 0.01)
      os << " (a plate this many cells across reads ~" << fmt("%.0f", 100 * std::abs(bias)) << "% "
         << (bias < 0 ? "low" : "high") << ": engine/README.md, \"Body contact\")";
    os << "\n";
  }
  os << "  time step  ~" << fmt("%.3g", dt) << " s (cfl " << fmt("%g", s.solver.cfl) << ")\n";
  os << "  end        t = " << fmt("%.4g", t_end) << " s";
  const int ref = reference_body_index(s);
  if (t_end < s.solver.end_time_s && ref >= 0)
    os << " (body \"" << s.bodies[size_t(ref)].name << "\" travels " << fmt("%g", s.solver.end_displacement_m) << " m)";
  os << "\n  steps      ~" << steps << ", " << fmt("%.3g", estimate_particle_steps(s)) << " particle-steps";
  if (steps > s.solver.max_steps) os << " (to solver.max_steps)";
  os << "\n";
  os << "  wall time  " << predicted_wall_text(s) << "\n";
  if (s.outputs.frame_interval_s > 0.0) {
    os << "  frames     " << long(std::floor(t_end / s.outputs.frame_interval_s + 1e-9)) + 1 << " every "
       << fmt("%g", s.outputs.frame_interval_s) << " s:";
    for (const auto& f : s.outputs.fields) os << " " << f;
    if (!s.outputs.movies.empty()) {
      os << "; movies:";
      for (const auto& f : s.outputs.movies) os << " " << f;
    }
    os << "\n";
  } else {
    os << "  frames     none (outputs.frame_interval_s = 0)\n";
  }
  if (steps > s.solver.max_steps)
    os << "  warning    solver.max_steps = " << s.solver.max_steps << " stops the run before its end\n";
  return os.str();
}

}  // namespace furrow::cli
