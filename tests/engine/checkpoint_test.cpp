// Run checkpoints: a run stopped after some steps and resumed must write exactly what the
// uninterrupted run writes (forces.csv byte for byte, run.json's forces and analysis, frames), for
// every contact method: each keeps different state across steps (particle contact warm-starts its
// impulses, cell_fraction keeps the nodes a point has touched).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/io/field_store.hpp"
#include "engine/run.hpp"
#include "engine/simulation.hpp"
#include "test_scenes.hpp"

using namespace furrow;
namespace fs = std::filesystem;

namespace {

// A file that is not there fails the test (two missing files must not compare equal).
std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) {
    ADD_FAILURE() << "cannot read " << p;
    return "<missing " + p.string() + ">";
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Two stored VDB frames hold the same fields, bit for bit (the files' bytes differ: each carries
// its own grid UUIDs).
void expect_same_frame(const std::string& a_path, const std::string& b_path) {
  ASSERT_TRUE(fs::exists(a_path)) << a_path;
  ASSERT_TRUE(fs::exists(b_path)) << b_path;
  const FieldFrame a = read_frame(a_path), b = read_frame(b_path);
  EXPECT_EQ(a.step, b.step) << b_path;
  EXPECT_EQ(a.time_s, b.time_s) << b_path;
  EXPECT_EQ(a.nx, b.nx) << b_path;
  EXPECT_EQ(a.ny, b.ny) << b_path;
  EXPECT_EQ(a.active, b.active) << b_path;
  EXPECT_EQ(a.scalars, b.scalars) << b_path;
  EXPECT_EQ(a.velocity_x, b.velocity_x) << b_path;
  EXPECT_EQ(a.velocity_y, b.velocity_y) << b_path;
  EXPECT_FALSE(a.velocity_x.empty()) << a_path << ": the scene stores velocity";
  EXPECT_EQ(a.scalars.count("packing_fraction"), 1u) << a_path;
  ASSERT_EQ(a.bodies.size(), b.bodies.size()) << b_path;
  for (size_t i = 0; i < a.bodies.size(); ++i) {
    EXPECT_EQ(a.bodies[i].outline_m, b.bodies[i].outline_m) << b_path;
    EXPECT_EQ(a.bodies[i].force_N_per_m, b.bodies[i].force_N_per_m) << b_path;
  }
}

// A DPM bed (dilatancy on: phi_d is state) with a plate pushed in at an angle, velocity frames (the
// wedge analysis keeps per-frame state) and a force interval that is not a multiple of dt (the
// force log carries a partial sum across the stop).
Scene checkpoint_scene(ContactMethod contact) {
  Material m = test_scenes::glass_beads(0.4);
  m.model = MaterialModel::DPM;
  m.chi = 5.0;
  m.phi_min = 0.45;
  Scene s = test_scenes::bed_scene(m, 0.1, 0.05, 0.02, 0.005, 1.0, 0.62);
  s.name = "checkpoint";
  s.effects.dilatancy = true;
  s.solver.contact = contact;
  s.bodies.push_back(test_scenes::plate(0.02, 0.01, 0.05, 0.051, Vec2(0.02, -0.1)));
  s.solver.end_displacement_m = 0.012;
  s.outputs.fields = {"velocity", "packing_fraction"};
  s.outputs.frame_interval_s = 0.02;
  s.outputs.force_interval_s = 0.00123;
  s.outputs.average_from_m = 0.004;
  return s;
}

struct Dirs {
  fs::path root;
  explicit Dirs(const std::string& name)
      : root(fs::temp_directory_path() / ("furrow_checkpoint_test_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(root);
    fs::create_directories(root);
  }
  ~Dirs() { fs::remove_all(root); }
};

RunOptions options(const fs::path& dir) {
  RunOptions o;
  o.out_dir = dir.string();
  return o;
}

}  // namespace

class Checkpoint : public ::testing::TestWithParam<ContactMethod> {};

TEST_P(Checkpoint, StoppedAndResumedRunWritesWhatTheUninterruptedRunWrites) {
  const Scene s = checkpoint_scene(GetParam());
  Dirs d(contact_method_name(GetParam()));
  const RunSummary whole = run_scene(s, options(d.root / "whole"));
  const int64_t steps = whole.run_json.at("steps").get<int64_t>();
  ASSERT_GT(steps, 100);

  // stop twice (a third and two thirds of the way), then finish; one thread, then two
  int64_t polled = 0;
  RunOptions o = options(d.root / "split");
  o.resume = true;
  o.stop_requested = [&] { return ++polled == steps / 3; };
  RunSummary part = run_scene(s, o);
  ASSERT_TRUE(part.stopped);
  EXPECT_EQ(part.resumed_from_step, -1);
  EXPECT_EQ(part.run_json.at("steps").get<int64_t>(), steps / 3);
  EXPECT_TRUE(fs::exists(fs::path(part.out_dir) / "checkpoint" / "simulation.bin"));
  EXPECT_FALSE(fs::exists(d.root / "split"));  // nothing in place until the run completes
  polled = 0;
  Scene two_threads = s;
  two_threads.solver.threads = 2;
  part = run_scene(two_threads, o);
  ASSERT_TRUE(part.stopped);
  EXPECT_EQ(part.resumed_from_step, steps / 3);
  o.stop_requested = nullptr;
  const RunSummary resumed = run_scene(s, o);
  ASSERT_FALSE(resumed.stopped);
  EXPECT_EQ(resumed.resumed_from_step, 2 * (steps / 3));

  const fs::path a = d.root / "whole", b = d.root / "split";
  EXPECT_EQ(read_bytes(a / "forces.csv"), read_bytes(b / "forces.csv"));
  const auto& ja = whole.run_json;
  const auto& jb = resumed.run_json;
  for (const char* key : {"steps", "end_time_s", "dt_min_s", "dt_max_s", "frames", "bodies", "analysis", "lead_body_travel_m"})
    EXPECT_EQ(ja.at(key), jb.at(key)) << key;
  if (ja.contains("contact")) {
    EXPECT_EQ(ja.at("contact"), jb.at("contact"));
  }
  EXPECT_EQ(jb.at("segments").get<int>(), 3);
  EXPECT_EQ(read_bytes(a / "frames.pvd"), read_bytes(b / "frames.pvd"));
  const int64_t frames = ja.at("frames").get<int64_t>();
  ASSERT_GE(frames, 3) << "frames before, between and after the stops";
  for (int64_t f = 0; f < frames; ++f) {
    EXPECT_EQ(read_bytes(frame_path(a.string(), f, "vti")), read_bytes(frame_path(b.string(), f, "vti"))) << f;
    expect_same_frame(frame_path(a.string(), f), frame_path(b.string(), f));
  }
  EXPECT_EQ(list_frames(b.string()).size(), size_t(frames));
  EXPECT_FALSE(fs::exists(b / "checkpoint"));  // a finished run keeps no checkpoint
}

INSTANTIATE_TEST_SUITE_P(Contact, Checkpoint,
                         ::testing::Values(ContactMethod::Node, ContactMethod::Particle, ContactMethod::CellFraction),
                         [](const auto& info) { return std::string(contact_method_name(info.param)); });

// A checkpoint is refused, with the file and the item named, when it is not of this scene or
// (unless asked for) was written by another build.
TEST(CheckpointErrors, OtherSceneAndDamagedFilesAreNamed) {
  Scene s = checkpoint_scene(ContactMethod::Node);
  s.solver.end_displacement_m = 0.003;
  Dirs d("errors");
  RunOptions o = options(d.root / "run");
  o.resume = true;
  int64_t polled = 0;
  o.stop_requested = [&] { return ++polled == 20; };
  const RunSummary part = run_scene(s, o);
  ASSERT_TRUE(part.stopped);
  o.stop_requested = nullptr;

  Scene other = s;
  other.bodies[0].friction = 0.2;
  try {
    run_scene(other, o);
    ADD_FAILURE() << "a checkpoint of another scene was resumed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("different scene"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(part.out_dir), std::string::npos) << e.what();
  }

  // a checkpoint another build wrote: refused unless asked for, and then run.json says so
  const fs::path state_json = fs::path(part.out_dir) / "checkpoint" / "run.json";
  nlohmann::json cj;
  {
    std::ifstream in(state_json);
    cj = nlohmann::json::parse(in);
  }
  EXPECT_EQ(cj.at("build").get<std::string>(), build_id());
  cj["build"] = "0.0.0-other";
  cj["builds"] = {"0.0.0-other"};
  std::ofstream(state_json) << cj.dump();
  try {
    run_scene(s, o);
    ADD_FAILURE() << "a checkpoint of another build was resumed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("0.0.0-other"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--resume-any-build"), std::string::npos) << e.what();
  }
  o.resume_any_build = true;
  const RunSummary across = run_scene(s, o);
  EXPECT_EQ(across.resumed_from_step, part.run_json.at("steps").get<int64_t>());
  EXPECT_EQ(across.run_json.at("resumed_across_builds"), nlohmann::json({"0.0.0-other", build_id()}));
  o.resume_any_build = false;
  o.force = true;
  const RunSummary fresh = run_scene(s, o);  // nothing left to resume: a new run, one build
  EXPECT_EQ(fresh.resumed_from_step, -1);
  EXPECT_FALSE(fresh.run_json.contains("resumed_across_builds"));

  // the simulation state of a scene with more particles
  Simulation sim(s);
  Scene bigger = s;
  bigger.domain.width_m = 0.12;
  bigger.beds[0].max_m.x() = 0.12;
  Simulation big(bigger);
  std::stringstream state;
  big.save_state(state);
  try {
    sim.load_state(state, "state.bin");
    ADD_FAILURE() << "a checkpoint of another bed loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("state.bin: particle count"), std::string::npos) << e.what();
  }
  // cut short
  std::stringstream full;
  sim.save_state(full);
  std::stringstream cut(full.str().substr(0, full.str().size() / 2));
  try {
    sim.load_state(cut, "cut.bin");
    ADD_FAILURE() << "a truncated checkpoint loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("file ends early"), std::string::npos) << e.what();
  }
}

