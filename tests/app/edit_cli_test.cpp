// `furrow edit --headless --script`: edits are validated like `furrow validate`, refused edits
// leave the scene as it was, saves never clobber, screenshots show the scene and the panel.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <map>
#include <sstream>

#include "engine/scene_io.hpp"
#include "render/image_io.hpp"
#include "render/scene_view.hpp"
#include "tests/app/cli_fixture.hpp"
#include "tests/app/xvfb.hpp"

namespace {

namespace fs = std::filesystem;
using furrow::cli_test::read_text;
using nlohmann::json;

class EditCli : public furrow::cli_test::CliFixture {
 protected:
  EditCli() : CliFixture("furrow_edit_cli_") {}
  void SetUp() override {
    CliFixture::SetUp();
    // a resolved scene file, as `furrow new` writes it
    const auto r = run({"new", "plate_intrusion", "-o", path("orig.json")});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  furrow::cli_test::Result edit(const std::string& script_text, const std::string& size = "640x400") {
    std::ofstream(path("script.txt")) << script_text;
    return run({"edit", path("orig.json"), "--headless", "--script", path("script.txt"), "--size", size});
  }
  static std::vector<json> lines(const std::string& out) { return furrow::cli_test::json_lines(out); }
};

TEST_F(EditCli, ResizedBodySavedValidatesAndDiffersInThatKeyOnly) {
  const auto r = edit("# widen the plate\nresize plate 0.15 0.02\nsave " + path("edited.json") + "\n");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto results = lines(r.out);
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0]["action"], "resize");
  EXPECT_EQ(results[0]["ok"], true);
  EXPECT_EQ(results[0]["line"], 2);
  EXPECT_EQ(results[1]["action"], "save");
  EXPECT_EQ(results[1]["ok"], true);

  const furrow::Scene edited = furrow::load_scene(path("edited.json"));  // throws if invalid
  EXPECT_DOUBLE_EQ(edited.bodies[0].shape.size_m.x(), 0.15);
  const json diff = json::diff(json::parse(read_text(path("orig.json"))), json::parse(read_text(path("edited.json"))));
  ASSERT_EQ(diff.size(), 1u) << diff.dump();
  EXPECT_EQ(diff[0]["path"], "/bodies/0/shape/size_m/0");
  EXPECT_EQ(diff[0]["value"], 0.15);
}

