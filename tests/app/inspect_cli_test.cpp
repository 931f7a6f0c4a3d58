// `furrow inspect --headless --script`, run as a user would with no display: probes equal the
// stored VDB values, profiles cross the free surface, a known angle, and a screenshot with the
// ImGui panel.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <signal.h>
#include <sys/wait.h>

#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <thread>

#include "engine/io/field_store.hpp"
#include "render/colormap.hpp"
#include "render/image_io.hpp"
#include "tests/app/cli_fixture.hpp"
#include "tests/app/stored_run.hpp"
#include "tests/app/xvfb.hpp"

namespace {

using furrow::cli_test::StoredRun;
using nlohmann::json;

// A screenshot of the view: the field in `colormap` colours left of x0 and the ImGui panel (a dark
// window with light text and the plot) from x0 on.
void expect_inspector_view(const furrow::render::RgbImage& img, int x0, const std::string& colormap) {
  int dark = 0, bright = 0, panel = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = x0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      ++panel;
      dark += p[0] < 120 && p[1] < 120 && p[2] < 120;
      bright += p[0] > 180 && p[1] > 180 && p[2] > 180 && x > x0 + 4 && y > 24;  // text on the dark window
    }
  EXPECT_GT(dark, panel / 2) << "the panel's dark window fills its region";
  EXPECT_GT(bright, 500) << "text and the plot in the panel";
  const auto& cmap = furrow::render::load_colormap(colormap);
  int field_px = 0;
  for (int y = 0; y < img.height; y += 2)
    for (int x = 0; x < x0; x += 2) {
      double d = 0;
      cmap.nearest_index(img.at(x, y), &d);
      field_px += d < 2.0;
    }
  EXPECT_GT(field_px, 10000) << "the field in " << colormap << " colours";
}

class InspectCli : public furrow::cli_test::CliFixture {
 protected:
  InspectCli() : CliFixture("furrow_inspect_cli_") {}
  std::string script(const std::string& text) {
    const std::string p = path("script.txt");
    std::ofstream(p) << text;
    return p;
  }
  static std::vector<json> lines(const std::string& out) { return furrow::cli_test::json_lines(out); }
};

TEST_F(InspectCli, ScriptedSessionProbesProfilesMeasuresAndScreenshots) {
  const StoredRun stored(dir_ / "run");
  const std::string shot = path("view.png");
  const auto r = run({"inspect", (dir_ / "run").string(), "--headless", "--script",
                      script("# a session on frame 2\n"
                             "field pressure\n"
                             "frame 2\n"
                             "probe 0.1025 0.0525\n"
                             "probe 0.1 0.23   # above the free surface\n"
                             "profile 0.0525 0.0025 0.0525 0.2425 25\n"
                             "angle 0.25 0.206 0.15 0.186 0.25 0.186\n"
                             "length 0.15 0.186 0.25 0.186\n"
                             "time 0.031\n"
                             "screenshot " + shot + "\n")});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<json> out = lines(r.out);
  ASSERT_EQ(out.size(), 9u) << r.out;
  EXPECT_EQ(out[0]["action"], "field");
  EXPECT_EQ(out[0]["unit"], "Pa");
  EXPECT_EQ(out[1]["frame"], 2);
  EXPECT_NEAR(out[1]["time_s"].get<double>(), 0.02, 1e-12);

  // probe: the values of cell (20, 10) of frame_00002.vdb read directly
  const furrow::FieldFrame f = furrow::read_frame(stored.frames[2]);
  const size_t k = f.index(20, 10);
  const json& probe = out[2];
  EXPECT_EQ(probe["line"], 4);
  EXPECT_EQ(probe["cell"], json::array({20, 10}));
  EXPECT_TRUE(probe["material"].get<bool>());
  EXPECT_EQ(float(probe["values"]["pressure"].get<double>()), f.scalars.at("pressure")[k]);
  EXPECT_EQ(float(probe["values"]["strain_rate"].get<double>()), f.scalars.at("strain_rate")[k]);
  EXPECT_EQ(float(probe["values"]["velocity"][0].get<double>()), f.velocity_x[k]);
  EXPECT_EQ(float(probe["values"]["velocity"][1].get<double>()), f.velocity_y[k]);
  EXPECT_EQ(probe["units"]["pressure"], "Pa");
  EXPECT_NEAR(probe["values"]["pressure"].get<double>(), 1.2 * 1512 * 9.81 * (0.2 - 0.0525), 0.1);
  EXPECT_TRUE(probe["inside_body"].is_null());
  EXPECT_FALSE(out[3]["material"].get<bool>());
  EXPECT_TRUE(out[3]["values"]["pressure"].is_null());

  // profile: 25 points 1 cm apart up x = 0.0525; material below 0.2 m, pressure falling with height
  const json& prof = out[4];
  ASSERT_EQ(prof["values"].size(), 25u);
  EXPECT_EQ(prof["field"], "pressure");
  int with_material = 0;
  for (size_t n = 0; n < 25; ++n) {
    const double y = prof["y_m"][n].get<double>();
    EXPECT_NEAR(y, 0.0025 + 0.01 * double(n), 1e-12);
    EXPECT_NEAR(prof["s_m"][n].get<double>(), 0.01 * double(n), 1e-12);
    const json& v = prof["values"][n];
    if (y < 0.2) {
      ASSERT_TRUE(v.is_number()) << "y = " << y;
      EXPECT_EQ(float(v.get<double>()), f.scalars.at("pressure")[f.index(10, int(y / 0.005))]);
      if (n > 0) {
        EXPECT_LT(v.get<double>(), prof["values"][n - 1].get<double>());
      }
      ++with_material;
    } else {
      EXPECT_TRUE(v.is_null()) << "y = " << y;
    }
  }
  EXPECT_EQ(with_material, 20);

  // the angle between the plate's bottom and its diagonal: atan(20 mm / 100 mm)
  EXPECT_NEAR(out[5]["deg"].get<double>(), std::atan(0.2) * 180 / M_PI, 0.5);
  EXPECT_NEAR(out[5]["deg"].get<double>(), 11.3099, 1e-3);
  EXPECT_NEAR(out[6]["m"].get<double>(), 0.1, 1e-12);
  EXPECT_EQ(out[7]["frame"], 3);  // 0.031 s is nearest to frame 3 at 0.03 s

  // screenshot: the frame with pressure colours on the left, the ImGui panel on the right
  const json& s = out[8];
  EXPECT_EQ(s["path"], shot);
  const auto img = furrow::render::read_png(shot);
  ASSERT_EQ(img.width, 1280);
  ASSERT_EQ(img.height, 720);
  const int x0 = s["panel_x0"].get<int>();
  EXPECT_EQ(x0, 860);
  expect_inspector_view(img, x0, "viridis");
  // the same screenshot again is refused: nothing is overwritten
  const auto again = run({"inspect", (dir_ / "run").string(), "--headless", "--script", script("screenshot " + shot + "\n")});
  EXPECT_EQ(again.status, 1);
  EXPECT_NE(again.err.find("script.txt:1:"), std::string::npos) << again.err;
}

