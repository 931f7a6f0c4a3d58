// `furrow render`'s movie layouts, run as a user would: following a body, dimensionless fields,
// runs side by side, the poster beside a movie, and the errors that write nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "engine/io/point_store.hpp"
#include "engine/scene/scene_io.hpp"
#include "render/colormap.hpp"
#include "render/image_io.hpp"
#include "tests/app/cli_fixture.hpp"
#include "tests/app/stored_run.hpp"

namespace {

namespace fs = std::filesystem;
using furrow::cli_test::StoredRun;
using furrow::render::RgbImage;

// Centre of the cyan body outline's pixels (x, y); {-1, -1} when there are none.
std::pair<double, double> outline_centre(const RgbImage& img);

class RenderLayouts : public furrow::cli_test::CliFixture {
 protected:
  RenderLayouts() : CliFixture("furrow_render_layouts_") {}
  // The frames' outline centres of a --png render of this run with `extra` options.
  std::vector<std::pair<double, double>> centres(const std::string& out, const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"render", dir_.string(), "--field", "pressure", "--png", "--no-panel",
                                     "--size", "640x360", "--out", out};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = run(args);
    EXPECT_EQ(r.status, 0) << r.err;
    std::vector<std::pair<double, double>> c;
    for (int k = 0; k < StoredRun::kFrames; ++k) {
      char name[32];
      std::snprintf(name, sizeof name, "/frame_%05d.png", k);
      c.push_back(outline_centre(furrow::render::read_png(out + name)));
    }
    return c;
  }
};

// Centre of the cyan body outline's pixels (x, y); {-1, -1} when there are none.
std::pair<double, double> outline_centre(const RgbImage& img) {
  double sx = 0, sy = 0;
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      if (p[0] < 60 && p[1] > 180 && p[2] > 210) sx += x, sy += y, ++n;
    }
  return n ? std::pair{sx / n, sy / n} : std::pair{-1.0, -1.0};
}

// The plate sinks 2 mm a frame (~2 px here): followed, its outline stays within a pixel.
TEST_F(RenderLayouts, FrameOfKeepsTheBodyStillWhileTheBedMoves) {
  const StoredRun stored(dir_);
  const auto still = centres(path("follow"), {"--frame-of", "plate"});
  const auto moving = centres(path("fixed"), {});
  for (int k = 0; k < StoredRun::kFrames; ++k) {
    ASSERT_GE(still[size_t(k)].first, 0) << "no outline in frame " << k;
    EXPECT_NEAR(still[size_t(k)].first, still[0].first, 1.0) << k;
    EXPECT_NEAR(still[size_t(k)].second, still[0].second, 1.0) << k;
  }
  // the measure sees motion: without following, the outline goes down by ~2 px a frame
  EXPECT_GT(moving.back().second - moving.front().second, 4.5);
  // zoomed about the plate, still in place
  const auto zoomed = centres(path("zoom"), {"--frame-of", "plate", "--zoom", "3"});
  EXPECT_NEAR(zoomed.back().second, zoomed.front().second, 1.0);
}

