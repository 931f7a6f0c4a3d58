// furrow run stopped by a signal (a batch system's time limit) and continued with --resume.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "tests/app/cli_fixture.hpp"
#include "tests/app/sweep_fixture.hpp"

namespace fs = std::filesystem;
using furrow::cli_test::read_text;

class RunCli : public furrow::cli_test::CliFixture {
 protected:
  RunCli() : CliFixture("furrow_run_") {}
  void SetUp() override {
    CliFixture::SetUp();
    std::ofstream(path("tiny.json")) << furrow::cli_test::tiny_plate_scene();
  }
};

TEST_F(RunCli, SigtermCheckpointsAndResumeFinishesTheRun) {
  // dx 2.5 mm: ~3k points, a few seconds on one thread. The run sends itself SIGTERM after step 200
  // (FURROW_SIGTERM_AT_STEP) through the same handler a batch system's signal reaches, so the stop
  // lands at a known step however loaded the machine is.
  const std::string out = path("run");
  const std::string cmd = "FURROW_SIGTERM_AT_STEP=200 exec " + furrow::cli_test::quote(FURROW_CLI_PATH) + " run " +
                          furrow::cli_test::quote(path("tiny.json")) +
                          " --set domain.dx_m=0.0025 --no-movies --no-paraview --out " + furrow::cli_test::quote(out);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", (cmd + " >" + path("stdout1") + " 2>" + path("stderr1")).c_str(), (char*)nullptr);
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  const fs::path partial = out + ".partial-" + std::to_string(pid);
  ASSERT_FALSE(fs::exists(out)) << "the run was not stopped: " << read_text(path("stderr1"));
  ASSERT_TRUE(WIFEXITED(status)) << "killed instead of stopping";
  EXPECT_EQ(WEXITSTATUS(status), 130);
  const std::string said = read_text(path("stderr1"));
  EXPECT_NE(said.find("stopped by signal 15 at step 200"), std::string::npos) << said;
  EXPECT_NE(said.find("--resume"), std::string::npos) << said;
  ASSERT_TRUE(fs::exists(partial / "checkpoint" / "simulation.bin"));
  const auto stopped_at = nlohmann::json::parse(read_text(partial / "checkpoint" / "run.json")).at("steps").get<int64_t>();
  EXPECT_EQ(stopped_at, 200);

  // starting afresh says a checkpoint is there; --resume continues it
  auto r = run({"run", path("tiny.json"), "--set", "domain.dx_m=0.0025", "--set", "solver.max_steps=2", "--no-movies",
                "--out", path("other")});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("holds a checkpoint"), std::string::npos) << "another --out has no checkpoint: " << r.err;
  r = run({"run", path("tiny.json"), "--set", "domain.dx_m=0.0025", "--no-movies", "--no-paraview", "--resume",
           "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("resumed from the checkpoint at step " + std::to_string(stopped_at)), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(read_text(fs::path(out) / "run.json"));
  EXPECT_EQ(j.at("segments").get<int>(), 2);
  EXPECT_GT(j.at("steps").get<int64_t>(), stopped_at);
  EXPECT_FALSE(fs::exists(partial));
  EXPECT_FALSE(fs::exists(fs::path(out) / "checkpoint"));

  // a checkpoint of a different scene under the same --out is refused, naming it
  const std::string out2 = path("run2");
  const pid_t gone = ::fork();  // the pid of a process that has ended, as a killed run's would be
  if (gone == 0) ::_exit(0);
  ::waitpid(gone, &status, 0);
  const std::string left = out2 + ".partial-" + std::to_string(gone);
  fs::create_directories(left + "/checkpoint");
  std::ofstream(left + "/checkpoint/run.json") << R"({"scene_hash": "0000000000000000", "steps": 5})";
  r = run({"run", path("tiny.json"), "--resume", "--no-movies", "--out", out2});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(left + " holds a checkpoint of a different scene"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out2));
  // a bad interval is a usage error
  r = run({"run", path("tiny.json"), "--checkpoint-every", "-5", "--out", path("run3")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--checkpoint-every"), std::string::npos) << r.err;
}
