// The paper's movie layouts as styles: dimensionless fields and time (its Movie S4 and Figure 8
// show velocity over the plate's speed and strain rate over 1/t0, t0 = L/v, time as t/t0).
#pragma once
#include <string>

#include "engine/scene/scene.hpp"
#include "render/frame_renderer.hpp"

namespace furrow::render {

// The scales of a scene's reference body (the first that moves): its largest speed v and its size
// L across its travel (a plate pushed down: its width; a dragged cylinder: its diameter).
struct BodyScales {
  std::string body;
  double speed_m_s = 0, length_m = 0;
};
// Throws std::runtime_error naming `source` when no body moves.
BodyScales body_scales(const Scene& scene, const std::string& source);
std::string scales_text(const BodyScales& s);  // "v = 0.1 m/s, L = 0.1 m (body plate)"

// Draws style->field dimensionless: velocity (and its components) over v, strain rate over v/L
// (the colorbar says which), time as t v/L; other fields keep their units. The title names the
// scales. style->range, in SI on entry, is scaled with the values.
void normalize_style(const BodyScales& scales, FrameStyle* style);

}  // namespace furrow::render
