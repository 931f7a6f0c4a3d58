#include "render/field_panels.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace furrow::render {

namespace {
constexpr double kPlotFraction = 0.38;  // FrameRenderer's share of the width for the force plot
}

PanelsRenderer::PanelsRenderer(const PanelsStyle& style) : style_(style) {
  if (style.fields.empty()) throw std::invalid_argument("side-by-side panels need at least one field");
  const int count = int(style.fields.size()) + (style.forces ? 1 : 0);
  panel_w_ = (style.width / count) / 2 * 2;
  if (panel_w_ < 16)
    throw std::invalid_argument("image width " + std::to_string(style.width) + " leaves panels under 16 px for " +
                                std::to_string(count) + " panels");
  for (size_t k = 0; k < style.fields.size(); ++k) {
    FrameStyle s = style.fields[k];
    s.width = panel_w_, s.height = style.height;
    s.panel.reset();
    s.show_time = k == 0;
    s.font_scale = style.height / 720.0;  // the same text size in every panel
    fields_.push_back(std::make_unique<FrameRenderer>(s));
  }
  if (style.forces) {
    // FrameRenderer gives its plot the right 38% of its width: draw wide enough for a panel's
    // width of plot and keep only that part
    FrameStyle s = style.fields.front();
    s.width = int(std::ceil(panel_w_ / kPlotFraction / 2.0)) * 2;
    s.height = style.height;
    s.panel = style.forces;
    s.show_colorbar = false, s.show_title = false, s.show_time = false;
    s.font_scale = style.height / 720.0;
    forces_ = std::make_unique<FrameRenderer>(s);
  }
}

PanelsRenderer::~PanelsRenderer() = default;

RgbImage PanelsRenderer::render(const FieldFrame& frame) {
  return render(std::vector<const FieldFrame*>(fields_.size(), &frame));
}

RgbImage PanelsRenderer::render(const std::vector<const FieldFrame*>& frames) {
  if (frames.size() != fields_.size())
    throw std::invalid_argument(std::to_string(frames.size()) + " frames for " + std::to_string(fields_.size()) +
                                " side-by-side panels");
  const auto& bg = style_.fields.front().background_rgb;
  RgbImage out(style_.width, style_.height, uint8_t(std::lround(255 * bg[0])), uint8_t(std::lround(255 * bg[1])),
               uint8_t(std::lround(255 * bg[2])));
  for (size_t k = 0; k < fields_.size(); ++k) out.blit(fields_[k]->render(*frames[k]), panel_x0(k), 0);
  if (forces_) {
    const RgbImage full = forces_->render(*frames.front());
    RgbImage plot(panel_w_, style_.height);
    plot.blit(full, -forces_->layout().panel_x0, 0);
    out.blit(plot, panel_x0(fields_.size()), 0);
  }
  return out;
}

}  // namespace furrow::render