// A small stored run of a plate descending into loose DPM material (paper case 4 at dx 4 mm, 10
// cells across the plate, 29 mm of travel: ~5 s of CPU): the frames where run.json's analysis
// found flank lines show them in the overlay colour exactly there, and `wedge` prints what run.json
// stored. The lines are checked against run.json's numbers, not against the overlay's own code.
TEST_F(InspectCli, WedgeOverlayDrawsTheFlankLinesRunJsonStored) {
  auto r = run({"new", "loose_intrusion", "-o", path("loose.json"), "--set", "domain.width_m=0.2", "--set",
                "domain.height_m=0.13", "--set", "domain.dx_m=0.004", "--set", "beds.0.max_m=[0.2,0.1]", "--set",
                "bodies.plate.start_m=[0.1,0.112]", "--set", "solver.end_displacement_m=0.029", "--set",
                "outputs.frame_interval_s=0.01", "--set", "outputs.fields=[\"velocity\",\"strain_rate\"]", "--set",
                "outputs.movies=[]"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = run({"run", path("loose.json"), "--out", path("run"), "--no-movies"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json frames = json::parse(furrow::cli_test::read_text(dir_ / "run" / "run.json"))["analysis"]["wedge"]["frames"];
  // the last frame with flank lines, and one without an angle
  int with = -1, without = -1;
  for (size_t k = 0; k < frames.size(); ++k) {
    if (frames[k]["left_flank_x_m"].is_number()) with = int(k);
    else if (without < 0) without = int(k);
  }
  ASSERT_GE(with, 0) << "no frame of the run has a wedge with flanks";
  ASSERT_GE(without, 0);
  const json& e = frames[size_t(with)];
  const std::string on = path("on.png"), off = path("off.png"), none = path("none.png");
  r = run({"inspect", path("run"), "--headless", "--script",
           script("frame " + std::to_string(with) + "\nwedge\nscreenshot " + on + "\nwedge off\nscreenshot " + off +
                  "\nwedge on\nframe " + std::to_string(without) + "\nwedge\nscreenshot " + none + "\n")});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<json> out = lines(r.out);
  ASSERT_EQ(out.size(), 9u) << r.out;
  // `wedge`: run.json's entry for that frame, to the bit
  const json& w = out[1];
  EXPECT_EQ(w["action"], "wedge");
  EXPECT_EQ(w["frame"], with);
  EXPECT_EQ(w["overlay"], true);
  EXPECT_EQ(w["lines"], true);
  for (const char* key : {"apex_angle_deg", "left_flank_deg", "right_flank_deg", "left_flank_x_m", "right_flank_x_m",
                          "face_y_m", "height_m"})
    EXPECT_EQ(w[key].get<double>(), e[key].get<double>()) << key;
  EXPECT_EQ(out[7]["apex_angle_deg"], nullptr);
  EXPECT_EQ(out[7]["lines"], false);

  // the stored lines in pixels: x = x_face +- tan(angle) (face_y - y), down to the region's depth
  // (or the apex, above it)
  const json& shot = out[2];
  const double ox = shot["bed_origin_px"][0], oy = shot["bed_origin_px"][1], ppm = shot["px_per_m"];
  const double y0 = e["face_y_m"], deg = M_PI / 180;
  const double depth = e["apex_depth_m"].is_number() ? std::min(e["height_m"].get<double>(), e["apex_depth_m"].get<double>())
                                                     : e["height_m"].get<double>();
  struct Line { double x0, slope; };  // x(z) = x0 + slope z, z = face_y - y
  const Line lines_m[2] = {{e["left_flank_x_m"], std::tan(e["left_flank_deg"].get<double>() * deg)},
                           {e["right_flank_x_m"], -std::tan(e["right_flank_deg"].get<double>() * deg)}};
  auto px = [&](double x, double y) { return std::pair<double, double>(ox + x * ppm, oy - y * ppm); };
  auto magenta = [](const uint8_t* p) { return p[0] > 220 && p[1] < 40 && p[2] > 220; };
  const auto img = furrow::render::read_png(on);
  // along each stored line, overlay pixels within 2 px
  for (const Line& l : lines_m)
    for (int n = 1; n < 10; ++n) {
      const double z = depth * n / 10.0;
      const auto [cx, cy] = px(l.x0 + l.slope * z, y0 - z);
      bool hit = false;
      for (int dy = -2; dy <= 2 && !hit; ++dy)
        for (int dx = -2; dx <= 2 && !hit; ++dx) hit = magenta(img.at(int(std::lround(cx)) + dx, int(std::lround(cy)) + dy));
      EXPECT_TRUE(hit) << "no overlay pixel near (" << cx << ", " << cy << ") on the line from x " << l.x0;
    }
  // and every overlay pixel lies on a stored line (within 2.5 px: the lines are ~3 px wide)
  int overlay_px = 0, off_line = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < shot["panel_x0"].get<int>(); ++x) {
      if (!magenta(img.at(x, y))) continue;
      ++overlay_px;
      // distance to the segment of each line from the face to 1.5 region depths below it (the
      // overlay stops at the region's depth or the apex: only where along the line is not checked)
      const Eigen::Vector2d q(x + 0.5, y + 0.5);
      double best = 1e9;
      for (const Line& l : lines_m) {
        const auto [ax, ay] = px(l.x0, y0);
        const auto [bx, by] = px(l.x0 + l.slope * 1.5 * e["height_m"].get<double>(), y0 - 1.5 * e["height_m"].get<double>());
        const Eigen::Vector2d a(ax, ay), b(bx, by);
        const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        best = std::min(best, (q - (a + t * (b - a))).norm());
      }
      off_line += best > 2.5;
    }
  EXPECT_GT(overlay_px, int(2 * depth * ppm)) << "two lines, each at least depth long and 2 px wide";
  EXPECT_EQ(off_line, 0) << "of " << overlay_px << " overlay pixels";
  // switched off, and on a frame without an angle: no overlay pixel at all
  for (const std::string& p : {off, none}) {
    const auto other = furrow::render::read_png(p);
    int n = 0;
    for (int y = 0; y < other.height; ++y)
      for (int x = 0; x < shot["panel_x0"].get<int>(); ++x) n += magenta(other.at(x, y));
    EXPECT_EQ(n, 0) << p;
  }
  // a run without a wedge analysis says so, naming its run.json
  const StoredRun stored(dir_ / "plain");
  r = run({"inspect", (dir_ / "plain").string(), "--headless", "--script", script("wedge\n")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("run.json holds no wedge analysis"), std::string::npos) << r.err;
}

TEST_F(InspectCli, BadScriptLinesNameFileLineAndWhatWasExpected) {
  const StoredRun stored(dir_ / "run");
  auto r = run({"inspect", (dir_ / "run").string(), "--headless", "--script",
                script("field pressure\n\nprobe 0.1\nlength 0 0 1 1\n")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("script.txt:3: expected 'probe X Y', got 'probe 0.1'"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");  // checked before anything runs
  r = run({"inspect", (dir_ / "run").string(), "--headless", "--script", script("zoom 2\n")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("script.txt:1: expected one of field, frame, time, probe"), std::string::npos) << r.err;
  r = run({"inspect", (dir_ / "run").string(), "--headless", "--script", script("field temperature\n")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("unknown field 'temperature'"), std::string::npos) << r.err;
  // what the run does not hold: the line, and what it has
  r = run({"inspect", (dir_ / "run").string(), "--headless", "--script", script("length 0 0 3 4\nframe 9\n")});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.out).size(), 1u);
  EXPECT_NE(r.err.find("script.txt:2: frame 9 is not stored"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames 0..3"), std::string::npos) << r.err;
  r = run({"inspect", (dir_ / "run").string(), "--headless", "--script", script("field phi_d\n")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("script.txt:1: field 'phi_d' is not stored"), std::string::npos) << r.err;
  // no --headless: a clear message, not a crash
  r = run({"inspect", (dir_ / "run").string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--headless --script FILE"), std::string::npos) << r.err;
}

TEST_F(InspectCli, WindowUnderXvfbReplaysAScriptAndScreenshotsTheWindow) {
  if (std::system("command -v Xvfb >/dev/null 2>&1") != 0)
    FURROW_SKIP_UNLESS_CI("Xvfb is not installed (apt-get install xvfb, as .ci/setup.sh does): no display to open the window on");
  furrow::cli_test::Xvfb x;
  if (!x.up) FURROW_SKIP_UNLESS_CI("Xvfb could not start");
  const StoredRun stored(dir_ / "run");
  const std::string shot = path("window.png");
  setenv("DISPLAY", (":" + std::to_string(x.number)).c_str(), 1);
  const auto r = run({"inspect", (dir_ / "run").string(), "--script",
                      script("frame 1\nfield strain_rate\nscreenshot " + shot + "\n"), "--exit-after-script"});
  unsetenv("DISPLAY");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<json> out = lines(r.out);
  ASSERT_EQ(out.size(), 3u) << r.out;
  EXPECT_EQ(out[2]["action"], "screenshot");
  EXPECT_EQ(out[2]["frame"], 1);
  // read back from the X server: the strain-rate field on the left, the panel on the right
  const auto img = furrow::render::read_png(shot);
  ASSERT_EQ(img.width, 1280);
  ASSERT_EQ(img.height, 720);
  const int x0 = out[2]["panel_x0"].get<int>();
  expect_inspector_view(img, x0, "magma");
}

}  // namespace

// A body that turns (forces.csv with torque and angle): `plot torque` and `plot angle` give each
// body's value at the frame's time; depth needs a free y, which only scene.json says, so without
// it the error names what there is; a forces.csv before those columns has none at all.
TEST_F(InspectCli, PlotTorqueAndAngleOfABodyThatTurns) {
  const StoredRun stored(dir_ / "run");
  {
    std::ofstream csv(dir_ / "run" / "forces.csv");
    csv << "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m,torque_N_m_per_m,angle_deg,vx_m_s,vy_m_s,omega_rad_s\n";
    for (int k = 0; k <= 30; ++k)
      csv << 0.001 * k << ",plate,0.2," << 0.2 - 0.0002 * k << ",0," << 40.0 * k << "," << -0.1 * k << "," << -2.0 * k
          << ",0,-0.2,-1\n";
  }
  auto r = run({"inspect", (dir_ / "run").string(), "--headless", "--script",
                script("time 0.01\nplot angle\nplot torque\nscreenshot " + path("shot.png") + "\nplot depth\n")});
  EXPECT_EQ(r.status, 1) << r.err;
  const auto out = lines(r.out);
  ASSERT_EQ(out.size(), 4u) << r.out;
  EXPECT_EQ(out[1].at("quantity"), "angle");
  EXPECT_NEAR(out[1].at("values").at("plate").get<double>(), -20.0, 1e-6);  // t = 0.01 s: sample 10
  EXPECT_EQ(out[2].at("label"), "torque (N m/m)");
  EXPECT_NEAR(out[2].at("values").at("plate").get<double>(), -1.0, 1e-6);
  EXPECT_TRUE(std::filesystem::exists(path("shot.png")));
  EXPECT_NE(r.err.find("script.txt:5: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("has no depth to plot (it has torque, angle)"), std::string::npos) << r.err;
  // the old columns: nothing to plot
  std::ofstream(dir_ / "run" / "forces.csv") << "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m\n0,plate,0.2,0.2,0,0\n0.01,plate,0.2,0.19,0,4\n";
  r = run({"inspect", (dir_ / "run").string(), "--headless", "--script", script("plot torque\n")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("no body turns or is free"), std::string::npos) << r.err;
}