// A version 2 checkpoint (written before P2G kept each point's strip: no strip ranges, no reorder
// counts) is still read; the points are sorted into strips again before the next step, so they
// scatter race-free and the run goes on with the same physics (the sums in another order: round-off).
TEST(Checkpoint, VersionTwoIsReadAndItsPointsSortedIntoStripsAgain) {
  const Scene s = checkpoint_scene(ContactMethod::Node);
  Simulation a(s);
  for (int k = 0; k < 100; ++k) a.step();  // 36 steps past the last scheduled reorder
  std::stringstream v2;
  a.save_state(v2, 2);

  Simulation b(s);
  b.load_state(v2, "v2.bin");
  EXPECT_FALSE(b.strips_hold());  // not sorted yet: the next step sorts first
  for (int k = 0; k < 50; ++k) {
    a.step();
    b.step();
  }
  EXPECT_TRUE(b.strips_hold());
  EXPECT_EQ(b.total_mass(), a.total_mass());
  EXPECT_EQ(b.time_s(), a.time_s());
  const Vec2 fa = a.bodies()[0].force_N_per_m, fb = b.bodies()[0].force_N_per_m;
  EXPECT_GT(fa.norm(), 1.0);
  EXPECT_LT((fb - fa).norm(), 1e-6 * fa.norm()) << "force " << fa.transpose() << " vs " << fb.transpose();
}

