// `furrow sweep` run as a user would: the real binary on a tiny scene, its run directories,
// sweep.csv (columns, units, normalizations), sweep.json, sweep.png, and its errors.
#include <gtest/gtest.h>

#include "tests/app/sweep_fixture.hpp"
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

namespace fs = std::filesystem;

namespace {

using furrow::cli_test::Csv;
using furrow::cli_test::Result;
using furrow::cli_test::SweepCli;
using furrow::cli_test::read_csv;
using furrow::cli_test::read_text;
using furrow::cli_test::split;

constexpr double kPi = 3.14159265358979323846;

}  // namespace

TEST_F(SweepCli, TwoByTwoWritesFourRunsAndATableWithUnits) {
  const Result r = run({"sweep", path("tiny.json"), "--vary", "bodies.plate.shape.size_m.0=0.02:0.03:0.01", "--vary",
                        "bodies.rod.start_m.1=0.03,0.035", "--jobs", "2", "--out", path("sw")});
  ASSERT_EQ(r.status, 0) << r.err;

  // four run directories named by their values, each a complete run
  const std::vector<std::string> dirs = {
      "tiny_bodies.plate.shape.size_m.0=0.02_bodies.rod.start_m.1=0.03",
      "tiny_bodies.plate.shape.size_m.0=0.02_bodies.rod.start_m.1=0.035",
      "tiny_bodies.plate.shape.size_m.0=0.03_bodies.rod.start_m.1=0.03",
      "tiny_bodies.plate.shape.size_m.0=0.03_bodies.rod.start_m.1=0.035"};
  size_t entries = 0;
  for (const auto& e : fs::directory_iterator(path("sw"))) entries += e.is_directory();
  EXPECT_EQ(entries, 4u);
  for (const auto& d : dirs) {
    EXPECT_TRUE(fs::exists(path("sw/" + d + "/forces.csv"))) << d;
    EXPECT_TRUE(fs::exists(path("sw/" + d + "/run.json"))) << d;
    EXPECT_FALSE(fs::exists(path("sw/" + d + "/movies"))) << "movies are off by default in sweeps";
  }
  // each run was given the swept values
  const auto scene = nlohmann::json::parse(read_text(path("sw/" + dirs[3] + "/scene.json")));
  EXPECT_DOUBLE_EQ(scene["bodies"][0]["shape"]["size_m"][0].get<double>(), 0.03);
  EXPECT_DOUBLE_EQ(scene["bodies"][1]["start_m"][1].get<double>(), 0.035);

  // one progress line per finished run, with its wall time and the sweep's ETA
  size_t progress_lines = 0;
  for (const auto& line : split(r.err, '\n'))
    if (line.rfind("[", 0) == 0) {
      ++progress_lines;
      EXPECT_NE(line.find(" s wall"), std::string::npos) << line;
      EXPECT_NE(line.find("ETA"), std::string::npos) << line;
    }
  EXPECT_EQ(progress_lines, 4u) << r.err;

  const Csv csv = read_csv(path("sw/sweep.csv"));
  ASSERT_EQ(csv.rows.size(), 4u);
  // swept keys are columns named by their paths; every other column names its unit
  EXPECT_EQ(csv.header.at(0), "run");
  EXPECT_EQ(csv.header.at(1), "bodies.plate.shape.size_m.0");
  EXPECT_EQ(csv.header.at(2), "bodies.rod.start_m.1");
  for (size_t k = 3; k < csv.header.size(); ++k) {
    const std::string& h = csv.header[k];
    const bool unit = h == "status" || h == "error" || h.find("_m") != std::string::npos || h.find("_s") != std::string::npos ||
                      h.find("_N_per_m") != std::string::npos || h.find("_kg_m3") != std::string::npos ||
                      h.find("_nondim") != std::string::npos;
    EXPECT_TRUE(unit) << "column without a unit: " << h;
  }
  for (const char* col : {"plate.mean_drag_N_per_m", "plate.mean_lift_N_per_m", "plate.peak_drag_N_per_m",
                          "plate.mean_drag_nondim", "plate.peak_drag_nondim", "rod.mean_Fx_N_per_m",
                          "rod.mean_Fy_N_per_m", "rod.mean_drag_nondim", "rod.mean_lift_nondim", "wall_s",
                          "L_avg_m", "z_m"})
    EXPECT_NE(std::find(csv.header.begin(), csv.header.end(), col), csv.header.end()) << col;

  const double rho_d = 2500 * 0.58, g = 9.81;
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(csv.rows[i].at("run"), dirs[i]);
    EXPECT_EQ(csv.rows[i].at("status"), "ok");
    const double L = i < 2 ? 0.02 : 0.03, y_rod = i % 2 ? 0.035 : 0.03;
    EXPECT_DOUBLE_EQ(csv.num(i, "bodies.plate.shape.size_m.0"), L);
    EXPECT_NEAR(csv.num(i, "rho_d_kg_m3"), rho_d, 1e-9);
    // plate: z = plate-bottom depth at the window's middle = (8.5 + 15.5) / 2 mm travel - 0.5 mm gap
    EXPECT_NEAR(csv.num(i, "z_m"), 0.0115, 1e-9);
    EXPECT_NEAR(csv.num(i, "plate.F0_N_per_m"), rho_d * g * 0.0115 * L, 1e-6);
    EXPECT_NEAR(csv.num(i, "plate.mean_drag_nondim"),
                csv.num(i, "plate.mean_drag_N_per_m") / (rho_d * g * 0.0115 * L), 1e-6);
    // a plate pushed down: drag is the upward force and resists
    EXPECT_GT(csv.num(i, "plate.mean_drag_N_per_m"), 0.0);
    EXPECT_NEAR(csv.num(i, "plate.mean_drag_N_per_m"), csv.num(i, "plate.mean_Fy_N_per_m"), 1e-9);
    // rod: F0 = pi (D/2)^2 rho_d g w; depth of its centre below the bed top
    EXPECT_NEAR(csv.num(i, "rod.F0_N_per_m"), kPi * 0.005 * 0.005 * rho_d * g, 1e-8);
    EXPECT_NEAR(csv.num(i, "rod.depth_m"), 0.05 - y_rod, 1e-9);
    EXPECT_NEAR(csv.num(i, "rod.mean_drag_N_per_m"), -csv.num(i, "rod.mean_Fx_N_per_m"), 1e-9);
    EXPECT_NEAR(csv.num(i, "rod.mean_lift_N_per_m"), csv.num(i, "rod.mean_Fy_N_per_m"), 1e-9);
    EXPECT_GT(csv.num(i, "wall_s"), 0.0);
  }
  // the mean over the window matches what the run itself summarised (same window, same forces)
  const auto run_json = nlohmann::json::parse(read_text(path("sw/" + dirs[0] + "/run.json")));
  EXPECT_NEAR(csv.num(0, "plate.mean_Fy_N_per_m"), run_json["bodies"][0]["mean_force_N_per_m"][1].get<double>(),
              0.01 * std::abs(csv.num(0, "plate.mean_Fy_N_per_m")));

  const auto sj = nlohmann::json::parse(read_text(path("sw/sweep.json")));
  EXPECT_EQ(sj["runs"].size(), 4u);
  EXPECT_TRUE(sj["columns"].contains("plate.F0_N_per_m"));
  // the first moving body is the plate and its width was swept: the paper's width-scaling figure
  EXPECT_EQ(sj["figure"], "plate_width_scaling");
  const std::string png = read_text(path("sw/sweep.png"));
  ASSERT_GT(png.size(), 1000u);
  EXPECT_EQ(png.substr(1, 3), "PNG");

  // an existing sweep directory is never overwritten without --force
  const auto before = fs::last_write_time(path("sw/sweep.csv"));
  const Result again = run({"sweep", path("tiny.json"), "--vary", "bodies.plate.friction=0.3", "--out", path("sw")});
  EXPECT_EQ(again.status, 1);
  EXPECT_NE(again.err.find("already exists"), std::string::npos) << again.err;
  EXPECT_EQ(fs::last_write_time(path("sw/sweep.csv")), before);
  const Result forced =
      run({"sweep", path("tiny.json"), "--vary", "bodies.plate.friction=0.3", "--out", path("sw"), "--force"});
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_EQ(read_csv(path("sw/sweep.csv")).rows.size(), 1u);
  EXPECT_FALSE(fs::exists(path("sw/" + dirs[0])));
}

