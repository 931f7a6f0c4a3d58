// `furrow templates / new / validate` run as a user would: the real binary, exit codes, stdout and
// stderr, files on disk.
#include <gtest/gtest.h>

#include "tests/app/cli_fixture.hpp"
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/scene/scene_io.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

using furrow::cli_test::Result;
using furrow::cli_test::read_text;
namespace cli_test = furrow::cli_test;

class SceneCli : public cli_test::CliFixture {
 protected:
  SceneCli() : CliFixture("furrow_scene_cli_") {}
};

}  // namespace

TEST_F(SceneCli, TemplatesListsEveryTemplateWithItsDescription) {
  const Result r = run({"templates"});
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  size_t n = 0;
  while (std::getline(lines, line)) {
    ASSERT_LT(n, furrow::scene_templates().size());
    const auto& t = furrow::scene_templates()[n++];
    EXPECT_EQ(line.rfind(t.name + " ", 0), 0u) << line;
    EXPECT_NE(line.find(t.description), std::string::npos) << line;
  }
  EXPECT_EQ(n, furrow::scene_templates().size());
  EXPECT_GE(n, 8u);
}

TEST_F(SceneCli, NewThenValidateRoundTripsEveryTemplate) {
  for (const auto& t : furrow::scene_templates()) {
    SCOPED_TRACE(t.name);
    const std::string file = path(t.name + "_copy.json");
    const Result made = run({"new", t.name, "-o", file});
    ASSERT_EQ(made.status, 0) << made.err;
    const json written = json::parse(read_text(file));
    EXPECT_EQ(written["name"], t.name + "_copy");  // named after the file
    const Result checked = run({"validate", file});
    ASSERT_EQ(checked.status, 0) << checked.err;
    // validate prints the resolved scene: the same document `new` wrote
    EXPECT_EQ(json::parse(checked.out), written);
    EXPECT_EQ(checked.out, read_text(file));
    // and it is the template resolved in-process
    const furrow::Scene s = furrow::parse_scene_text(t.text, t.name, {"name=" + t.name + "_copy"});
    EXPECT_EQ(furrow::scene_to_json(s), written);
    EXPECT_NE(checked.err.find("particles"), std::string::npos);
    EXPECT_NE(checked.err.find("time step"), std::string::npos);
  }
}

TEST_F(SceneCli, NewAppliesSetsAndNeverOverwritesWithoutForce) {
  const std::string file = path("wide.json");
  Result r = run({"new", "plate-intrusion", "-o", file, "--set", "bodies.plate.shape.size_m=[0.2,0.02]",
                  "--set", "domain.dx_m=0.005"});
  ASSERT_EQ(r.status, 0) << r.err;
  json j = json::parse(read_text(file));
  EXPECT_EQ(j["bodies"][0]["shape"]["size_m"], json::parse("[0.2, 0.02]"));
  EXPECT_EQ(j["domain"]["dx_m"], 0.005);

  const std::string before = read_text(file);
  r = run({"new", "blank_bed", "-o", file});
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(file), before);

  r = run({"new", "blank_bed", "-o", file, "--force"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json::parse(read_text(file))["domain"]["width_m"], 0.5);
  // no temporary files left behind
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir_)) files += e.path().filename() == "wide.json";
  EXPECT_EQ(files, 1u);
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST_F(SceneCli, NewRejectsUnknownTemplatesAndBadSets) {
  Result r = run({"new", "plate_intrusionn", "-o", path("x.json")});
  EXPECT_EQ(r.status, 2);
  for (const auto& t : furrow::scene_templates()) EXPECT_NE(r.err.find(t.name), std::string::npos) << r.err;
  r = run({"new", "plate_intrusion", "-o", path("x.json"), "--set", "bodies.plate.friction=-1"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("/bodies/0/friction"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("x.json")));
}

TEST_F(SceneCli, ValidateReportsFileAndPathAndFailsOnBadScenes) {
  struct Bad {
    std::string name, text, path;
  };
  const json good = json::parse(furrow::find_scene_template("plate_intrusion")->text);
  auto with = [&](const std::function<void(json&)>& f) {
    json j = good;
    f(j);
    return j.dump(2);
  };
  const std::vector<Bad> cases = {
      {"truncated.json", good.dump(2).substr(0, 150), "truncated.json:"},
      {"typo.json", with([](json& j) { j["domain"]["dxm"] = 0.01; }), "/domain/dxm"},
      {"negative.json", with([](json& j) { j["domain"]["dx_m"] = -0.01; }), "/domain/dx_m"},
      {"wall.json", with([](json& j) { j["bodies"][0]["start_m"][0] = 1.18; }), "/bodies/0/start_m"},
      {"field.json", with([](json& j) { j["outputs"]["fields"][0] = "strainrate"; }), "/outputs/fields/0"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    std::ofstream(path(c.name)) << c.text;
    const Result r = run({"validate", path(c.name)});
    EXPECT_EQ(r.status, 1);
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_NE(r.err.find(path(c.name)), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.path), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("expected"), std::string::npos) << r.err;
  }
  const Result missing = run({"validate", path("nope.json")});
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("nope.json"), std::string::npos);
}

TEST_F(SceneCli, ValidateSetsAndYes) {
  const std::string file = path("p.json");
  ASSERT_EQ(run({"new", "plate_intrusion", "-o", file}).status, 0);
  Result r = run({"validate", file, "--brief", "--set", "domian.dx_m=0.01"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("/domian"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("did you mean \"domain\""), std::string::npos) << r.err;

  // 1.2 x 0.6 m at dx 0.2 mm: 7.2e7 particles, above the 2e7 guard
  r = run({"validate", file, "--brief", "--set", "domain.dx_m=0.0002"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--yes"), std::string::npos) << r.err;
  r = run({"validate", file, "--brief", "--yes", "--set", "domain.dx_m=0.0002"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty());  // --brief: summary only
  EXPECT_NE(r.err.find("72000000"), std::string::npos) << r.err;
}

// validate says how many cells a body spans across its travel, and how far a plate that size
// reads from its converged force: plate_intrusion's 0.1 m plate descends, so its width counts
// (0.1 m / dx); turned to move sideways its 0.02 m thickness counts.
TEST_F(SceneCli, ValidateGivesCellsAcrossTheTravelAndTheContactBias) {
  const std::string file = path("p.json");
  ASSERT_EQ(run({"new", "plate_intrusion", "-o", file}).status, 0);
  Result r = run({"validate", file, "--brief"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("plate: box, 10 cells across its travel"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cell_fraction contact (a plate this many cells across reads ~4% low"), std::string::npos) << r.err;
  r = run({"validate", file, "--brief", "--set", "domain.dx_m=0.005", "--set", "solver.contact=node"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("20 cells across its travel"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("node contact (a plate this many cells across reads ~6% low"), std::string::npos) << r.err;
  r = run({"validate", file, "--brief", "--set", "bodies.plate.motion.velocity_m_s=[0.1,0.0]"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("2 cells across its travel"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("under 8 cells across"), std::string::npos) << r.err;
}