TEST_F(EditCli, InvalidEditsAreRefusedNamingTheKeyAndChangeNothing) {
  const auto r = edit("set bodies.0.shape.size_m [-0.1,0.01]\nmove plate 5 0.3\nsave " + path("after.json") + "\n");
  EXPECT_EQ(r.status, 1) << r.err;
  const auto results = lines(r.out);
  ASSERT_EQ(results.size(), 3u) << r.out;
  EXPECT_EQ(results[0]["ok"], false);
  EXPECT_NE(results[0]["error"].get<std::string>().find("/bodies/0/shape/size_m"), std::string::npos) << results[0];
  EXPECT_EQ(results[1]["action"], "move");
  EXPECT_EQ(results[1]["ok"], false);
  EXPECT_NE(results[1]["error"].get<std::string>().find("/bodies/0/start_m"), std::string::npos) << results[1];
  EXPECT_EQ(results[2]["ok"], true);
  EXPECT_NE(r.err.find("script.txt:1:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("script.txt:2:"), std::string::npos) << r.err;
  EXPECT_EQ(json::parse(read_text(path("after.json"))), json::parse(read_text(path("orig.json"))));
}

TEST_F(EditCli, SaveNeverReplacesAFileWithoutOverwrite) {
  std::ofstream(path("existing.json")) << "keep me\n";
  const auto r = edit("move plate 0.5 0.65\nsave " + path("existing.json") + "\n");
  EXPECT_EQ(r.status, 1);
  const auto results = lines(r.out);
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[1]["ok"], false);
  EXPECT_NE(results[1]["error"].get<std::string>().find("exists"), std::string::npos) << results[1];
  EXPECT_EQ(read_text(path("existing.json")), "keep me\n");

  const auto again = edit("move plate 0.5 0.65\nsave " + path("existing.json") + " --overwrite\n");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_DOUBLE_EQ(furrow::load_scene(path("existing.json")).bodies[0].start_m.x(), 0.5);
}

TEST_F(EditCli, ScreenshotShowsTheBedToScaleAndThePanel) {
  const auto r = edit("screenshot " + path("view.png") + "\n");
  ASSERT_EQ(r.status, 0) << r.err;
  const json shot = lines(r.out).at(0);
  const auto img = furrow::render::read_png(path("view.png"));
  ASSERT_EQ(img.width, 640);
  ASSERT_EQ(img.height, 400);
  // the bed, [0, 1.2] x [0, 0.6] m, inset by 3 px: bed colour except where the plate overlaps
  const double ox = shot["origin_px"][0], oy = shot["origin_px"][1], s = shot["px_per_m"];
  const int x0 = int(ox + 3), x1 = int(ox + 1.2 * s - 3), y0 = int(oy - 0.6 * s + 3), y1 = int(oy - 3);
  ASSERT_LT(x0, x1);
  ASSERT_LT(y0, y1);
  int bed = 0, total = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x, ++total) {
      const uint8_t* p = img.at(x, y);
      bed += std::abs(p[0] - furrow::render::kBedRgb[0]) <= 2 && std::abs(p[1] - furrow::render::kBedRgb[1]) <= 2 &&
             std::abs(p[2] - furrow::render::kBedRgb[2]) <= 2;
    }
  EXPECT_GT(bed, 0.9 * total);
  // above the bed (0.65 m, away from the plate) is not bed colour
  const uint8_t* above = img.at(int(ox + 0.1 * s), int(oy - 0.65 * s));
  EXPECT_NE(above[0], furrow::render::kBedRgb[0]);
  // the panel holds text: many pixels off its most common colour
  const int px0 = shot["panel_x0"];
  std::map<int, int> counts;
  for (int y = 0; y < img.height; ++y)
    for (int x = px0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      ++counts[p[0] << 16 | p[1] << 8 | p[2]];
    }
  int most = 0;
  for (const auto& [c, n] : counts) most = std::max(most, n);
  const int panel = (img.width - px0) * img.height;
  EXPECT_GT(panel - most, panel / 50);
  EXPECT_GT(counts.size(), 10u);
}

TEST_F(EditCli, BadScriptLineNamesFileLineAndExpectation) {
  const auto r = edit("validate\nmove plate 0.1\nsave " + path("never.json") + "\n");
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("script.txt:2: expected 'move BODY X Y'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("never.json")));
}

TEST_F(EditCli, ValidatePrintsTheSummaryOfATemplate) {
  std::ofstream(path("script.txt")) << "validate\n";
  const auto r = run({"edit", "plate_intrusion", "--headless", "--script", path("script.txt")});
  ASSERT_EQ(r.status, 0) << r.err;
  const json v = lines(r.out).at(0);
  EXPECT_EQ(v["valid"], true);
  EXPECT_NE(v["summary"].get<std::string>().find("is valid"), std::string::npos);
}

}  // namespace

namespace {

TEST_F(EditCli, WindowUnderXvfbReplaysAScriptAndSaves) {
  if (std::system("command -v Xvfb >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "Xvfb is not installed (apt-get install xvfb, as .ci/setup.sh does): no display to open the window on";
  furrow::cli_test::Xvfb x;
  if (!x.up) GTEST_SKIP() << "Xvfb could not start on display :" << x.number;
  std::ofstream(path("script.txt")) << "move plate 0.4 0.64\nsave " + path("moved.json") + "\n";
  setenv("DISPLAY", (":" + std::to_string(x.number)).c_str(), 1);
  const auto r = run({"edit", path("orig.json"), "--script", path("script.txt"), "--exit-after-script"});
  unsetenv("DISPLAY");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(lines(r.out).size(), 2u) << r.out;
  EXPECT_DOUBLE_EQ(furrow::load_scene(path("moved.json")).bodies[0].start_m.x(), 0.4);
}

TEST_F(EditCli, WithoutADisplayTheWindowSaysUseHeadless) {
  const auto r = run({"edit", path("orig.json")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--headless --script FILE"), std::string::npos) << r.err;
}

}  // namespace
