// A fixed, known scene (flat-coloured disk + caption on a plain background) used by the smoke
// tests and `furrow demo` to prove that headless VTK rendering works on this machine.
#pragma once
#include <cstdint>

#include "render/image_io.hpp"

namespace furrow::render {

struct TestSceneLayout {
  double disk_center_x_px = 0, disk_center_y_px = 0;  // image coordinates, top row is y = 0
  double disk_radius_px = 0;
  uint8_t background[3] = {32, 48, 64};
  uint8_t disk[3] = {230, 120, 20};
  // The caption sits in the bottom-left corner, inside this box (pixels, top-left origin).
  int caption_x0 = 0, caption_y0 = 0, caption_x1 = 0, caption_y1 = 0;
};

TestSceneLayout test_scene_layout(int width, int height);

// Renders the scene off-screen (OSMesa); no display needed.
RgbImage render_test_scene(int width, int height);

}  // namespace furrow::render
