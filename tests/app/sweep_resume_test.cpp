// Sweeps that outlive one process: spread over the ranks of an MPI job, stopped part-way and run
// again, and runs that fail among runs that do not.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <nlohmann/json.hpp>
#include <set>

#include "tests/app/sweep_fixture.hpp"

namespace fs = std::filesystem;

namespace {

using namespace furrow::cli_test;

// 2 plate widths x 3 rod depths
const std::vector<std::string> kSixRuns = {"--vary", "bodies.plate.shape.size_m.0=0.02,0.03", "--vary",
                                           "bodies.rod.start_m.1=0.025:0.035:0.005"};
// Open MPI refuses to start as root unless told so; only the mpirun children are told.
const std::vector<std::string> kMpiEnv = {"OMPI_ALLOW_RUN_AS_ROOT=1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1"};

// A run directory's identity: a rerun writes it anew (run_scene renames a new directory into place).
struct Written {
  ino_t dir_inode = 0, run_json_inode = 0;
  bool operator==(const Written& o) const { return dir_inode == o.dir_inode && run_json_inode == o.run_json_inode; }
};

// The finished runs in a sweep directory (those with a run.json), by name. A run being written
// lives in NAME.partial-PID, which holds its run.json just before the rename: not finished.
std::map<std::string, Written> finished_runs(const fs::path& sweep_dir) {
  std::map<std::string, Written> out;
  for (const auto& e : fs::directory_iterator(sweep_dir)) {
    if (e.path().filename().string().find(".partial-") != std::string::npos) continue;
    struct stat d {}, j {};
    if (::stat(e.path().c_str(), &d) == 0 && ::stat((e.path() / "run.json").c_str(), &j) == 0)
      out[e.path().filename().string()] = {d.st_ino, j.st_ino};
  }
  return out;
}

size_t count_with(const fs::path& dir, const std::string& part) {
  size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.path().filename().string().find(part) != std::string::npos;
  return n;
}

// The processes that were writing runs: NAME.partial-PID.
std::vector<pid_t> partial_pids(const fs::path& dir) {
  std::vector<pid_t> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (const auto at = n.rfind(".partial-"); at != std::string::npos) out.push_back(pid_t(std::stol(n.substr(at + 9))));
  }
  return out;
}

bool any_process_alive(const std::vector<pid_t>& pids) {
  for (const pid_t p : pids)
    if (p > 0 && ::kill(p, 0) == 0) return true;
  return false;
}

std::map<std::string, size_t> statuses(const fs::path& sweep_json) {
  std::map<std::string, size_t> n;
  const auto j = nlohmann::json::parse(read_text(sweep_json));
  for (const auto& r : j["runs"]) ++n[r["status"].get<std::string>()];
  return n;
}

class SweepResume : public SweepCli {
 protected:
  std::vector<std::string> sweep(const std::vector<std::string>& vary, const std::string& out) {
    std::vector<std::string> a = {"sweep", path("tiny.json")};
    a.insert(a.end(), vary.begin(), vary.end());
    a.insert(a.end(), {"--out", path(out)});
    return a;
  }
  std::vector<std::string> mpirun(int ranks, const std::vector<std::string>& args) {
    std::vector<std::string> a = {"mpirun", "--oversubscribe", "-np", std::to_string(ranks), FURROW_CLI_PATH};
    a.insert(a.end(), args.begin(), args.end());
    return a;
  }
  // "" when mpirun starts ranks of this furrow here, else why not.
  std::string mpi_unavailable() {
    if (run({"--version"}).out.find("MPI: yes") == std::string::npos) return "this furrow is built without MPI";
    Child c = start(mpirun(2, {"--version"}), kMpiEnv);
    if (c.pid < 0) return "no mpirun on PATH";
    const Result r = finish(c);
    return r.status == 0 ? "" : "mpirun cannot start 2 ranks here: " + r.err;
  }
  // Starts `argv`, sends it SIGTERM as soon as one run has finished, and returns the finished runs.
  std::map<std::string, Written> stop_after_first_run(const std::vector<std::string>& argv,
                                                      const std::vector<std::string>& env, const fs::path& out) {
    Child c = start(argv, env);
    if (c.pid <= 0) {  // never kill(-1, ...): that signals every process we may signal
      ADD_FAILURE() << "could not start " << argv[0];
      return {};
    }
    const bool one = wait_until([&] { return fs::exists(out) && !finished_runs(out).empty(); }, 120, &c);
    ::kill(-c.pid, SIGTERM);  // the job's process group (c.pid > 0 checked above)
    const Result r = finish(c);
    EXPECT_TRUE(one) << "no run finished: " << r.err;
    EXPECT_NE(r.status, 0) << "the sweep ended before it was stopped: " << r.err;
    // mpirun may exit before its ranks are gone; the job is over when they are
    wait_until([&] { return !any_process_alive(partial_pids(out)); }, 10);
    return finished_runs(out);
  }
  // Runs the same sweep again: every run that was finished is kept as it was, the rest are run.
  void expect_rerun_completes_only_the_rest(const std::map<std::string, Written>& before, const Result& again,
                                            const fs::path& out, size_t runs) {
    ASSERT_EQ(again.status, 0) << again.err;
    EXPECT_NE(again.err.find("(" + std::to_string(before.size()) + " already done)"), std::string::npos) << again.err;
    const auto after = finished_runs(out);
    EXPECT_EQ(after.size(), runs);
    for (const auto& [name, w] : before) EXPECT_TRUE(after.at(name) == w) << name << " was run again";
    EXPECT_EQ(count_with(out, ".partial-"), 0u) << "a run killed part-way was left behind";
    auto n = statuses(out / "sweep.json");
    EXPECT_EQ(n["reused"], before.size());
    EXPECT_EQ(n["ok"], runs - before.size());
    const Csv csv = read_csv(out / "sweep.csv");
    ASSERT_EQ(csv.rows.size(), runs);
    for (size_t i = 0; i < runs; ++i) {
      EXPECT_EQ(csv.rows[i].at("status"), "ok");
      EXPECT_GT(csv.num(i, "plate.mean_drag_N_per_m"), 0.0);
    }
  }
};

