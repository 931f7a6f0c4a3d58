// `furrow bench` and the wall-time prediction it feeds: the stored calibration, and what
// `furrow validate` says with and without one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <thread>

#include "tests/app/cli_fixture.hpp"

namespace {

using furrow::cli_test::read_text;

const char* kScene = R"({
  "schema_version": 1,
  "name": "tiny",
  "domain": {"width_m": 0.1, "height_m": 0.07, "dx_m": 0.005},
  "solver": {"end_time_s": 0.2, "threads": 1},
  "materials": [{"name": "sand", "model": "ndpm", "grain_density_kg_m3": 2500, "phi_c": 0.6, "mu_s": 0.4}],
  "beds": [{"material": "sand", "min_m": [0, 0], "max_m": [0.1, 0.05], "packing_fraction": 0.6}]
})";

class BenchCli : public furrow::cli_test::CliFixture {
 protected:
  BenchCli() : CliFixture("furrow_bench_") {}
  void SetUp() override {
    CliFixture::SetUp();
    std::ofstream(path("tiny.json")) << kScene;
  }
  // validate's particle-step estimate and its "wall time" line
  std::pair<double, std::string> validate() {
    const auto r = run({"validate", path("tiny.json"), "--brief"});
    EXPECT_EQ(r.status, 0) << r.err;
    std::smatch m;
    double psteps = NAN;
    if (std::regex_search(r.err, m, std::regex(R"(, ([0-9.e+]+) particle-steps)"))) psteps = std::stod(m[1]);
    std::string wall;
    if (std::regex_search(r.err, m, std::regex(R"(wall time  ([^\n]*))"))) wall = m[1];
    return {psteps, wall};
  }
};

TEST_F(BenchCli, ValidateSaysHowToCalibrateWithoutACalibration) {
  const auto [psteps, wall] = validate();
  EXPECT_GT(psteps, 0.0);
  EXPECT_NE(wall.find("unknown"), std::string::npos) << wall;
  EXPECT_NE(wall.find("furrow bench"), std::string::npos) << wall;
}

TEST_F(BenchCli, PredictionIsParticleStepsOverTheCalibratedRate) {
  // 1 thread: 1e5 particle-steps/s for quadratic NDPM (the scene's settings); other entries differ so
  // a wrong pick shows
  nlohmann::json c = {{"host", "test"}, {"cpu", "test"}, {"date", "today"}, {"particles", 1000},
                      {"entries",
                       {{{"shape_function", "quadratic"}, {"model", "ndpm"}, {"threads", 1}, {"particle_steps_per_s", 1e5}},
                        {{"shape_function", "quadratic"}, {"model", "ndpm"}, {"threads", 4}, {"particle_steps_per_s", 4e5}},
                        {{"shape_function", "linear"}, {"model", "ndpm"}, {"threads", 1}, {"particle_steps_per_s", 1e7}}}}};
  std::ofstream(path("calibration.json")) << c.dump();
  const auto [psteps, wall] = validate();
  ASSERT_GT(psteps, 0.0);
  std::smatch m;
  const std::string w = wall;
  ASSERT_TRUE(std::regex_search(w, m, std::regex(R"(~([0-9]+) s)"))) << wall;
  EXPECT_EQ(std::stod(m[1]), std::ceil(psteps / 1e5)) << wall;
  EXPECT_NE(wall.find("1 thread"), std::string::npos) << wall;
}

