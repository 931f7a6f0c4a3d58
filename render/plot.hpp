// Static XY charts (VTK charts, drawn off-screen) for sweep summaries and studies: one figure of
// one or more panels side by side, each with titled axes (units in the labels), a legend, optional
// log axes and a few lines of notes (e.g. fitted exponents). The caller decides what to plot.
#pragma once
#include <string>
#include <vector>

#include "render/image_io.hpp"

namespace furrow::render {

struct PlotSeries {
  std::string label;             // legend entry; empty: not in the legend
  std::vector<double> x, y;      // non-finite points (and non-positive ones on log axes) are skipped
  bool line = true;              // polyline through the points in the given order
  bool markers = true;
  bool dashed = false;           // e.g. fits
  int color = -1;                // palette index; -1: the series' position in the panel
  std::vector<std::string> point_labels;  // optional text beside each point (e.g. a study's dx)
};

struct PlotPanel {
  std::string title;
  std::string x_label, y_label;  // with units, e.g. "|z| / D" or "L (m)"
  bool log_x = false, log_y = false;
  bool y_from_zero = false;      // linear y axis includes 0
  bool legend_top = false;       // legend top right instead of bottom right
  std::vector<PlotSeries> series;
  std::vector<std::string> notes;  // drawn top-left inside the plot area, one per line
};

struct PlotFigure {
  std::string title;               // above all panels (may be empty)
  std::vector<PlotPanel> panels;   // laid out left to right
  int width = 1280, height = 720;  // pixels
};

// Renders the figure. Throws std::invalid_argument for an empty figure or a size below 64 px and
// std::runtime_error if no off-screen GL context can be made.
RgbImage render_figure(const PlotFigure& figure);

// render_figure + write_png (atomic publish; an existing file is replaced only with overwrite).
void write_figure_png(const PlotFigure& figure, const std::string& path, bool overwrite = false);

}  // namespace furrow::render
