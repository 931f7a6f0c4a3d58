// Foundation smoke test: VTK draws off-screen through OSMesa with no display and no GL noise.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "render/test_scene.hpp"
#include "tests/render/capture_output.hpp"

using namespace furrow::render;

namespace {
int max_channel_diff(const uint8_t* a, const uint8_t* b) {
  int d = 0;
  for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a[c]) - int(b[c])));
  return d;
}
}  // namespace

TEST(VtkSmoke, DrawsDiskOnBackgroundWithoutDisplay) {
  ASSERT_EQ(std::getenv("DISPLAY") == nullptr || std::string(std::getenv("DISPLAY")).empty(), true)
      << "this test must prove rendering works with DISPLAY unset";
  const int w = 320, h = 240;
  RgbImage img;
  const std::string noise = furrow::test::capture_output([&] { img = render_test_scene(w, h); });
  EXPECT_FALSE(furrow::test::mentions_gl_trouble(noise)) << "render printed:\n" << noise;
  ASSERT_EQ(img.width, w);
  ASSERT_EQ(img.height, h);

  const TestSceneLayout L = test_scene_layout(w, h);
  // Inside the disk (up to 90% of its radius, clear of edge anti-aliasing): the flat disk colour.
  int inside = 0, inside_ok = 0, outside = 0, outside_ok = 0;
  int bad_x0 = w, bad_y0 = h, bad_x1 = -1, bad_y1 = -1;  // where stray pixels are, for the message
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double r = std::hypot(x + 0.5 - L.disk_center_x_px, y + 0.5 - L.disk_center_y_px);
      const bool in_caption = x >= L.caption_x0 && x < L.caption_x1 && y >= L.caption_y0 && y < L.caption_y1;
      if (r < 0.9 * L.disk_radius_px) {
        ++inside;
        inside_ok += max_channel_diff(img.at(x, y), L.disk) <= 2;
      } else if (r > 1.1 * L.disk_radius_px && !in_caption) {
        ++outside;
        const bool ok = max_channel_diff(img.at(x, y), L.background) == 0;
        outside_ok += ok;
        if (!ok) {
          bad_x0 = std::min(bad_x0, x), bad_y0 = std::min(bad_y0, y);
          bad_x1 = std::max(bad_x1, x), bad_y1 = std::max(bad_y1, y);
        }
      }
    }
  // The disk covers pi (0.9 r)^2 pixels; all of them must carry the disk colour (±2 for rounding).
  EXPECT_NEAR(inside, M_PI * std::pow(0.9 * L.disk_radius_px, 2), 0.02 * inside);
  EXPECT_EQ(inside_ok, inside);
  EXPECT_GT(outside, w * h / 2);
  EXPECT_EQ(outside_ok, outside) << "background pixels well outside the disk must be untouched; stray pixels in x "
                                 << bad_x0 << ".." << bad_x1 << ", y " << bad_y0 << ".." << bad_y1;

  // The caption (FreeType text) put light pixels in its box.
  int text_px = 0;
  for (int y = L.caption_y0; y < L.caption_y1; ++y)
    for (int x = L.caption_x0; x < L.caption_x1; ++x) text_px += img.at(x, y)[0] > 160;
  EXPECT_GT(text_px, 50) << "no caption text drawn";
}

TEST(VtkSmoke, RenderingTwiceGivesIdenticalPixels) {
  const RgbImage a = render_test_scene(160, 120);
  const RgbImage b = render_test_scene(160, 120);
  EXPECT_EQ(a.rgb, b.rgb);
}
