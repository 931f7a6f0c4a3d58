#include "render/layouts.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "engine/scene/scene_io.hpp"

namespace furrow::render {

BodyScales body_scales(const Scene& scene, const std::string& source) {
  const int k = reference_body_index(scene);
  if (k < 0) throw std::runtime_error(source + ": no moving body to take the speed v and size L from");
  const Body& b = scene.bodies[size_t(k)];
  const Vec2 d = travel_direction(scene, b);
  const auto [lo, hi] = shape_bounds_m(b.shape);
  const Vec2 size = hi - lo;
  // the extent across the travel direction (exact for axis-aligned travel)
  BodyScales s{b.name, motion_max_speed_m_s(b.motion), std::abs(d.y()) * size.x() + std::abs(d.x()) * size.y()};
  if (!(s.speed_m_s > 0) || !(s.length_m > 0))
    throw std::runtime_error(source + ": body '" + b.name + "' has no speed or no size across its travel");
  return s;
}

std::string scales_text(const BodyScales& s) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "v = %.3g m/s, L = %.3g m (body %s)", s.speed_m_s, s.length_m, s.body.c_str());
  return buf;
}

void normalize_style(const BodyScales& sc, FrameStyle* style) {
  const FieldInfo* info = find_display_field(style->field);
  if (!info) throw std::invalid_argument("unknown field '" + style->field + "'");
  const bool velocity = style->field.rfind("velocity", 0) == 0, rate = style->field == "strain_rate";
  if (velocity || rate) {
    style->value_scale = velocity ? 1.0 / sc.speed_m_s : sc.length_m / sc.speed_m_s;
    style->value_title = info->label + (info->vector ? " magnitude" : "") + (velocity ? " / v" : " / (v/L)");
    style->range.lo *= style->value_scale, style->range.hi *= style->value_scale;
  }
  style->time_scale = sc.speed_m_s / sc.length_m;
  style->time_label = "t v/L";
  style->title = (style->title.empty() ? info->label : style->title) + ", " + scales_text(sc);
}

}  // namespace furrow::render