// The columns that depend on where and when a run ran, not on what it computed.
bool timing_column(const std::string& name) { return name == "wall_s"; }

}  // namespace

TEST_F(SweepResume, ThreeMpiRanksWriteTheTableOfOneProcess) {
  if (const std::string why = mpi_unavailable(); !why.empty()) FURROW_SKIP_UNLESS_CI(why);
  const Result local = run(sweep(kSixRuns, "local"));
  ASSERT_EQ(local.status, 0) << local.err;
  Child c = start(mpirun(3, sweep(kSixRuns, "mpi")), kMpiEnv);
  const Result mpi = finish(c);
  ASSERT_EQ(mpi.status, 0) << mpi.err;

  const Csv a = read_csv(path("local/sweep.csv")), b = read_csv(path("mpi/sweep.csv"));
  ASSERT_EQ(a.rows.size(), 6u);
  ASSERT_EQ(b.header, a.header);
  ASSERT_EQ(b.rows.size(), a.rows.size());
  for (size_t i = 0; i < a.rows.size(); ++i) {
    EXPECT_EQ(a.rows[i].at("status"), "ok");
    for (const auto& col : a.header)
      if (!timing_column(col)) {
        EXPECT_EQ(b.rows[i].at(col), a.rows[i].at(col)) << "row " << i << ", " << col;
      }
  }
  // the numbers compared are forces, different for each run
  std::set<std::string> drags;
  for (const auto& r : b.rows) drags.insert(r.at("rod.mean_drag_N_per_m"));
  EXPECT_EQ(drags.size(), 6u);

  // rank 0 reported every run, and the runs went to more than one rank
  const auto sj = nlohmann::json::parse(read_text(path("mpi/sweep.json")));
  EXPECT_EQ(sj["ranks"], 3);
  std::set<int> ranks;
  for (const auto& r : sj["runs"]) ranks.insert(r["rank"].get<int>());
  EXPECT_GE(ranks.size(), 2u) << sj["runs"].dump();
  size_t progress_lines = 0;
  for (const auto& line : split(mpi.err, '\n')) progress_lines += line.rfind("[", 0) == 0;
  EXPECT_EQ(progress_lines, 6u) << mpi.err;
}

TEST_F(SweepResume, StoppedSweepRunsOnlyTheMissingRunsAgain) {
  // finer runs (about 3x the particle-steps) long enough to stop the sweep between them; they run first
  const std::vector<std::string> vary = {"--vary", "domain.dx_m=0.005,0.0035", "--vary", "bodies.rod.start_m.1=0.03,0.035"};
  std::vector<std::string> argv = sweep(vary, "sw");
  argv.insert(argv.begin(), FURROW_CLI_PATH);
  const auto before = stop_after_first_run(argv, {}, path("sw"));
  ASSERT_GE(before.size(), 1u);
  ASSERT_LT(before.size(), 4u);
  for (const auto& [name, w] : before) EXPECT_NE(name.find("dx_m=0.0035"), std::string::npos) << "longest first";
  expect_rerun_completes_only_the_rest(before, run(sweep(vary, "sw")), path("sw"), 4);
}

