// `furrow study`: the convergence arithmetic on made-up ladders with known answers, and the real
// binary on a tiny scene: its table agrees with the runs it made, it resumes, it keeps finished
// rungs when stopped, and bad options stop it before anything runs.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/study.hpp"
#include "tests/app/sweep_fixture.hpp"

namespace fs = std::filesystem;

namespace {

using furrow::cli_test::read_text;
using furrow::study::Rung;

TEST(StudyRichardson, RecoversOrderAndLimitOfAPowerLaw) {
  // q = 3 + 0.5 h^2 on a halving ladder
  auto q2 = [](double h) { return 3.0 + 0.5 * h * h; };
  auto r = furrow::study::richardson(0.04, q2(0.04), 0.02, q2(0.02), 0.01, q2(0.01));
  ASSERT_TRUE(r.ok) << r.note;
  EXPECT_NEAR(r.order, 2.0, 1e-9);
  EXPECT_NEAR(r.extrapolated, 3.0, 1e-12);
  // q = 1 - 2 h^1.5 on a ladder without a constant ratio
  auto q15 = [](double h) { return 1.0 - 2.0 * std::pow(h, 1.5); };
  r = furrow::study::richardson(0.03, q15(0.03), 0.02, q15(0.02), 0.0125, q15(0.0125));
  ASSERT_TRUE(r.ok) << r.note;
  EXPECT_NEAR(r.order, 1.5, 1e-9);
  EXPECT_NEAR(r.extrapolated, 1.0, 1e-12);
}

TEST(StudyRichardson, RefusesWhatItCannotExtrapolate) {
  EXPECT_FALSE(furrow::study::richardson(0.04, 1.0, 0.02, 2.0, 0.01, 1.5).ok);   // differences change sign
  EXPECT_FALSE(furrow::study::richardson(0.04, 1.0, 0.02, 2.0, 0.02, 2.5).ok);   // two rungs at one dx
  EXPECT_FALSE(furrow::study::richardson(0.04, 1.0, 0.02, 1.0, 0.01, 1.0).ok);   // converged to the digit
}

// Two settings ("a" first order, "b" second order) converging to the same limit Q0.
std::vector<Rung> made_up_ladder(double Q0) {
  std::vector<Rung> rungs;
  for (const std::string g : {"a", "b"})
    for (double h : {0.04, 0.02, 0.01}) {
      Rung r;
      r.dir = g + std::to_string(h);
      r.group = g;
      r.dx_m = h;
      r.ok = true;
      r.value = g == "a" ? Q0 + 10.0 * h : Q0 - 50.0 * h * h;
      r.estimated_particle_steps = r.particle_steps = 1.0 / (h * h * h);
      r.wall_s = (g == "a" ? 1.0 : 2.0) * r.particle_steps * 1e-6;
      rungs.push_back(r);
    }
  return rungs;
}

TEST(StudyAnalysis, ErrorsAreMeasuredFromTheExtrapolationOfTheMostExpensiveSettings) {
  const double Q0 = 100.0;
  auto rungs = made_up_ladder(Q0);
  const auto s = furrow::study::analyse(rungs);
  // at equal particle-steps the slower settings ("b") count as the more expensive ones
  EXPECT_NE(s.reference_from.find("b"), std::string::npos) << s.reference_from;
  EXPECT_NEAR(s.reference, Q0, 1e-9);
  for (const auto& r : rungs) {
    const double exact = r.group == "a" ? 10.0 * r.dx_m : 50.0 * r.dx_m * r.dx_m;
    EXPECT_NEAR(r.error_relative, exact / Q0, 1e-9) << r.dir;
    EXPECT_NEAR(r.extrapolated, Q0, 1e-9) << r.dir;
    if (r.dx_m == 0.04) {
      EXPECT_NEAR(r.order, r.group == "a" ? 1.0 : 2.0, 1e-9) << r.dir;
    } else {
      EXPECT_TRUE(std::isnan(r.order)) << r.dir;  // needs two finer rungs
    }
    if (r.dx_m == 0.01) {
      EXPECT_EQ(r.diff_finest, 0.0);
    }
  }
}

// case 3's quantity: the lead body's relative drag fluctuation as run.json's analysis states it,
// refused (NaN and a reason) where the run has none or another body is asked for
TEST(StudyQuantity, FluctuationIsReadFromTheRunsDragAnalysis) {
  using namespace furrow::study;
  const Quantity q = parse_quantity("fluctuation");
  EXPECT_EQ(quantity_column(q), "fluctuation_relative");
  const furrow::sweep::RunMetrics metrics;
  nlohmann::json run = {{"analysis", {{"lead_body", "plow"}, {"drag", {{"relative_fluctuation", 0.0342}}}}}};
  std::string why;
  EXPECT_DOUBLE_EQ(extract(q, metrics, run, "", &why), 0.0342);
  EXPECT_DOUBLE_EQ(extract(q, metrics, run, "plow", &why), 0.0342);
  EXPECT_TRUE(std::isnan(extract(q, metrics, run, "other", &why)));
  EXPECT_NE(why.find("lead body"), std::string::npos) << why;
  run["analysis"]["drag"]["relative_fluctuation"] = nullptr;  // too short a travel
  EXPECT_TRUE(std::isnan(extract(q, metrics, run, "", &why)));
  EXPECT_NE(why.find("fluctuation"), std::string::npos) << why;
}

TEST(StudyPrediction, ALineInParticleStepsThroughTheFinishedRungs) {
  std::vector<Rung> rungs(4);
  for (size_t i = 0; i < rungs.size(); ++i) {
    rungs[i].dir = "r" + std::to_string(i);
    rungs[i].estimated_particle_steps = 1e6 * std::pow(8.0, double(i));
    rungs[i].wall_s = 0.3 + 2e-8 * rungs[i].estimated_particle_steps;  // start-up + cost per particle-step
  }
  std::string basis;
  EXPECT_TRUE(std::isnan(furrow::study::predict_wall_s(rungs, rungs[0], &basis)));  // nothing finished
  rungs[0].ok = true;
  // one finished rung: proportional to particle-steps
  EXPECT_NEAR(furrow::study::predict_wall_s(rungs, rungs[1], &basis), rungs[0].wall_s * 8.0, 1e-9);
  rungs[1].ok = true;
  EXPECT_NEAR(furrow::study::predict_wall_s(rungs, rungs[3], &basis), rungs[3].wall_s, 1e-9 * rungs[3].wall_s) << basis;
  // a rung of other settings is predicted from the most expensive finished rung of any settings
  rungs[2].group = "other";
  EXPECT_NEAR(furrow::study::predict_wall_s(rungs, rungs[2], &basis), rungs[1].wall_s * 8.0, 1e-9);
  EXPECT_NE(basis.find("other settings"), std::string::npos);
}

// ---- the real binary ----------------------------------------------------------------------------

struct Table {
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
};

Table read_csv(const fs::path& p) {
  Table t;
  std::istringstream in(read_text(p));
  std::string line;
  auto split = [](const std::string& l) {
    std::vector<std::string> out(1);
    for (char c : l) {
      if (c == ',') out.emplace_back();
      else out.back() += c;
    }
    return out;
  };
  std::getline(in, line);
  t.header = split(line);
  while (std::getline(in, line)) {
    const auto cells = split(line);
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < t.header.size() && i < cells.size(); ++i) row[t.header[i]] = cells[i];
    t.rows.push_back(row);
  }
  return t;
}