// A bed larger than the bench's runs at the calibrated rate times (N / bench particles)^size_exponent.
TEST_F(BenchCli, LargerBedsArePredictedAtTheSizeScaledRate) {
  nlohmann::json c = {{"host", "test"}, {"cpu", "test"}, {"date", "today"}, {"particles", 100}, {"size_exponent", 0.0},
                      {"entries",
                       {{{"shape_function", "quadratic"}, {"model", "ndpm"}, {"threads", 1}, {"particle_steps_per_s", 1e6}}}}};
  std::ofstream(path("calibration.json")) << c.dump();
  const auto [psteps, flat] = validate();
  c["size_exponent"] = -0.2;
  std::ofstream(path("calibration.json")) << c.dump();
  const auto [psteps2, scaled] = validate();
  const auto r = run({"validate", path("tiny.json")});
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex(R"(particles  ~([0-9]+))"))) << r.err;
  const double n = std::stod(m[1]);
  ASSERT_GT(n, 400.0);  // well above the calibration's 100
  auto seconds = [](const std::string& wall) {
    std::smatch s;
    EXPECT_TRUE(std::regex_search(wall, s, std::regex(R"(~([0-9]+) s)"))) << wall;
    return std::stod(s[1]);
  };
  // validate prints particle-steps to 3 digits and whole seconds rounded up
  EXPECT_NEAR(seconds(flat), psteps / 1e6, 1.0) << flat;
  EXPECT_NEAR(seconds(scaled), psteps / (1e6 * std::pow(n / 100.0, -0.2)), 1.0) << scaled;
  EXPECT_GT(seconds(scaled), seconds(flat) + 1.0) << flat << " / " << scaled;
  EXPECT_NE(scaled.find("for this bed's size"), std::string::npos) << scaled;
}

