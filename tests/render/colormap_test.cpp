// The shipped colour tables: shape, anchors, and the perceptual properties they were made for.
#include <gtest/gtest.h>

#include <cmath>

#include <vtkLookupTable.h>
#include <vtkNew.h>

#include "render/colormap.hpp"

using namespace furrow::render;

namespace {
// CIE L* of an sRGB colour (D65), enough to check lightness ordering.
double lightness(const std::array<float, 3>& c) {
  auto lin = [](double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); };
  const double y = 0.2126729 * lin(c[0]) + 0.7151522 * lin(c[1]) + 0.0721750 * lin(c[2]);
  return y > std::pow(6.0 / 29, 3) ? 116 * std::cbrt(y) - 16 : y * std::pow(29.0 / 3, 3);
}
int to8(float v) { return int(std::lround(255 * v)); }
}  // namespace

TEST(Colormap, TablesHave256Entries) {
  for (const char* name : {"viridis", "magma", "coolwarm"}) EXPECT_EQ(load_colormap(name).rgb.size(), 256u) << name;
  const auto names = colormap_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "viridis"), names.end());
}

TEST(Colormap, ViridisAndMagmaEndAtTheirDefiningColours) {
  // viridis runs from #440154 to #fde725, magma from #000004 to #fcfdbf (8-bit, +-1 for rounding)
  const auto& v = load_colormap("viridis").rgb;
  EXPECT_NEAR(to8(v.front()[0]), 0x44, 1);
  EXPECT_NEAR(to8(v.front()[1]), 0x01, 1);
  EXPECT_NEAR(to8(v.front()[2]), 0x54, 1);
  EXPECT_NEAR(to8(v.back()[0]), 0xfd, 1);
  EXPECT_NEAR(to8(v.back()[1]), 0xe7, 1);
  EXPECT_NEAR(to8(v.back()[2]), 0x25, 1);
  const auto& m = load_colormap("magma").rgb;
  EXPECT_NEAR(to8(m.back()[0]), 0xfc, 1);
  EXPECT_NEAR(to8(m.back()[1]), 0xfd, 1);
  EXPECT_NEAR(to8(m.back()[2]), 0xbf, 1);
  // the mid colour of viridis is #21908c; our fit lands within a few 8-bit steps
  const auto& mid = load_colormap("viridis").at(0.5);
  EXPECT_NEAR(to8(mid[0]), 0x21, 6);
  EXPECT_NEAR(to8(mid[1]), 0x90, 6);
  EXPECT_NEAR(to8(mid[2]), 0x8c, 6);
}

TEST(Colormap, SequentialMapsGetStrictlyLighter) {
  for (const char* name : {"viridis", "magma"}) {
    const auto& t = load_colormap(name).rgb;
    for (size_t k = 1; k < t.size(); ++k) ASSERT_GT(lightness(t[k]), lightness(t[k - 1])) << name << " entry " << k;
    // lightness steps are even (perceptually uniform): none more than 2.5x another. Magma is
    // uniform in CAM02-UCS J', which near black grows much faster than CIE L*, so its first tenth
    // is left out of this L*-based check.
    double lo = 1e9, hi = 0;
    for (size_t k = std::string(name) == "magma" ? 26 : 1; k < t.size(); ++k) {
      const double d = lightness(t[k]) - lightness(t[k - 1]);
      lo = std::min(lo, d), hi = std::max(hi, d);
    }
    EXPECT_LT(hi / lo, 2.5) << name;
  }
}

TEST(Colormap, DivergingMapIsSymmetricInLightnessWithLightCentre) {
  const auto& t = load_colormap("coolwarm").rgb;
  for (size_t k = 0; k < t.size() / 2; ++k)
    EXPECT_NEAR(lightness(t[k]), lightness(t[t.size() - 1 - k]), 4.0) << k;
  EXPECT_GT(lightness(t[127]), 85.0);
  EXPECT_LT(lightness(t[0]), 55.0);
  EXPECT_GT(t[0][2], t[0][0]);      // blue end
  EXPECT_GT(t[255][0], t[255][2]);  // red end
}

TEST(Colormap, UnknownNameListsKnownOnes) {
  try {
    load_colormap("jet");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("viridis"), std::string::npos) << e.what();
  }
}

TEST(Colormap, FillsVtkLookupTable) {
  vtkNew<vtkLookupTable> lut;
  const auto& cm = load_colormap("viridis");
  fill_lookup_table(cm, lut);
  ASSERT_EQ(lut->GetNumberOfTableValues(), 256);
  double rgba[4];
  lut->GetTableValue(200, rgba);
  EXPECT_NEAR(rgba[1], cm.rgb[200][1], 0.5 / 255);  // VTK keeps 8-bit table entries
}