// Velocity over the plate's speed and time as t v/L, with the scales from the run's scene.json.
TEST_F(RenderLayouts, NormalizePrintsItsScales) {
  const StoredRun stored(dir_);
  std::ofstream(dir_ / "scene.json") << furrow::find_scene_template("plate_intrusion")->text;
  const auto r = run({"render", dir_.string(), "--field", "velocity_y", "--normalize", "--png", "--frames", "1",
                      "--out", path("n")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("normalized by v = 0.1 m/s, L = 0.1 m (body plate)"), std::string::npos) << r.out;
  // without a scene.json there is nothing to normalize by: an error naming the file, nothing written
  fs::remove(dir_ / "scene.json");
  const auto bad = run({"render", dir_.string(), "--field", "velocity_y", "--normalize", "--png", "--out", path("m")});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("scene.json"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(path("m")));
}

// Two runs, one field: each panel its own run (the second run's pressure doubled), one colour range.
TEST_F(RenderLayouts, RunsSideBySideEachShowItsOwnRun) {
  const StoredRun a(dir_ / "a"), b(dir_ / "b");
  for (const auto& f : b.frames) {
    furrow::FieldFrame frame = furrow::read_frame(f);
    for (float& p : frame.scalars["pressure"]) p *= 2.0f;
    furrow::write_frame_vdb(f, frame);
  }
  auto panels_differ = [&](const std::string& second, const std::string& out) {
    const auto r = run({"render", (dir_ / "a").string(), second, "--field", "pressure", "--labels", "loose,dense",
                        "--png", "--frames", "2", "--no-panel", "--size", "960x320", "--out", out});
    EXPECT_EQ(r.status, 0) << r.err;
    const RgbImage img = furrow::render::read_png(out + "/frame_00002.png");
    EXPECT_EQ(img.width, 960);
    int differ = 0;  // below the title band, pixel by pixel between the two 480-px panels
    for (int y = 40; y < img.height; ++y)
      for (int x = 0; x < 480; ++x) {
        const uint8_t *p = img.at(x, y), *q = img.at(x + 480, y);
        differ += std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 30;
      }
    return differ;
  };
  EXPECT_GT(panels_differ((dir_ / "b").string(), path("ab")), 5000);
  EXPECT_LT(panels_differ((dir_ / "a").string(), path("aa")), 50);  // the same run twice: the same panels
}

TEST_F(RenderLayouts, BadLayoutsAreErrorsThatWriteNothing) {
  const StoredRun a(dir_ / "a");
  // a run of another domain (0.3 m wide instead of 0.4 m)
  furrow::FieldFrame other = furrow::test::hydrostatic_frame(60, 50, StoredRun::kDx, StoredRun::kSurface, 0.0);
  furrow::write_frame_vdb(furrow::frame_path((dir_ / "c").string(), 0), other);
  const auto domains = run({"render", (dir_ / "a").string(), (dir_ / "c").string(), "--field", "pressure", "--png",
                            "--out", path("x1")});
  EXPECT_EQ(domains.status, 1);
  EXPECT_NE(domains.err.find("domains differ"), std::string::npos) << domains.err;
  EXPECT_NE(domains.err.find((dir_ / "c").string()), std::string::npos) << domains.err;
  const auto body = run({"render", (dir_ / "a").string(), "--field", "pressure", "--frame-of", "wheel", "--png",
                         "--out", path("x2")});
  EXPECT_EQ(body.status, 1);
  EXPECT_NE(body.err.find("no body 'wheel'"), std::string::npos) << body.err;
  EXPECT_NE(body.err.find("bodies: plate"), std::string::npos) << body.err;
  const auto labels = run({"render", (dir_ / "a").string(), (dir_ / "a").string(), "--field", "pressure", "--labels",
                           "one", "--png", "--out", path("x3")});
  EXPECT_EQ(labels.status, 2);
  EXPECT_NE(labels.err.find("1 labels for 2 runs"), std::string::npos) << labels.err;
  const auto fields = run({"render", (dir_ / "a").string(), (dir_ / "a").string(), "--field", "pressure,strain_rate",
                           "--png", "--out", path("x4")});
  EXPECT_EQ(fields.status, 2);
  const auto unknown = run({"render", (dir_ / "a").string(), "--field", "velocity_z", "--png", "--out", path("x5")});
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.err.find("velocity_x, velocity_y"), std::string::npos) << unknown.err;
  for (const char* out : {"x1", "x2", "x3", "x4", "x5"}) EXPECT_FALSE(fs::exists(path(out))) << out;
}

// A movie gets its last frame as a poster beside it, at a frame rate that makes it last ~10 s
// (2 fps at least: four frames last 2 s).
TEST_F(RenderLayouts, MovieHasAPosterAndAFrameRateForItsLength) {
  const StoredRun stored(dir_);
  const std::string out = path("m.mp4");
  const auto r = run({"render", dir_.string(), "--field", "pressure", "--size", "640x360", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("at 2 fps"), std::string::npos) << r.out;
  ASSERT_TRUE(fs::exists(path("m.png")));
  const RgbImage poster = furrow::render::read_png(path("m.png"));
  EXPECT_EQ(poster.width, 640);
  EXPECT_EQ(poster.height, 360);
  // a second render to the same path is refused, and leaves both files as they were
  const auto again = run({"render", dir_.string(), "--field", "pressure", "--size", "640x360", "--out", out});
  EXPECT_EQ(again.status, 1);
}

}  // namespace

namespace {
// The material points drawn as discs: a run whose frames have points files beside them renders
// with --points; one without says which file is missing and writes nothing.
TEST_F(RenderLayouts, PointsRenderAsDiscsAndTheirAbsenceIsAnError) {
  const StoredRun stored(dir_);
  const auto missing = run({"render", dir_.string(), "--field", "pressure", "--points", "--png", "--out", path("p0")});
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("points_00000.vdb"), std::string::npos) << missing.err;
  EXPECT_FALSE(fs::exists(path("p0")));
  for (int k = 0; k < StoredRun::kFrames; ++k) {
    furrow::PointFrame pts;
    pts.dx_m = StoredRun::kDx;
    pts.time_s = 0.01 * k;
    for (int j = 0; j < 80; ++j)
      for (int i = 0; i < 160; ++i) {
        pts.x_m.push_back((i + 0.5) * 0.0025), pts.y_m.push_back((j + 0.5) * 0.0025);
        pts.vx_m_s.push_back(0.f), pts.vy_m_s.push_back(0.f), pts.volume_m2.push_back(float(0.0025 * 0.0025));
        pts.pressure_Pa.push_back(float(1000.0 * (0.2 - pts.y_m.back())));
      }
    furrow::write_points_vdb(furrow::points_path(dir_.string(), k), pts);
  }
  const auto r = run({"render", dir_.string(), "--field", "pressure", "--points", "--png", "--frames", "1",
                      "--no-panel", "--size", "640x360", "--out", path("p1")});
  ASSERT_EQ(r.status, 0) << r.err;
  const RgbImage img = furrow::render::read_png(path("p1") + "/points_00001.png");
  const auto& viridis = furrow::render::load_colormap("viridis");
  int coloured = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      double d = 0;
      viridis.nearest_index(img.at(x, y), &d);
      coloured += d < 2.0;
    }
  EXPECT_GT(coloured, 30000);  // the bed of points, ~0.4 x 0.2 m at ~1000 px/m
}
}  // namespace