TEST_F(BenchCli, BenchStoresAFigureForEveryShapeFunctionModelAndThreadCount) {
  const auto r = run({"bench", "--seconds", "0.05", "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto c = nlohmann::json::parse(read_text(path("calibration.json")));
  std::set<std::string> seen;
  for (const auto& e : c.at("entries")) {
    EXPECT_GT(e.at("particle_steps_per_s").get<double>(), 0.0);
    seen.insert(e.at("shape_function").get<std::string>() + "/" + e.at("model").get<std::string>() + "/" +
                std::to_string(e.at("threads").get<int>()));
  }
  const size_t thread_counts = std::thread::hardware_concurrency() > 1 ? 2 : 1;
  EXPECT_EQ(seen.size(), 3 * 2 * thread_counts);
  // the size exponent is what was measured on a bed 16 times larger, not a clamped figure: the
  // log of the two rates over the log of the two sizes (a NaN or a stored 0 fails here)
  double reference_rate = std::nan("");
  int most_threads = 0;  // the reference: quadratic NDPM on the most threads measured
  for (const auto& e : c.at("entries"))
    if (e.at("shape_function") == "quadratic" && e.at("model") == "ndpm" && e.at("threads").get<int>() > most_threads)
      most_threads = e.at("threads").get<int>(), reference_rate = e.at("particle_steps_per_s").get<double>();
  const double large = c.at("large_particles").get<double>(), small = c.at("particles").get<double>();
  EXPECT_NEAR(large / small, 16.0, 1.0);
  const double measured = std::log(c.at("large_particle_steps_per_s").get<double>() / reference_rate) / std::log(large / small);
  ASSERT_TRUE(std::isfinite(measured));
  EXPECT_NEAR(c.at("size_exponent").get<double>(), measured, 1e-9);
  const auto [psteps, wall] = validate();
  EXPECT_EQ(wall.find("unknown"), std::string::npos) << wall;
  EXPECT_NE(wall.find("on this machine"), std::string::npos) << wall;
  // a negative or absurd duration is refused before anything is measured
  const auto bad = run({"bench", "--seconds", "-1"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--seconds"), std::string::npos) << bad.err;
}

}  // namespace

namespace {

// `furrow bench --threads`: a row per thread count, each phase's seconds adding up to the step's,
// each bracketed speedup the first row's seconds over the row's, and no calibration written.
TEST_F(BenchCli, ScalingTableHasARowPerThreadCountWhosePhasesAddUpToTheStep) {
  const auto r = run({"bench", "--threads", "1,3", "--dx", "0.01", "--steps", "5"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::regex row(R"(^ *([0-9]+) +([0-9.]+)((?: +[0-9.]+ \((?:[0-9.]+x|-)\)){6}) *$)");
  const std::regex cell(R"(([0-9.]+) \(([0-9.]+x|-)\))");  // "-": the phase did not run
  std::vector<int> threads;
  std::vector<std::vector<std::pair<double, double>>> cells;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, row)) continue;
    threads.push_back(std::stoi(m[1]));
    EXPECT_GT(std::stod(m[2]), 0.0) << line;
    const std::string rest = m[3];
    cells.emplace_back();
    for (std::sregex_iterator it(rest.begin(), rest.end(), cell), end; it != end; ++it)
      cells.back().emplace_back(std::stod((*it)[1]), (*it)[2] == "-" ? NAN : std::stod((*it)[2]));
  }
  ASSERT_EQ(threads, (std::vector<int>{1, 3})) << r.out;
  for (const auto& c : cells) {
    double phases = 0.0;
    for (size_t k = 0; k + 1 < c.size(); ++k) phases += c[k].first;
    EXPECT_NEAR(phases, c.back().first, 5 * 0.00005 + 1e-9) << r.out;  // five phases printed to 4 decimals
    EXPECT_GT(c.back().first, 0.0);
  }
  for (size_t k = 0; k < cells[0].size(); ++k) {
    if (std::isnan(cells[0][k].second) || std::isnan(cells[1][k].second)) {  // only a phase with no time
      EXPECT_TRUE(cells[0][k].first == 0.0 || cells[1][k].first == 0.0) << r.out;
      continue;
    }
    EXPECT_DOUBLE_EQ(cells[0][k].second, 1.0);
    if (cells[1][k].first >= 0.001) {  // large enough for the printed digits to give the ratio to ~10%
      EXPECT_NEAR(cells[1][k].second, cells[0][k].first / cells[1][k].first,
                  0.1 * cells[0][k].first / cells[1][k].first + 0.01)
          << r.out;
    }
  }
  EXPECT_FALSE(std::filesystem::exists(path("calibration.json")));
  // a list that is not one, and the scaling options without --threads, are refused by name
  for (const std::vector<std::string>& bad : {std::vector<std::string>{"bench", "--threads", "1,,2"},
                                              std::vector<std::string>{"bench", "--threads", "0"},
                                              std::vector<std::string>{"bench", "--threads", "2", "--dx", "-1"},
                                              std::vector<std::string>{"bench", "--steps", "10"}}) {
    const auto b = run(bad);
    EXPECT_EQ(b.status, 2) << bad[2];
    EXPECT_NE(b.err.find(bad[bad.size() - 2]), std::string::npos) << b.err;
  }
}

// `--ceiling`: a row per phase and one for the step. The step's speedup on T threads lies between
// 1 and T: its tasks shared out can neither take longer than on one thread nor gain more than T
// (the runs' pace is matched by P2G and G2P, nearly all of a step, so little noise is left; 10%
// allowed). P2G is split into more than one task a region; "-" only for the reorder, which five
// steps do not reach.
TEST_F(BenchCli, CeilingGivesTheStepASpeedupBetweenOneAndTheThreads) {
  const auto r = run({"bench", "--threads", "1", "--dx", "0.01", "--steps", "5", "--ceiling"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::regex row(R"(^(p2g|grid|contact|g2p\+const|reorder|step) +([0-9.]+) +([0-9.]+)% +([0-9.]*)((?: +(?:[0-9.]+x|-)){6}) *$)");
  const std::regex cell(R"(([0-9.]+)x|-)");  // "-": the phase did not run (no reorder in 5 steps)
  const int T[] = {2, 4, 8, 16, 32, 64};
  std::vector<std::string> names;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, row)) continue;
    names.push_back(m[1]);
    if (m[1] == "p2g") {
      EXPECT_GT(std::stod(m[4]), 1.0) << line;
    }
    const std::string rest = m[5];
    int k = 0;
    for (std::sregex_iterator it(rest.begin(), rest.end(), cell), end; it != end; ++it, ++k) {
      if ((*it)[0] == "-") {
        EXPECT_EQ(m[1], "reorder") << line;
        continue;
      }
      const double speedup = std::stod((*it)[1]);
      EXPECT_GT(speedup, 0.0) << line;
      if (m[1] == "step") {
        EXPECT_GE(speedup, 0.9) << line;
        EXPECT_LE(speedup, 1.1 * T[k]) << line;
      }
    }
  }
  EXPECT_EQ(names, (std::vector<std::string>{"p2g", "grid", "contact", "g2p+const", "reorder", "step"})) << r.out;
  const auto b = run({"bench", "--ceiling"});
  EXPECT_EQ(b.status, 2);
  EXPECT_NE(b.err.find("--ceiling"), std::string::npos) << b.err;
}

}  // namespace
