// Foundation smoke test: Dear ImGui (OpenGL3 backend built by the project) draws into an OSMesa
// buffer with no display.
#include <gtest/gtest.h>

#include <imgui.h>

#include "render/imgui_offscreen.hpp"
#include "tests/render/capture_output.hpp"

using namespace furrow::render;

TEST(ImGuiSmoke, WindowWithTextIsDrawnOffscreen) {
  const int w = 400, h = 300;
  const float clear[3] = {0.2f, 0.6f, 0.3f};  // green: unlike any colour of the dark style
  ImVec2 win_min, win_max, text_min, text_max;
  RgbImage img;
  const std::string noise = furrow::test::capture_output([&] {
    ImGuiOffscreen ui(w, h);
    auto draw = [&] {
      ImGui::SetNextWindowPos(ImVec2(40, 30));
      ImGui::SetNextWindowSize(ImVec2(300, 200));
      ImGui::Begin("Furrow inspector");
      ImGui::Text("strain rate  1.23e+01 1/s");
      text_min = ImGui::GetItemRectMin();
      text_max = ImGui::GetItemRectMax();
      win_min = ImGui::GetWindowPos();
      win_max = ImVec2(win_min.x + ImGui::GetWindowSize().x, win_min.y + ImGui::GetWindowSize().y);
      ImGui::End();
    };
    ui.frame(draw, clear);  // first frame: builds the font atlas and lays the window out
    img = ui.frame(draw, clear);
  });
  EXPECT_FALSE(furrow::test::mentions_gl_trouble(noise)) << "ImGui printed:\n" << noise;
  ASSERT_EQ(img.width, w);
  ASSERT_EQ(img.height, h);
  EXPECT_FLOAT_EQ(win_min.x, 40.f);
  EXPECT_FLOAT_EQ(win_max.y, 230.f);

  const uint8_t clear8[3] = {uint8_t(0.2f * 255 + 0.5f), uint8_t(0.6f * 255 + 0.5f), uint8_t(0.3f * 255 + 0.5f)};
  auto is_clear = [&](int x, int y) {
    const uint8_t* p = img.at(x, y);
    return std::abs(p[0] - clear8[0]) <= 1 && std::abs(p[1] - clear8[1]) <= 1 && std::abs(p[2] - clear8[2]) <= 1;
  };
  // Outside the window: exactly the clear colour.
  int outside = 0, outside_clear = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (x < win_min.x - 2 || x > win_max.x + 2 || y < win_min.y - 2 || y > win_max.y + 2) {
        ++outside;
        outside_clear += is_clear(x, y);
      }
  EXPECT_EQ(outside_clear, outside);
  // Inside the window (clear of its border): nothing shows the clear colour through.
  int inside = 0, inside_clear = 0;
  for (int y = int(win_min.y) + 3; y < int(win_max.y) - 3; ++y)
    for (int x = int(win_min.x) + 3; x < int(win_max.x) - 3; ++x) {
      ++inside;
      inside_clear += is_clear(x, y);
    }
  EXPECT_EQ(inside_clear, 0) << "of " << inside << " window pixels";
  // Text: light glyph pixels on the dark window background inside the text item's rectangle.
  int bright = 0, total = 0;
  for (int y = int(text_min.y); y < int(text_max.y); ++y)
    for (int x = int(text_min.x); x < int(text_max.x); ++x) {
      ++total;
      const uint8_t* p = img.at(x, y);
      bright += p[0] > 180 && p[1] > 180 && p[2] > 180;
    }
  EXPECT_GT(total, 100);
  EXPECT_GT(bright, total / 20) << "no text glyphs in the text rectangle";
  EXPECT_LT(bright, total / 2);
  // Title bar text exists too.
  int title_bright = 0;
  for (int y = int(win_min.y); y < int(win_min.y) + 18; ++y)
    for (int x = int(win_min.x) + 20; x < int(win_min.x) + 140; ++x) title_bright += img.at(x, y)[0] > 180;
  EXPECT_GT(title_bright, 20);
}
