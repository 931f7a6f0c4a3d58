// Whether a run directory holds a finished run of a scene: what sweep and study reuse.
#include "app/run_dirs.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"
#include "tests/app/sweep_fixture.hpp"

namespace fs = std::filesystem;
using namespace furrow;

namespace {

Scene tiny(const std::vector<std::string>& sets = {}) { return parse_scene_text(cli_test::kTinyScene, "tiny", sets); }

class RunDirs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("furrow_run_dirs_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // a finished run's directory as run_scene leaves it, minus the outputs these checks do not read
  fs::path finished(const Scene& s, const nlohmann::json& run_json) {
    fs::create_directories(dir_ / "run");
    std::ofstream(dir_ / "run" / "scene.json") << format_scene(s);
    std::ofstream(dir_ / "run" / "run.json") << run_json.dump();
    return dir_ / "run";
  }
  fs::path dir_;
};

}  // namespace

TEST(SceneHash, IgnoresThreadsAndMoviesOnlyAndIsStable) {
  const Scene a = tiny(), b = tiny({"solver.threads=7"}), c = tiny({"domain.dx_m=0.004"});
  EXPECT_EQ(scene_hash(a), scene_hash(b));
  EXPECT_NE(scene_hash(a), scene_hash(c));
  // movies are drawn from the frames; the frames' fields are results
  const std::vector<std::string> frames = {"outputs.frame_interval_s=0.05", R"(outputs.fields=["pressure"])"};
  std::vector<std::string> with_movie = frames;
  with_movie.push_back(R"(outputs.movies=["pressure"])");
  std::vector<std::string> more_fields = frames;
  more_fields.back() = R"(outputs.fields=["pressure","strain_rate"])";
  EXPECT_EQ(scene_hash(tiny(frames)), scene_hash(tiny(with_movie)));
  EXPECT_NE(scene_hash(tiny(frames)), scene_hash(tiny(more_fields)));
  EXPECT_EQ(scene_hash(a).size(), 16u);
  EXPECT_EQ(scene_hash(a).find_first_not_of("0123456789abcdef"), std::string::npos);
  // the written scene, read back, is the same scene
  EXPECT_EQ(scene_hash(parse_scene_text(format_scene(c), "again")), scene_hash(c));
}

TEST_F(RunDirs, TheHashOrTheStoredSceneDecides) {
  const Scene s = tiny();
  EXPECT_EQ(cli::match_run_dir(dir_ / "run", s).state, cli::RunDirState::absent);
  fs::create_directories(dir_ / "run");
  EXPECT_EQ(cli::match_run_dir(dir_ / "run", s).state, cli::RunDirState::incomplete);

  finished(s, {{"scene_hash", scene_hash(s)}});
  EXPECT_EQ(cli::match_run_dir(dir_ / "run", tiny({"solver.threads=3"})).state, cli::RunDirState::same_scene);
  // a run without the hash (written before it existed) is compared key by key
  finished(s, nlohmann::json::object());
  EXPECT_EQ(cli::match_run_dir(dir_ / "run", s).state, cli::RunDirState::same_scene);

  const auto other = cli::match_run_dir(dir_ / "run", tiny({"domain.dx_m=0.004", "bodies.rod.friction=0.1"}));
  EXPECT_EQ(other.state, cli::RunDirState::other_scene);
  EXPECT_NE(other.why.find("/domain/dx_m"), std::string::npos) << other.why;
  EXPECT_NE(other.why.find("/bodies/1/friction"), std::string::npos) << other.why;
}
