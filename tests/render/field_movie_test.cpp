// Re-rendering stored frames (written by the field store) to movies, PNGs and contact sheets, and
// reading forces.csv for the force panel.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "engine/io/field_store.hpp"
#include "render/colormap.hpp"
#include "render/field_movie.hpp"
#include "render/force_series.hpp"
#include "tests/render/capture_output.hpp"
#include "tests/render/synthetic_frames.hpp"

namespace fs = std::filesystem;
using namespace furrow;
using namespace furrow::render;

namespace {
std::string shell(const std::string& cmd) {
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> p(popen(cmd.c_str(), "r"), pclose);
  char buf[256];
  while (p && fgets(buf, sizeof buf, p.get())) out += buf;
  return out;
}

// A run directory with 6 frames 0.01 s apart: a plate sinking 2 mm per frame into a hydrostatic bed
// whose pressure scales by (1 + k/10) in frame k.
struct RunDir {
  fs::path dir;
  std::vector<std::string> frames;
  RunDir() {
    dir = fs::temp_directory_path() / ("furrow_field_movie_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    for (int k = 0; k < 6; ++k) {
      FieldFrame f = test::hydrostatic_frame(80, 50, 0.005, 0.2, 0.01 * k);
      f.step = 100 * k;
      for (float& p : f.scalars["pressure"]) p *= float(1.0 + 0.1 * k);
      const double y0 = 0.19 - 0.002 * k;
      f.bodies.push_back(test::box_body("plate", 0.15, y0, 0.25, y0 + 0.02));
      const std::string path = frame_path(dir.string(), k);
      write_frame_vdb(path, f);
      frames.push_back(path);
    }
  }
  ~RunDir() { fs::remove_all(dir); }
};

std::string write_csv(const fs::path& dir, const std::string& name, const std::string& text) {
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}
}  // namespace

TEST(FieldMovie, ScanFindsRangeAndTimesOverStoredFrames) {
  RunDir run;
  ASSERT_EQ(list_frames(run.dir.string()).size(), 6u);
  const FrameScan scan = scan_frames(run.frames, "pressure");
  ASSERT_EQ(scan.times_s.size(), 6u);
  EXPECT_NEAR(scan.times_s[5], 0.05, 1e-12);
  EXPECT_EQ(scan.time_decimals, 3);
  // deepest cell centre 0.1975 m below the surface, in the last frame (x1.5)
  EXPECT_NEAR(scan.range.hi, 1.5 * test::kRhoBulk_kg_m3 * test::kG_m_s2 * 0.1975, 0.5);
  EXPECT_NEAR(scan.range.lo, test::kRhoBulk_kg_m3 * test::kG_m_s2 * 0.0025, 0.5);
  EXPECT_EQ(time_decimals_for({0.0, 0.0005, 0.001}), 4);
  EXPECT_EQ(time_decimals_for({0.0, 0.1, 0.2}), 3);
  try {
    scan_frames(run.frames, "phi_d");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("frame_00000.vdb"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("phi_d"), std::string::npos) << e.what();
  }
}