// A version 3 checkpoint (bodies without an angle, angular velocity or torque) is read into a
// body that does not turn, and a version 4 one (no strip rows: contact walks whole strips until
// the next reorder, as those builds did); the run goes on exactly as if it had not stopped. The
// uninterrupted run walks only the rows its points' y drift allows, so this also checks that walk
// misses no point in reach (a point missed changes the force's bits).
TEST(Checkpoint, VersionThreeAndFourAreReadAndTheRunGoesOnUnchanged) {
  const Scene s = checkpoint_scene(ContactMethod::CellFraction);
  for (uint32_t version : {3u, 4u}) {
    Simulation a(s);
    for (int k = 0; k < 100; ++k) a.step();
    std::stringstream old;
    a.save_state(old, version);
    Simulation b(s);
    b.load_state(old, "old.bin");
    for (int k = 0; k < 50; ++k) {
      a.step();
      b.step();
    }
    EXPECT_GT(a.bodies()[0].force_N_per_m.norm(), 1.0);
    EXPECT_EQ(b.bodies()[0].force_N_per_m, a.bodies()[0].force_N_per_m) << "version " << version;
    EXPECT_EQ(b.bodies()[0].position_m, a.bodies()[0].position_m) << "version " << version;
  }
}

// A blow-up made by hand: after step 30 one point's vy becomes NaN. The run stops at that step with
// a message naming step, field, point and position; the force rows written before it are kept in
// the partial directory and none of them is non-finite; no run directory appears.
TEST(NonFinite, RunStopsAtTheFirstBadStepAndKeepsWhatItWrote) {
  Scene s = checkpoint_scene(ContactMethod::Node);
  Dirs d("nonfinite");
  RunOptions o = options(d.root / "run");
  o.write_paraview = false;
  const size_t victim = 7;
  o.after_step = [&](Simulation& sim) {
    if (sim.step_count() == 30) sim.mutable_particles().vy[victim] = std::nan("");
  };
  std::string what;
  try {
    run_scene(s, o);
  } catch (const std::runtime_error& e) {
    what = e.what();
  }
  ASSERT_FALSE(what.empty()) << "the run went on past a NaN";
  EXPECT_NE(what.find("step 30 "), std::string::npos) << what;
  EXPECT_NE(what.find("vy of point 7 at ("), std::string::npos) << what;
  EXPECT_FALSE(fs::exists(d.root / "run"));
  const auto partial = fs::path(d.root / ("run.partial-" + std::to_string(::getpid())));
  ASSERT_TRUE(fs::exists(partial / "forces.csv"));
  std::ifstream in(partial / "forces.csv");
  std::string line;
  int rows = 0;
  std::getline(in, line);
  while (std::getline(in, line)) {
    ++rows;
    EXPECT_EQ(line.find("nan"), std::string::npos) << line;
  }
}