// The templates name movies; a sweep renders them only with --movies. What defines a run's
// result leaves the movies out (they are drawn from the stored frames afterwards), so the same
// sweep again reuses its finished runs (until 2026-12-03 every template's runs were "a different
// scene, differs at /outputs/movies" and the rerun stopped).
TEST_F(SweepResume, SceneWithMoviesIsReusedBySweepsThatDoNotRenderThem) {
  const std::vector<std::string> vary = {"--vary", "bodies.rod.start_m.1=0.03,0.035", "--set",
                                         R"(outputs.movies=["pressure"])", "--set", R"(outputs.fields=["pressure"])",
                                         "--set", "outputs.frame_interval_s=0.05"};
  const Result first = run(sweep(vary, "sw"));
  ASSERT_EQ(first.status, 0) << first.err;
  const auto before = finished_runs(path("sw"));
  ASSERT_EQ(before.size(), 2u);
  const Result again = run(sweep(vary, "sw"));
  expect_rerun_completes_only_the_rest(before, again, path("sw"), 2);
  EXPECT_EQ(again.err.find("no sweep.png"), std::string::npos) << "the figure follows the table: " << again.err;
}

TEST_F(SweepResume, StoppedMpiJobRunsOnlyTheMissingRunsAgain) {
  if (const std::string why = mpi_unavailable(); !why.empty()) FURROW_SKIP_UNLESS_CI(why);
  // runs long enough (dx 2.5 mm) that the second pair cannot finish while the stop reaches the ranks
  const std::vector<std::string> vary = {"--vary", "domain.dx_m=0.0025", "--vary", "bodies.rod.start_m.1=0.025:0.04:0.005"};
  const auto before = stop_after_first_run(mpirun(2, sweep(vary, "sw")), kMpiEnv, path("sw"));
  ASSERT_GE(before.size(), 1u);
  ASSERT_LT(before.size(), 4u);
  Child c = start(mpirun(2, sweep(vary, "sw")), kMpiEnv);
  expect_rerun_completes_only_the_rest(before, finish(c), path("sw"), 4);
}

TEST_F(SweepResume, InvalidCombinationIsAFailedRowAndTheOthersRun) {
  const std::vector<std::string> vary = {"--vary", "bodies.plate.shape.size_m.0=0.02,-0.02,0.03"};
  const Result r = run(sweep(vary, "sw"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("(0 reused, 1 failed)"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("1 of 3 runs failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/bodies/0/shape/size_m/0"), std::string::npos) << r.err;
  const Csv csv = read_csv(path("sw/sweep.csv"));
  ASSERT_EQ(csv.rows.size(), 3u);
  EXPECT_NE(std::find(csv.header.begin(), csv.header.end(), "error"), csv.header.end());
  EXPECT_EQ(csv.rows[1].at("status"), "failed");
  EXPECT_NE(csv.rows[1].at("error").find("/bodies/0/shape/size_m/0"), std::string::npos) << csv.rows[1].at("error");
  EXPECT_NE(csv.rows[1].at("error").find("set by --vary bodies.plate.shape.size_m.0=0.02,-0.02,0.03"),
            std::string::npos) << csv.rows[1].at("error");
  EXPECT_TRUE(std::isnan(csv.num(1, "plate.mean_drag_N_per_m")));
  for (size_t i : {0, 2}) {
    EXPECT_EQ(csv.rows[i].at("status"), "ok");
    EXPECT_EQ(csv.rows[i].at("error"), "");
    EXPECT_GT(csv.num(i, "plate.mean_drag_N_per_m"), 0.0);
  }
  // a wider plate meets more resistance
  EXPECT_GT(csv.num(2, "plate.mean_drag_N_per_m"), csv.num(0, "plate.mean_drag_N_per_m"));

  // again: the two runs are kept, the invalid one is reported again
  const auto kept = finished_runs(path("sw"));
  ASSERT_EQ(kept.size(), 2u);
  const Result again = run(sweep(vary, "sw"));
  EXPECT_EQ(again.status, 1);
  EXPECT_NE(again.out.find("(2 reused, 1 failed)"), std::string::npos) << again.out;
  EXPECT_TRUE(finished_runs(path("sw")) == kept);

  // the same runs of another version of the scene do not join this table
  const auto csv_before = read_text(path("sw/sweep.csv"));
  std::vector<std::string> other = sweep(vary, "sw");
  other.insert(other.end(), {"--set", "bodies.rod.friction=0.2"});
  const Result mixed = run(other);
  EXPECT_EQ(mixed.status, 1);
  EXPECT_NE(mixed.err.find(path("sw/tiny_bodies.plate.shape.size_m.0=0.02")), std::string::npos) << mixed.err;
  EXPECT_NE(mixed.err.find("differs at /bodies/1/friction"), std::string::npos) << mixed.err;
  EXPECT_EQ(read_text(path("sw/sweep.csv")), csv_before);
  EXPECT_TRUE(finished_runs(path("sw")) == kept);
}