class StudyCli : public furrow::cli_test::CliFixture {
 protected:
  StudyCli() : CliFixture("furrow_study_") {}
  void SetUp() override {
    CliFixture::SetUp();
    std::ofstream(path("tiny.json")) << furrow::cli_test::tiny_plate_scene();
  }
};

TEST_F(StudyCli, TableAgreesWithItsRunsAndARerunReusesThem) {
  const std::string out = path("s");
  auto r = run({"study", path("tiny.json"), "--ladder", "domain.dx_m=0.01,0.005,0.0025", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table t = read_csv(fs::path(out) / "study.csv");
  ASSERT_EQ(t.rows.size(), 3u);
  for (const char* col : {"drag_mean_N_per_m", "diff_from_finest_N_per_m", "extrapolated_N_per_m", "observed_order",
                          "error_vs_reference_percent", "predicted_wall_s", "wall_s", "particle_steps", "peak_memory_MB"})
    EXPECT_NE(std::find(t.header.begin(), t.header.end(), col), t.header.end()) << col;
  std::vector<double> q, h;
  for (const auto& row : t.rows) {
    ASSERT_EQ(row.at("status"), "ok") << row.at("note");
    // the value is the run's own window-mean drag: for a plate moving down, drag = Fy
    const auto j = nlohmann::json::parse(read_text(fs::path(out) / row.at("rung") / "run.json"));
    const double fy = j["bodies"][0]["mean_force_N_per_m"][1].get<double>();
    EXPECT_NEAR(std::stod(row.at("drag_mean_N_per_m")), fy, 1e-6 * std::abs(fy)) << row.at("rung");
    EXPECT_EQ(std::stod(row.at("particle_steps")), j["particles"].get<double>() * j["steps"].get<double>());
    q.push_back(std::stod(row.at("drag_mean_N_per_m")));
    h.push_back(std::stod(row.at("dx_m")));
  }
  // rows follow the ladder; the table's extrapolation is the three rungs' Richardson value
  ASSERT_GT(h[0], h[1]);
  ASSERT_GT(h[1], h[2]);
  // the tiny plate's drag over this ladder converges monotonically (its differences keep their
  // sign), so the three rungs have a Richardson value and the table must hold it
  const auto rich = furrow::study::richardson(h[0], q[0], h[1], q[1], h[2], q[2]);
  std::printf("drag %.6g / %.6g / %.6g N/m at dx %g / %g / %g m: Richardson %.6g, order %.3g\n", q[0], q[1], q[2], h[0],
              h[1], h[2], rich.extrapolated, rich.order);
  ASSERT_TRUE(rich.ok) << rich.note;
  EXPECT_NEAR(std::stod(t.rows[2].at("extrapolated_N_per_m")), rich.extrapolated, 1e-6 * std::abs(rich.extrapolated));
  EXPECT_NEAR(std::stod(t.rows[0].at("observed_order")), rich.order, 1e-3 * std::max(1.0, std::abs(rich.order)));
  EXPECT_EQ(std::stod(t.rows[2].at("diff_from_finest_N_per_m")), 0.0);
  // every rung after the first was predicted from the rungs finished before it (one at a time,
  // cheapest first), as predict_wall_s says from their stored wall times and particle-step
  // estimates: checked against that arithmetic, not against the clock (the wall times are the
  // machine's load; how close the prediction came is printed)
  EXPECT_TRUE(t.rows[0].at("predicted_wall_s").empty());
  const auto sj = nlohmann::json::parse(read_text(fs::path(out) / "study.json"));
  ASSERT_EQ(sj.at("rungs").size(), 3u);
  std::vector<Rung> done(3);
  for (size_t i = 0; i < 3; ++i) {
    const auto& e = sj.at("rungs")[i];
    done[i].dir = e.at("dir").get<std::string>();
    done[i].wall_s = e.at("wall_s").get<double>();
    done[i].estimated_particle_steps = e.at("estimated_particle_steps").get<double>();
  }
  ASSERT_LT(done[0].estimated_particle_steps, done[1].estimated_particle_steps);
  ASSERT_LT(done[1].estimated_particle_steps, done[2].estimated_particle_steps);
  for (size_t i = 1; i < 3; ++i) {
    done[i - 1].ok = true;
    std::string basis;
    const double expected = furrow::study::predict_wall_s(done, done[i], &basis);
    const double predicted = std::stod(t.rows[i].at("predicted_wall_s")), took = std::stod(t.rows[i].at("wall_s"));
    std::printf("rung %zu: predicted %.3g s, took %.3g s\n", i, predicted, took);
    EXPECT_NEAR(predicted, expected, 1e-3 * expected) << t.rows[i].at("rung");
    EXPECT_NEAR(sj.at("rungs")[i].at("predicted_wall_s").get<double>(), expected, 1e-9 * expected);
  }
  EXPECT_TRUE(fs::exists(fs::path(out) / "study.png"));
  EXPECT_NE(read_text(fs::path(out) / "study.md").find("| rung |"), std::string::npos);

  // again: nothing reruns; with one rung's directory gone only that one does
  const auto stamp = fs::last_write_time(fs::path(out) / t.rows[0].at("rung") / "run.json");
  r = run({"study", path("tiny.json"), "--ladder", "domain.dx_m=0.01,0.005,0.0025", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("3 already done"), std::string::npos) << r.err;
  fs::remove_all(fs::path(out) / t.rows[1].at("rung"));
  r = run({"study", path("tiny.json"), "--ladder", "domain.dx_m=0.01,0.005,0.0025", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("2 already done"), std::string::npos) << r.err;
  EXPECT_EQ(fs::last_write_time(fs::path(out) / t.rows[0].at("rung") / "run.json"), stamp);
  const Table t2 = read_csv(fs::path(out) / "study.csv");
  EXPECT_EQ(t2.rows[1].at("status"), "ok");
  EXPECT_EQ(t2.rows[0].at("status"), "reused");
  EXPECT_EQ(t2.rows[1].at("drag_mean_N_per_m"), t.rows[1].at("drag_mean_N_per_m"));  // deterministic
}

TEST_F(StudyCli, StoredCalibrationPredictsTheFirstRung) {
  // no finished rung to extrapolate from: the first rung's prediction is its particle-steps over the
  // calibrated rate (the tiny scene runs quadratic NDPM on one thread)
  const nlohmann::json c = {
      {"host", "test"}, {"cpu", "test"}, {"date", "today"}, {"particles", 1000},
      {"entries",
       {{{"shape_function", "quadratic"}, {"model", "ndpm"}, {"threads", 1}, {"particle_steps_per_s", 1e5}},
        {{"shape_function", "linear"}, {"model", "ndpm"}, {"threads", 1}, {"particle_steps_per_s", 1e7}}}}};
  std::ofstream(path("calibration.json")) << c.dump();
  const std::string out = path("s");
  const auto r = run({"study", path("tiny.json"), "--ladder", "domain.dx_m=0.01,0.005", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  // the header names the threads the rungs run on (the scene's one), not cores / jobs
  EXPECT_NE(r.err.find("1 at a time, 1 thread each"), std::string::npos) << r.err;
  const Table t = read_csv(fs::path(out) / "study.csv");
  ASSERT_EQ(t.rows.size(), 2u);
  ASSERT_FALSE(t.rows[0].at("predicted_wall_s").empty());
  // validate's particle-step estimate, not the run's count, feeds the prediction: within 10% of it
  EXPECT_NEAR(std::stod(t.rows[0].at("predicted_wall_s")), std::stod(t.rows[0].at("particle_steps")) / 1e5,
              0.1 * std::stod(t.rows[0].at("particle_steps")) / 1e5);
}

TEST_F(StudyCli, StoppedStudyKeepsFinishedRungsAndFinishesOnRerun) {
  const std::string out = path("s");
  // The study sends itself SIGTERM as it starts the third rung, the two cheap ones done
  // (FURROW_SIGTERM_AFTER_RUNGS), through the handler Ctrl-C reaches: on any machine the stop finds
  // two rungs finished and the finest running, which it stops and whose partial run it removes.
  const std::string cmd = "FURROW_SIGTERM_AFTER_RUNGS=2 exec " + furrow::cli_test::quote(FURROW_CLI_PATH) + " study " +
                          furrow::cli_test::quote(path("tiny.json")) +
                          " --ladder domain.dx_m=0.01,0.005,0.0025 --quiet --out " + furrow::cli_test::quote(out);
  auto ok_rungs = [&] {
    int n = 0;
    for (const auto& row : read_csv(fs::path(out) / "study.csv").rows) n += row.count("status") && row.at("status") == "ok";
    return n;
  };
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", (cmd + " >/dev/null 2>" + furrow::cli_test::quote(path("stderr"))).c_str(), (char*)nullptr);
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  const int ok = ok_rungs();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 130) << read_text(path("stderr"));
  EXPECT_EQ(ok, 2) << read_text(path("stderr"));
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
  const auto r = run({"study", path("tiny.json"), "--ladder", "domain.dx_m=0.01,0.005,0.0025", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("2 already done"), std::string::npos) << r.err;
  for (const auto& row : read_csv(fs::path(out) / "study.csv").rows) EXPECT_NE(row.at("status"), "pending");
}

TEST_F(StudyCli, BadOptionsStopItBeforeAnythingRuns) {
  struct Case {
    std::vector<std::string> args;
    int status;
    std::vector<std::string> said;
  };
  const std::vector<Case> cases = {
      {{"--ladder", "domain.dxx_m=0.01,0.005"}, 1, {"--ladder domain.dxx_m", "/domain/dxx_m"}},
      {{"--ladder", "domain.dx_m=0.01,-0.005"}, 1, {"--ladder", "/domain/dx_m", "-0.005"}},
      {{"--ladder", "domain.dx_m=0.01", "--quantity", "wedge_angle"}, 1, {"--quantity wedge_angle", "velocity"}},
      {{"--ladder", "domain.dx_m=0.01", "--quantity", "drag"}, 2, {"--quantity drag", "drag_mean"}},
      {{"--ladder", "domain.dx_m=0.01", "--body", "rod"}, 1, {"--body rod", "plate"}},
      {{"--ladder", "domain.dx_m=0.01", "--ladder", "domain.dx_m=0.005"}, 2, {"domain.dx_m", "twice"}},
      {{}, 2, {"--ladder"}},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = {"study", path("tiny.json"), "--out", path("s")};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const auto r = run(args);
    EXPECT_EQ(r.status, c.status) << r.err;
    for (const auto& s : c.said) EXPECT_NE(r.err.find(s), std::string::npos) << "expected '" << s << "' in: " << r.err;
    EXPECT_FALSE(fs::exists(path("s"))) << "a bad study wrote " << path("s");
  }
  // a rung directory that holds a different run is never overwritten
  auto r = run({"run", path("tiny.json"), "--set", "domain.dx_m=0.01", "--set", "solver.cfl=0.3", "--no-movies",
                "--quiet", "--out", path("s") + "/tiny_domain.dx_m=0.01"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = run({"study", path("tiny.json"), "--ladder", "domain.dx_m=0.01,0.005", "--out", path("s")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("/solver/cfl"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("s") + "/tiny_domain.dx_m=0.005"));
}

}  // namespace
