// `furrow render` with several fields side by side, run as a user would.
#include <gtest/gtest.h>

#include <algorithm>

#include "render/colormap.hpp"
#include "render/image_io.hpp"
#include "tests/app/cli_fixture.hpp"
#include "tests/app/stored_run.hpp"

namespace {

using furrow::cli_test::StoredRun;

class RenderCli : public furrow::cli_test::CliFixture {
 protected:
  RenderCli() : CliFixture("furrow_render_cli_") {}
};

// Pixels in columns [x0, x1) within 2 (0..255 units) of an entry of `cmap`, and how many distinct
// entries they show.
std::pair<int, int> colormap_pixels(const furrow::render::RgbImage& img, int x0, int x1,
                                    const furrow::render::Colormap& cmap) {
  int n = 0;
  std::vector<bool> seen(cmap.rgb.size(), false);
  for (int y = 0; y < img.height; ++y)
    for (int x = x0; x < x1; ++x) {
      double d = 0;
      const int idx = cmap.nearest_index(img.at(x, y), &d);
      if (d < 2.0) ++n, seen[size_t(idx)] = true;
    }
  return {n, int(std::count(seen.begin(), seen.end(), true))};
}

TEST_F(RenderCli, TwoFieldsSideBySideEachWithItsColours) {
  const StoredRun stored(dir_);
  const std::string out = path("panels");
  const auto r = run({"render", dir_.string(), "--field", "strain_rate,pressure", "--png", "--frames", "2", "--size",
                      "960x320", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("strain_rate range"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("pressure range"), std::string::npos) << r.out;
  const auto img = furrow::render::read_png(out + "/frame_00002.png");
  ASSERT_EQ(img.width, 960);
  ASSERT_EQ(img.height, 320);
  // panels of 320 px: strain rate (magma), pressure (viridis), force plot
  const auto& magma = furrow::render::load_colormap("magma");
  const auto& viridis = furrow::render::load_colormap("viridis");
  const auto [sr_px, sr_colours] = colormap_pixels(img, 0, 320, magma);
  const auto [p_px, p_colours] = colormap_pixels(img, 320, 640, viridis);
  EXPECT_GT(sr_px, 8000);  // the bed's material alone is ~270 x 110 px
  EXPECT_GT(p_px, 8000);
  EXPECT_GT(sr_colours, 150);  // a full range of colours in each field and its colorbar
  EXPECT_GT(p_colours, 150);
  // neither field panel shows the other's colours (viridis' greens are not in magma)
  EXPECT_LT(colormap_pixels(img, 0, 320, viridis).first, sr_px / 10);
  EXPECT_LT(colormap_pixels(img, 320, 640, magma).first, p_px / 10);
  // the force plot: its blue series line in the last panel
  int blue = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 640; x < 960; ++x) {
      const uint8_t* p = img.at(x, y);
      blue += std::abs(p[0] - 31) < 40 && std::abs(p[1] - 92) < 40 && p[2] > p[0] + 80;
    }
  EXPECT_GT(blue, 30);
}

TEST_F(RenderCli, UnknownFieldInTheListIsAnErrorNamingIt) {
  const StoredRun stored(dir_);
  const auto r = run({"render", dir_.string(), "--field", "pressure,temperature", "--png", "--out", path("x")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("unknown field 'temperature'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("valid fields: velocity, pressure, strain_rate"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("x")));
  // a field the run did not store: the frame file and the fields it has
  const auto missing = run({"render", dir_.string(), "--field", "pressure,phi_d", "--png", "--out", path("y")});
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("frame_00000.vdb"), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("phi_d"), std::string::npos) << missing.err;
}

}  // namespace
