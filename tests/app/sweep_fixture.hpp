// What the sweep tests share: a tiny scene, sweep.csv as rows of named cells, and the furrow
// binary started in the background (to be stopped part-way) or under mpirun.
#pragma once
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/app/cli_fixture.hpp"

extern char** environ;

namespace furrow::cli_test {

// A 0.1 x 0.05 m bed at dx 5 mm (about 800 particles): a plate pushed down 15 mm from 0.5 mm above
// the surface and a rod dragged sideways; each run takes well under a second.
inline const char* kTinyScene = R"({
  "schema_version": 1,
  "name": "tiny",
  "domain": {"width_m": 0.1, "height_m": 0.07, "dx_m": 0.005},
  "solver": {"end_time_s": 1.0, "end_displacement_m": 0.0155, "threads": 1},
  "materials": [{"name": "sand", "model": "ndpm", "grain_density_kg_m3": 2500, "phi_c": 0.6, "mu_s": 0.4}],
  "beds": [{"material": "sand", "min_m": [0, 0], "max_m": [0.1, 0.05], "packing_fraction": 0.58}],
  "bodies": [
    {"name": "plate", "shape": {"type": "box", "size_m": [0.02, 0.01]}, "start_m": [0.05, 0.0555],
     "motion": {"type": "constant_velocity", "velocity_m_s": [0, -0.1]}},
    {"name": "rod", "shape": {"type": "circle", "radius_m": 0.005}, "start_m": [0.015, 0.03],
     "motion": {"type": "constant_velocity", "velocity_m_s": [0.05, 0]}}
  ],
  "outputs": {"average_window": {"from_m": 0.0085, "to_m": 0.0155}}
})";

// The same bed with the plate alone (what the study tests read).
inline std::string tiny_plate_scene() {
  auto j = nlohmann::json::parse(kTinyScene);
  j["bodies"].erase(1);
  return j.dump(2);
}

inline std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out(1);
  for (char c : line) {
    if (c == sep) out.emplace_back();
    else out.back() += c;
  }
  return out;
}

// One CSV line into cells; a quoted cell may hold commas and doubled quotes.
inline std::vector<std::string> csv_cells(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"' && quoted && i + 1 < line.size() && line[i + 1] == '"') out.back() += c, ++i;
    else if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) out.emplace_back();
    else out.back() += c;
  }
  return out;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  double num(size_t r, const std::string& col) const {
    auto it = rows.at(r).find(col);
    if (it == rows.at(r).end()) ADD_FAILURE() << "no column " << col;
    return it == rows.at(r).end() || it->second.empty() ? NAN : std::stod(it->second);
  }
};

inline Csv read_csv(const fs::path& p) {
  std::istringstream in(read_text(p));
  Csv c;
  std::string line;
  std::getline(in, line);
  c.header = csv_cells(line);
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const auto cells = csv_cells(line);
    EXPECT_EQ(cells.size(), c.header.size()) << line;
    std::map<std::string, std::string> row;
    for (size_t k = 0; k < std::min(cells.size(), c.header.size()); ++k) row[c.header[k]] = cells[k];
    c.rows.push_back(row);
  }
  return c;
}

// A process started in the background, its output going to files of the test directory.
struct Child {
  pid_t pid = -1;
  fs::path out, err;
  int wait_status = -1;  // once it ended
};

class SweepCli : public CliFixture {
 protected:
  SweepCli() : CliFixture("furrow_sweep_cli_") {}
  void SetUp() override {
    CliFixture::SetUp();
    std::ofstream(dir_ / "tiny.json") << kTinyScene;
  }
  // Nothing but the scene and the captured output in the test directory.
  void expect_nothing_written() const {
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      EXPECT_TRUE(n == "tiny.json" || n == "stdout" || n == "stderr") << "unexpected " << n;
    }
  }

  // argv[0] is looked up in PATH; `extra_env` (NAME=VALUE) is added to this child's environment only.
  Child start(const std::vector<std::string>& argv, const std::vector<std::string>& extra_env = {}) {
    static int n = 0;
    Child c;
    c.out = dir_ / ("child" + std::to_string(n) + ".out");
    c.err = dir_ / ("child" + std::to_string(n++) + ".err");
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, c.out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, 2, c.err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<std::string> env(extra_env);
    for (char** e = environ; *e; ++e) env.push_back(*e);
    std::vector<std::string> args(argv);
    std::vector<char*> a, e;
    for (auto& s : args) a.push_back(s.data());
    for (auto& s : env) e.push_back(s.data());
    a.push_back(nullptr);
    e.push_back(nullptr);
    // its own process group, so a stop can signal the whole job as a batch system does
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attr, 0);
    const int rc = posix_spawnp(&c.pid, a[0], &fa, &attr, a.data(), e.data());
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) c.pid = -1;
    return c;
  }
  // Exit status (-1 when killed by a signal) and output; a child still running after `timeout_s`
  // (a hung mpirun) is killed.
  Result finish(Child& c, double timeout_s = 300) {
    Result r;
    if (c.pid > 0 && c.wait_status < 0) wait_until([] { return false; }, timeout_s, &c);
    if (c.pid > 0 && c.wait_status < 0) {
      ADD_FAILURE() << "killed after " << timeout_s << " s: " << read_text(c.err);
      ::kill(c.pid, SIGKILL);
      ::waitpid(c.pid, &c.wait_status, 0);
    }
    r.status = c.wait_status >= 0 && WIFEXITED(c.wait_status) ? WEXITSTATUS(c.wait_status) : -1;
    r.out = read_text(c.out);
    r.err = read_text(c.err);
    return r;
  }
  // Waits until `ready()` (true), or `timeout_s` passes or the child (if any) ends (false).
  static bool wait_until(const std::function<bool()>& ready, double timeout_s, Child* c = nullptr) {
    if (c && c->pid <= 0) return false;
    const auto t0 = std::chrono::steady_clock::now();
    while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < timeout_s) {
      if (ready()) return true;
      if (c && ::waitpid(c->pid, &c->wait_status, WNOHANG) == c->pid) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
};

}  // namespace furrow::cli_test