TEST_F(SweepCli, UnknownKeyNamesTheNearestKeysAndWritesNothing) {
  const Result r = run({"sweep", path("tiny.json"), "--vary", "bodies.plate.frictoin=0.2,0.3", "--out", path("sw")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("/bodies/0/frictoin"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("did you mean \"friction\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--vary bodies.plate.frictoin=0.2,0.3"), std::string::npos) << r.err;
  expect_nothing_written();
}

TEST_F(SweepCli, NoValidValueNamesTheVaryAndWritesNothing) {
  // every value is out of range: found before anything runs (one invalid value among valid ones
  // is a failed row instead: sweep_resume_test.cpp)
  const Result r = run({"sweep", path("tiny.json"), "--vary", "domain.dx_m=-0.005,0", "--out", path("sw")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("/domain/dx_m: got -0.005"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/domain/dx_m: got 0,"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("set by --vary domain.dx_m=-0.005,0"), std::string::npos) << r.err;
  expect_nothing_written();
}

TEST_F(SweepCli, MalformedVaryIsAUsageError) {
  struct Case {
    std::string vary, message;
  };
  const std::vector<Case> cases = {
      {"bodies.plate.friction=0.1:0.3:0", "step is 0"},
      {"bodies.plate.friction=0.1:0.3", "expected a:b:step"},
      {"bodies.plate.friction=0.1:x:0.1", "expected a:b:step"},
      {"bodies.plate.friction=0.3:0.1:0.1", "leads away"},
      {"bodies.plate.friction", "expected KEYS=VALUES"},
      {"=0.1,0.2", "expected KEYS=VALUES"},
      {"bodies.plate.friction=", "no values"},
      {"bodies.plate.friction=0.1,,0.2", "empty value"},
      {"bodies.plate.friction=0.1,0.1", "listed twice"},
      {"bodies.plate.friction+=0.1", "empty key path"},
      {"bodies.plate.friction+bodies.rod.friction=0.1;0.2;0.3", "3 values separated by ';' for 2 key(s)"},
      {"bodies.plate.friction+bodies.rod.friction=0.1;", "empty value in '0.1;'"},
  };
  for (const auto& c : cases) {
    const Result r = run({"sweep", path("tiny.json"), "--vary", c.vary, "--out", path("sw")});
    EXPECT_EQ(r.status, 2) << c.vary;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.vary << ": " << r.err;
    EXPECT_NE(r.err.find("--vary " + c.vary), std::string::npos) << r.err;
  }
  const Result none = run({"sweep", path("tiny.json"), "--out", path("sw")});
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.err.find("at least one --vary"), std::string::npos) << none.err;
  const Result twice = run({"sweep", path("tiny.json"), "--vary", "domain.dx_m=0.005", "--vary",
                            "domain.dx_m=0.01", "--out", path("sw")});
  EXPECT_EQ(twice.status, 2);
  EXPECT_NE(twice.err.find("varied twice"), std::string::npos) << twice.err;
  const Result jobs = run({"sweep", path("tiny.json"), "--vary", "domain.dx_m=0.005", "--jobs", "0", "--out", path("sw")});
  EXPECT_EQ(jobs.status, 2);
  EXPECT_NE(jobs.err.find("--jobs"), std::string::npos) << jobs.err;
  expect_nothing_written();
}

TEST_F(SweepCli, LinkedKeysTakeTheSameValueAndRangesIncludeTheirEnd) {
  // '+' joins keys that take one value; a:b:step includes b despite rounding (0.1 + 2 * 0.05)
  const Result r = run({"sweep", path("tiny.json"), "--vary", "bodies.plate.friction+bodies.rod.friction=0.1:0.2:0.05",
                        "--set", "solver.end_displacement_m=0.01", "--set", "outputs.average_window.to_m=0.01",
                        "--out", path("sw")});
  ASSERT_EQ(r.status, 0) << r.err;
  const Csv csv = read_csv(path("sw/sweep.csv"));
  ASSERT_EQ(csv.rows.size(), 3u);
  EXPECT_EQ(csv.header.at(1), "bodies.plate.friction+bodies.rod.friction");
  const std::vector<std::string> values = {"0.1", "0.15", "0.2"};
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(csv.rows[i].at("bodies.plate.friction+bodies.rod.friction"), values[i]);
    const auto scene = nlohmann::json::parse(read_text(path("sw/" + csv.rows[i].at("run") + "/scene.json")));
    EXPECT_DOUBLE_EQ(scene["bodies"][0]["friction"].get<double>(), std::stod(values[i]));
    EXPECT_DOUBLE_EQ(scene["bodies"][1]["friction"].get<double>(), std::stod(values[i]));
  }
}

// A pair's separation moves both plates, each its own way: one value per key, separated by ';',
// in step (not a cartesian product); the table's column keeps the value as given.
TEST_F(SweepCli, LinkedKeysTakeOneValueEachWhenSeparatedBySemicolons) {
  const Result r = run({"sweep", path("tiny.json"), "--vary",
                        "bodies.plate.friction+bodies.rod.friction=0.1;0.3,0.2;0.4,0.5",
                        "--set", "solver.end_displacement_m=0.01", "--set", "outputs.average_window.to_m=0.01",
                        "--out", path("sw")});
  ASSERT_EQ(r.status, 0) << r.err;
  const Csv csv = read_csv(path("sw/sweep.csv"));
  ASSERT_EQ(csv.rows.size(), 3u);
  const std::vector<std::string> given = {"0.1;0.3", "0.2;0.4", "0.5"};
  const std::vector<double> plate = {0.1, 0.2, 0.5}, rod = {0.3, 0.4, 0.5};
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(csv.rows[i].at("bodies.plate.friction+bodies.rod.friction"), given[i]);
    const auto scene = nlohmann::json::parse(read_text(path("sw/" + csv.rows[i].at("run") + "/scene.json")));
    EXPECT_DOUBLE_EQ(scene["bodies"][0]["friction"].get<double>(), plate[i]);
    EXPECT_DOUBLE_EQ(scene["bodies"][1]["friction"].get<double>(), rod[i]);
  }
}

TEST_F(SweepCli, FigureFollowsWhatWasSwept) {
  struct Case {
    std::vector<std::string> args;
    std::string figure;
  };
  const std::string plate2 =
      R"(bodies.2={"name":"plate2","shape":{"type":"box","size_m":[0.02,0.01]},"start_m":[0.078,0.0555],)"
      R"("motion":{"type":"constant_velocity","velocity_m_s":[0,-0.1]}})";
  const std::vector<Case> cases = {
      // the rod leads once the plate stands still: its depth was swept
      {{"--vary", "bodies.rod.start_m.1=0.03,0.035", "--set", "bodies.plate.motion.velocity_m_s=[0,0]"},
       "drag_lift_vs_depth"},
      // two moving plates whose gap changes
      {{"--vary", "bodies.plate2.start_m.0=0.078,0.083", "--set", plate2}, "pair_separation"},
      // anything else
      {{"--vary", "bodies.plate.friction=0.2,0.4"}, "generic"},
  };
  int n = 0;
  for (const auto& c : cases) {
    const std::string out = path("fig" + std::to_string(n++));
    std::vector<std::string> args = {"sweep", path("tiny.json"), "--out", out, "--set", "solver.end_displacement_m=0.01",
                                     "--set", "outputs.average_window.to_m=0.01"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const Result r = run(args);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto sj = nlohmann::json::parse(read_text(out + "/sweep.json"));
    EXPECT_EQ(sj["figure"], c.figure) << c.args[1];
    EXPECT_TRUE(fs::exists(out + "/sweep.png")) << c.args[1];
  }
}

// Released columns of two aspect ratios (the collapse template, coarse): sweep.csv carries a, the
// runout and Hf/H0 of each, a taller column runs further and ends lower relative to its height,
// and the figure is runout against a.
TEST_F(SweepCli, CollapseSweepTabulatesRunoutAgainstAspectRatio) {
  const std::string out = path("collapse");
  const Result r = run({"sweep", std::string(FURROW_SOURCE_DIR) + "/scenes/column_collapse.json", "--out", out,
                        "--vary", "beds.0.max_m=[0.1,0.05],[0.1,0.1]", "--set", "domain.dx_m=0.01", "--set",
                        "domain.width_m=0.4", "--set", "solver.end_time_s=0.4", "--set", "outputs.fields=[]", "--set",
                        "outputs.movies=[]", "--no-paraview", "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Csv csv = read_csv(out + "/sweep.csv");
  ASSERT_EQ(csv.rows.size(), 2u);
  std::map<double, std::pair<double, double>> by_a;  // a -> runout, Hf/H0
  for (const auto& row : csv.rows)
    by_a[std::stod(row.at("aspect_ratio_nondim"))] = {std::stod(row.at("runout_nondim")),
                                                       std::stod(row.at("final_height_nondim"))};
  ASSERT_EQ(by_a.size(), 2u);
  EXPECT_DOUBLE_EQ(by_a.begin()->first, 0.5);
  EXPECT_DOUBLE_EQ(by_a.rbegin()->first, 1.0);
  const auto [low_runout, low_height] = by_a.begin()->second;
  const auto [tall_runout, tall_height] = by_a.rbegin()->second;
  EXPECT_GT(low_runout, 0.2);
  EXPECT_GT(tall_runout, 1.3 * low_runout);
  EXPECT_LT(tall_height, low_height);
  EXPECT_LE(low_height, 1.0 + 1e-3);
  const auto sj = nlohmann::json::parse(read_text(out + "/sweep.json"));
  EXPECT_EQ(sj["figure"], "collapse_runout");
  EXPECT_TRUE(fs::exists(out + "/sweep.png"));
}