TEST(FieldMovie, MovieHasOneVideoFramePerStoredFrame) {
  RunDir run;
  FrameStyle style;
  style.field = "pressure";
  style.width = 640, style.height = 360;
  style.range = scan_frames(run.frames, "pressure").range;
  const std::string out = (run.dir / "movies" / "pressure.mp4").string();
  fs::create_directories(run.dir / "movies");
  size_t calls = 0;
  const std::string noise = test::capture_output(
      [&] { render_movie(run.frames, style, out, 10.0, false, [&](size_t done, size_t total) { calls += done <= total; }); });
  EXPECT_FALSE(test::mentions_gl_trouble(noise)) << noise;
  EXPECT_EQ(calls, 6u);
  const std::string info = shell("ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                                 "stream=codec_name,width,height,pix_fmt,nb_read_frames -of default=nw=1 '" + out + "'");
  EXPECT_NE(info.find("nb_read_frames=6"), std::string::npos) << info;
  EXPECT_NE(info.find("width=640"), std::string::npos) << info;
  EXPECT_NE(info.find("pix_fmt=yuv420p"), std::string::npos) << info;
  EXPECT_THROW(render_movie(run.frames, style, out, 10.0, false), std::runtime_error);  // never overwrites
}

TEST(FieldMovie, PngsAreNamedLikeTheirFrames) {
  RunDir run;
  FrameStyle style;
  style.field = "strain_rate";
  style.width = 320, style.height = 180;
  style.range = scan_frames(run.frames, "strain_rate").range;
  const auto written = render_pngs({run.frames[1], run.frames[4]}, style, (run.dir / "renders").string(), false);
  ASSERT_EQ(written.size(), 2u);
  EXPECT_EQ(fs::path(written[1]).filename(), "frame_00004.png");
  const RgbImage img = read_png(written[1]);
  EXPECT_EQ(img.width, 320);
  EXPECT_EQ(img.height, 180);
}

TEST(FieldMovie, ContactSheetTilesFramesWithTimesAndOneColorbar) {
  RunDir run;
  FrameStyle style;
  style.field = "pressure";
  style.width = 960, style.height = 540;
  style.range = scan_frames(run.frames, "pressure").range;
  const RgbImage sheet = render_contact_sheet(run.frames, style, 3);
  const int tile_w = 320, tile_h = 180;
  EXPECT_EQ(sheet.width, 3 * tile_w);
  ASSERT_GT(sheet.height, 2 * tile_h);
  // every tile has dark time-stamp text in its top band, right half
  for (int k = 0; k < 6; ++k) {
    const int x0 = (k % 3) * tile_w + tile_w / 2, y0 = (k / 3) * tile_h;
    int dark = 0;
    for (int y = y0; y < y0 + int(0.09 * tile_h); ++y)
      for (int x = x0; x < x0 + tile_w / 2 - 4; ++x) dark += sheet.at(x, y)[0] < 90 && sheet.at(x, y)[2] < 90;
    EXPECT_GT(dark, 20) << "tile " << k;
  }
  // the shared colorbar below the tiles shows the colormap
  const Colormap& cmap = load_colormap("viridis");
  std::vector<bool> seen(256, false);
  for (int y = 2 * tile_h; y < sheet.height; ++y)
    for (int x = 0; x < sheet.width; ++x) {
      double d = 0;
      const int i = cmap.nearest_index(sheet.at(x, y), &d);
      if (d < 1.5) seen[size_t(i)] = true;
    }
  EXPECT_GT(std::count(seen.begin(), seen.end(), true), 200);
  // deeper pressure grows frame to frame: the same bed pixel gets a higher colour index
  const int probe_x = tile_w / 6, probe_y = int(tile_h * 0.8);
  int previous = -1;
  for (int k = 0; k < 3; ++k) {
    const int idx = cmap.nearest_index(sheet.at(k * tile_w + probe_x, probe_y));
    EXPECT_GT(idx, previous) << "tile " << k;
    previous = idx;
  }
}

TEST(ForceSeries, ResistingForceAlongTravelAgainstDisplacement) {
  const fs::path dir = fs::temp_directory_path() / ("furrow_forces_" + std::to_string(::getpid()));
  // plate pushed down 1 mm per sample feeling Fy = 100 k; sled dragged along +x feeling Fx = -7
  std::string csv = "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m\n";
  for (int k = 0; k < 5; ++k) {
    csv += std::to_string(0.01 * k) + ",plate,0.5," + std::to_string(0.3 - 0.001 * k) + ",0.5," + std::to_string(100.0 * k) + "\n";
    csv += std::to_string(0.01 * k) + ",sled," + std::to_string(0.1 + 0.002 * k) + ",0.2,-7,3\n";
  }
  const ForcePanel panel = read_force_panel(write_csv(dir, "forces.csv", csv));
  ASSERT_EQ(panel.series.size(), 2u);
  EXPECT_EQ(panel.series[0].label, "plate");
  EXPECT_EQ(panel.x_label, "displacement (mm)");
  EXPECT_NEAR(panel.series[0].x[4], 4.0, 1e-9);    // mm
  EXPECT_NEAR(panel.series[0].y[4], 400.0, 1e-9);  // Fy for downward travel
  EXPECT_NEAR(panel.series[1].x[4], 8.0, 1e-9);
  EXPECT_NEAR(panel.series[1].y[2], 7.0, 1e-9);  // -Fx for +x travel (drag is positive)
  // nothing moves: |F| against time
  const ForcePanel still = read_force_panel(write_csv(dir, "still.csv",
      "t_s, body, x_m, y_m, Fx_N_per_m, Fy_N_per_m\n0,a,0,0,3,4\n0.5,a,0,0,6,8\n"));
  EXPECT_EQ(still.x_label, "time (s)");
  EXPECT_NEAR(still.series[0].y[1], 10.0, 1e-12);
  EXPECT_NEAR(still.series[0].x[1], 0.5, 1e-12);
  // bad input names file, line and column
  try {
    read_force_panel(write_csv(dir, "bad.csv", "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m\n0,a,0,0,1,1\n0.1,a,0,zero,1,1\n"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("y_m"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_force_panel(write_csv(dir, "nohdr.csv", "t,body,x,y\n")), std::runtime_error);
  fs::remove_all(dir);
}

// forces.csv with the motion columns: a body that turns gets torque and angle rows; which DOFs are
// free only scene.json says (depth for a free y, speed for a free x or y); a plate that only
// translates gets none, so its panel stays the force chart alone.
TEST(ForceSeries, TorqueAndDepthRowsForBodiesThatTurnOrAreFree) {
  const fs::path dir = fs::temp_directory_path() / ("furrow_motion_" + std::to_string(::getpid()));
  std::string csv = "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m,torque_N_m_per_m,angle_deg,vx_m_s,vy_m_s,omega_rad_s\n";
  for (int k = 0; k < 5; ++k) {
    const std::string t = std::to_string(0.01 * k);
    csv += t + ",impactor,0.12," + std::to_string(0.132 - 0.002 * k) + ",0,5," + std::to_string(-0.1 * k) + "," +
           std::to_string(-3.0 * k) + ",0,-0.2,-1\n";
    csv += t + ",plate,0.5," + std::to_string(0.3 - 0.001 * k) + ",0,9,0.01,0,0,-0.1,0\n";
  }
  const ForcePanel data_only = read_force_panel(write_csv(dir / "a", "forces.csv", csv));
  ASSERT_EQ(data_only.series.size(), 2u);
  ASSERT_EQ(data_only.rows.size(), 2u);  // no scene.json: the impactor turns, free DOFs unknown
  EXPECT_EQ(data_only.rows[0].key, "torque");
  EXPECT_EQ(data_only.rows[0].y_label, "torque (N m/m)");
  EXPECT_TRUE(data_only.rows[0].movie);
  ASSERT_EQ(data_only.rows[0].series.size(), 1u);
  EXPECT_EQ(data_only.rows[0].series[0].label, "impactor");
  EXPECT_NEAR(data_only.rows[0].series[0].x[3], 0.03, 1e-12);  // against time (s)
  EXPECT_NEAR(data_only.rows[0].series[0].y[3], -0.3, 1e-12);
  EXPECT_EQ(data_only.rows[1].key, "angle");
  EXPECT_FALSE(data_only.rows[1].movie);

  // scene.json beside it: the impactor template (x, y and angle free)
  std::ifstream in(std::string(FURROW_SOURCE_DIR) + "/scenes/impactor.json");
  std::stringstream scene;
  scene << in.rdbuf();
  write_csv(dir / "b", "scene.json", scene.str());
  const ForcePanel with_scene = read_force_panel(write_csv(dir / "b", "forces.csv", csv));
  ASSERT_EQ(with_scene.rows.size(), 4u);
  EXPECT_EQ(with_scene.rows[1].key, "depth");
  EXPECT_EQ(with_scene.rows[1].y_label, "depth below start (mm)");
  EXPECT_TRUE(with_scene.rows[1].movie);
  ASSERT_EQ(with_scene.rows[1].series.size(), 1u);
  EXPECT_NEAR(with_scene.rows[1].series[0].y[4], 8.0, 1e-9);  // 2 mm a sample, positive down
  EXPECT_EQ(with_scene.rows[2].key, "speed");
  EXPECT_NEAR(with_scene.rows[2].series[0].y[0], 0.2, 1e-12);

  // the impactor's torque against its 1% floor (largest |F| 5 N/m x reach 0.01 m x 0.01 = 5e-4 N m/m):
  // a torque that reaches 0.4 N m/m sets its own axes
  EXPECT_NEAR(with_scene.rows[0].y_floor, 5e-4, 1e-12);
  const ForceAxes real = motion_row_axes(with_scene.rows[0], with_scene.rows[0].series.data(), 1);
  EXPECT_LT(real.y_lo, -0.4);
  // a symmetric body's round-off torque (+-2e-8 N m/m) is drawn over the floor, so it reads as zero
  std::string sym = "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m,torque_N_m_per_m,angle_deg,vx_m_s,vy_m_s,omega_rad_s\n";
  for (int k = 0; k < 5; ++k)
    sym += std::to_string(0.01 * k) + ",impactor,0.12,0.13,0,5," + (k % 2 ? "2e-8" : "-2e-8") + ",0,0,-0.2,0\n";
  const ForcePanel round_off = read_force_panel(write_csv(dir / "b", "forces.csv", sym));
  const ForceAxes flat = motion_row_axes(round_off.rows[0], round_off.rows[0].series.data(), 1);
  EXPECT_DOUBLE_EQ(flat.y_lo, -5e-4);
  EXPECT_DOUBLE_EQ(flat.y_hi, 5e-4);

  // the same forces.csv before the motion columns: no rows
  std::string old = "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m\n0,impactor,0.12,0.132,0,5\n0.01,impactor,0.12,0.13,0,5\n";
  EXPECT_TRUE(read_force_panel(write_csv(dir / "b", "old.csv", old)).rows.empty());
  // a bad value in a motion column names it
  try {
    read_force_panel(write_csv(dir / "a", "bad.csv",
                               "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m,torque_N_m_per_m,angle_deg,vx_m_s,vy_m_s,omega_rad_s\n"
                               "0,a,0,0,1,1,nan,0,0,0,0\n"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("torque_N_m_per_m"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}
