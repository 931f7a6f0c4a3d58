// Runs the real furrow binary as a user would, in a fresh per-test directory: exit status,
// stdout and stderr.
#pragma once
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#ifndef FURROW_CLI_PATH
#error "FURROW_CLI_PATH must name the furrow binary (set by CMakeLists.txt)"
#endif

namespace furrow::cli_test {

namespace fs = std::filesystem;

// Under CI (CI=true) the tools .ci/setup.sh installs (MPI, Xvfb, XTest) must work: a test that
// cannot run for want of one fails there, and is skipped elsewhere.
inline bool on_ci() {
  const char* v = std::getenv("CI");
  return v && std::string(v) == "true";
}
#define FURROW_SKIP_UNLESS_CI(why)                                                     \
  do {                                                                                 \
    const std::string furrow_why_ = (why);                                             \
    if (::furrow::cli_test::on_ci()) FAIL() << furrow_why_ << " (CI=true: .ci/setup.sh installs it)"; \
    GTEST_SKIP() << furrow_why_;                                                       \
  } while (0)

struct Result {
  int status = -1;
  std::string out, err;
};

inline std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// One JSON object per line of a command's stdout (inspect, edit).
inline std::vector<nlohmann::json> json_lines(const std::string& out) {
  std::vector<nlohmann::json> v;
  std::istringstream in(out);
  for (std::string l; std::getline(in, l);) v.push_back(nlohmann::json::parse(l));
  return v;
}

inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

class CliFixture : public ::testing::Test {
 protected:
  explicit CliFixture(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    dir_ = fs::temp_directory_path() / (prefix_ + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A calibration left in the user's config by `furrow bench` changes what validate, run and
    // study print; each test starts without one unless it writes calibration.json itself.
    ::setenv("FURROW_CALIBRATION", path("calibration.json").c_str(), 1);
  }
  void TearDown() override {
    ::unsetenv("FURROW_CALIBRATION");
    fs::remove_all(dir_);
  }

  Result run(const std::vector<std::string>& args) {
    std::string cmd = quote(FURROW_CLI_PATH);
    for (const auto& a : args) cmd += " " + quote(a);
    cmd += " >" + quote((dir_ / "stdout").string()) + " 2>" + quote((dir_ / "stderr").string());
    const int rc = std::system(cmd.c_str());
    Result r;
    r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    r.out = read_text(dir_ / "stdout");
    r.err = read_text(dir_ / "stderr");
    return r;
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::string prefix_;
  fs::path dir_;
};

}  // namespace furrow::cli_test
