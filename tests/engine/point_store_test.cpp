// Point files (engine/io/point_store): the material points of a frame survive OpenVDB's reordering by
// voxel, a run with outputs.points stores the solver's own particles, bad files are named in
// errors, and the scene key is checked like the other outputs keys.
#include "engine/io/point_store.hpp"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "engine/io/field_store.hpp"
#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"
#include "test_scenes.hpp"

namespace fs = std::filesystem;
using namespace furrow;

namespace {

class PointStore : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* t = ::testing::UnitTest::GetInstance()->current_test_info();
    dir = fs::temp_directory_path() / ("furrow_points_" + std::to_string(::getpid()) + "_" + t->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

// 300 points written in an order that runs against OpenVDB's voxel order (x falling, y jumping
// between rows), several per voxel, each value distinct.
PointFrame hand_made_frame() {
  PointFrame f;
  f.scene_name = "hand_made";
  f.step = 4242;
  f.time_s = 0.125;
  f.dt_s = 3.5e-5;
  f.dx_m = 0.01;
  BodyOutline b;
  b.name = "plate";
  b.outline_m = {{0.1, 0.2}, {0.2, 0.2}, {0.2, 0.22}, {0.1, 0.22}};
  b.position_m = {0.15, 0.21};
  b.force_N_per_m = {-1.5, 250.0};
  f.bodies = {b};
  const int n = 300;
  for (int k = 0; k < n; ++k) {
    f.x_m.push_back(0.5 - 0.0016 * k);
    f.y_m.push_back(0.0037 * ((k * 7) % 23));
    f.vx_m_s.push_back(0.01f * float(k) - 1.0f);
    f.vy_m_s.push_back(float(std::sin(k)));
    f.volume_m2.push_back(2.5e-5f * (1.0f + 0.001f * float(k)));
    f.pressure_Pa.push_back(1000.0f + 3.7f * float(k));
    f.packing_fraction.push_back(0.55f + 0.0002f * float(k));
    f.strain_rate_1_s.push_back(k % 3 ? 0.0f : 1e-3f * float(k));
    f.phi_d.push_back(0.6f - 0.0001f * float(k));
  }
  return f;  // plastic_strain left out: an optional array that is not stored
}

int32_t first_stored_id_out_of_order(const std::string& path) {
  openvdb::io::File file(path);
  file.open();
  auto grid = openvdb::GridBase::grid<openvdb::points::PointDataGrid>(file.readGrid("points"));
  file.close();
  int32_t expected = 0;
  for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
    openvdb::points::AttributeHandle<int32_t> id(leaf->constAttributeArray("id"));
    for (auto it = leaf->beginIndexAll(); it; ++it, ++expected)
      if (id.get(*it) != expected) return expected;
  }
  return -1;
}

Scene small_bed(double end_time_s) {
  Scene s = test_scenes::bed_scene(0.1, 0.05, 0.03, 0.01, end_time_s);
  s.outputs.frame_interval_s = 0.001;
  s.outputs.fields = {"pressure"};
  s.outputs.points = true;
  return s;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_F(PointStore, RoundTripReturnsEveryPointInOrder) {
  const PointFrame f = hand_made_frame();
  const std::string path = (dir / "points_00000.vdb").string();
  write_points_vdb(path, f);
  // the file really is in another order than the solver's, so read_points had to restore it
  openvdb::initialize();
  EXPECT_GE(first_stored_id_out_of_order(path), 0);

  const PointFrame r = read_points(path);
  EXPECT_EQ(r.scene_name, f.scene_name);
  EXPECT_EQ(r.step, f.step);
  EXPECT_EQ(r.time_s, f.time_s);
  EXPECT_EQ(r.dt_s, f.dt_s);
  EXPECT_EQ(r.dx_m, f.dx_m);
  ASSERT_EQ(r.bodies.size(), 1u);
  EXPECT_EQ(r.bodies[0].name, "plate");
  EXPECT_EQ(r.bodies[0].outline_m, f.bodies[0].outline_m);
  EXPECT_EQ(r.bodies[0].force_N_per_m, f.bodies[0].force_N_per_m);
  ASSERT_EQ(r.size(), f.size());
  for (size_t i = 0; i < f.size(); ++i) {
    // P is a float offset within its voxel: float precision relative to dx
    ASSERT_NEAR(r.x_m[i], f.x_m[i], 1e-7 * f.dx_m) << i;
    ASSERT_NEAR(r.y_m[i], f.y_m[i], 1e-7 * f.dx_m) << i;
  }
  EXPECT_EQ(r.vx_m_s, f.vx_m_s);
  EXPECT_EQ(r.vy_m_s, f.vy_m_s);
  EXPECT_EQ(r.volume_m2, f.volume_m2);
  EXPECT_EQ(r.pressure_Pa, f.pressure_Pa);
  EXPECT_EQ(r.packing_fraction, f.packing_fraction);
  EXPECT_EQ(r.strain_rate_1_s, f.strain_rate_1_s);
  EXPECT_EQ(r.phi_d, f.phi_d);
  EXPECT_TRUE(r.plastic_strain.empty());
}

TEST_F(PointStore, FileCarriesTheFrameMetadataAndUnits) {
  const PointFrame f = hand_made_frame();
  const std::string path = (dir / "p.vdb").string();
  write_points_vdb(path, f);
  openvdb::initialize();
  openvdb::io::File file(path);
  file.open();
  const auto meta = file.getMetadata();
  auto grid = openvdb::GridBase::grid<openvdb::points::PointDataGrid>(file.readGrid("points"));
  file.close();
  EXPECT_EQ(meta->metaValue<std::string>("scene"), "hand_made");
  EXPECT_EQ(meta->metaValue<int64_t>("point_count"), 300);
  EXPECT_EQ(meta->metaValue<int32_t>("dimension"), 2);
  EXPECT_EQ(meta->metaValue<std::string>("furrow_version"), FURROW_VERSION);
  EXPECT_NE(meta->metaValue<std::string>("bodies_json").find("plate"), std::string::npos);
  ASSERT_TRUE(grid);
  EXPECT_DOUBLE_EQ(grid->voxelSize().x(), 0.01);
  EXPECT_EQ(grid->metaValue<std::string>("unit_pressure"), "Pa");
  EXPECT_EQ(grid->metaValue<std::string>("unit_v"), "m/s");
  // pscale, the disc radius, for renderers that size points by it
  auto leaf = grid->tree().cbeginLeaf();
  ASSERT_TRUE(leaf);
  openvdb::points::AttributeHandle<float> pscale(leaf->constAttributeArray("pscale")),
      volume(leaf->constAttributeArray("volume"));
  openvdb::points::AttributeHandle<openvdb::Vec3f> v(leaf->constAttributeArray("v"));
  EXPECT_NEAR(pscale.get(0), std::sqrt(volume.get(0) / M_PI), 1e-7);
  EXPECT_EQ(v.get(0).z(), 0.0f);
}

TEST_F(PointStore, EmptyFrameRoundTrips) {
  PointFrame f;
  f.scene_name = "empty";
  f.dx_m = 0.005;
  const std::string path = (dir / "empty.vdb").string();
  write_points_vdb(path, f);
  const PointFrame r = read_points(path);
  EXPECT_EQ(r.size(), 0u);
  EXPECT_EQ(r.scene_name, "empty");
}

TEST_F(PointStore, InconsistentFramesAreRefused) {
  PointFrame f = hand_made_frame();
  f.pressure_Pa.pop_back();
  EXPECT_NE(error_of([&] { write_points_vdb((dir / "a.vdb").string(), f); }).find("pressure"), std::string::npos);
  f = hand_made_frame();
  f.dx_m = 0.0;
  EXPECT_THROW(write_points_vdb((dir / "b.vdb").string(), f), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "a.vdb"));
}

// A run with outputs.points: one points file per frame, and each holds the solver's particles at
// that frame's step (runs are deterministic, so a second Simulation stepped as far is the same).
TEST_F(PointStore, RunStoresTheSolversParticles) {
  const Scene scene = small_bed(0.004);
  RunOptions opt;
  opt.out_dir = (dir / "run").string();
  opt.write_paraview = false;
  const RunSummary summary = run_scene(scene, opt);
  const int64_t frames = summary.run_json.at("frames").get<int64_t>();
  ASSERT_GE(frames, 3);
  for (int64_t k = 0; k < frames; ++k) {
    EXPECT_TRUE(fs::exists(frame_path(opt.out_dir, k))) << k;
    EXPECT_TRUE(fs::exists(points_path(opt.out_dir, k))) << k;
  }
  EXPECT_FALSE(fs::exists(points_path(opt.out_dir, frames)));
  EXPECT_EQ(list_frames(opt.out_dir).size(), size_t(frames));  // points files are not frames

  const PointFrame r = read_points(points_path(opt.out_dir, frames - 1));
  EXPECT_EQ(r.scene_name, scene.name);
  EXPECT_EQ(r.dx_m, scene.domain.dx_m);
  Simulation sim(scene);
  while (sim.step_count() < r.step) sim.step();
  EXPECT_EQ(sim.time_s(), r.time_s);
  const ParticleView p = sim.particle_view();
  ASSERT_EQ(r.size(), p.count);
  ASSERT_FALSE(r.strain_rate_1_s.empty());  // points ask the solver to keep them
  ASSERT_FALSE(r.plastic_strain.empty());
  EXPECT_TRUE(r.phi_d.empty());             // NDPM
  const double dx = scene.domain.dx_m;
  double max_v = 0.0;
  for (size_t i = 0; i < p.count; ++i) {
    ASSERT_NEAR(r.x_m[i], p.x_m[i], 1e-7 * dx) << i;
    ASSERT_NEAR(r.y_m[i], p.y_m[i], 1e-7 * dx) << i;
    ASSERT_EQ(r.pressure_Pa[i], float(p.pressure_Pa[i])) << i;
    ASSERT_EQ(r.vx_m_s[i], float(p.vx_m_s[i])) << i;
    ASSERT_EQ(r.vy_m_s[i], float(p.vy_m_s[i])) << i;
    ASSERT_EQ(r.volume_m2[i], float(p.volume_m2[i])) << i;
    ASSERT_EQ(r.strain_rate_1_s[i], float(p.strain_rate_1_s[i])) << i;
    ASSERT_EQ(r.plastic_strain[i], float(p.plastic_strain[i])) << i;
    ASSERT_NEAR(r.packing_fraction[i], p.mass_kg[i] / (p.grain_density_kg_m3[i] * p.volume_m2[i]), 1e-6) << i;
    max_v = std::max(max_v, std::abs(p.vy_m_s[i]));
  }
  EXPECT_GT(max_v, 0.0);  // the bed has moved: the comparison is not between two initial states
}

TEST_F(PointStore, DpmRunsStorePhiD) {
  Material m = test_scenes::glass_beads();
  m.model = MaterialModel::DPM;
  m.chi = 2.5;
  m.phi_min = 0.45;
  Scene scene = test_scenes::bed_scene(m, 0.1, 0.05, 0.03, 0.01, 0.01, 0.62);
  scene.effects.dilatancy = true;
  Simulation sim(scene);
  for (int s = 0; s < 5; ++s) sim.step();
  PointFrameInfo info;
  info.scene_name = scene.name;
  info.step = sim.step_count();
  info.dx_m = scene.domain.dx_m;
  const std::string path = (dir / "dpm.vdb").string();
  const ParticleView p = sim.particle_view();
  write_points_vdb(path, info, p);
  const PointFrame r = read_points(path);
  ASSERT_EQ(r.size(), p.count);
  ASSERT_EQ(r.phi_d.size(), p.count);
  for (size_t i = 0; i < p.count; ++i) {
    ASSERT_NEAR(r.y_m[i], p.y_m[i], 1e-7 * info.dx_m) << i;
    ASSERT_EQ(r.phi_d[i], float(p.phi_d[i])) << i;
  }
  EXPECT_TRUE(r.strain_rate_1_s.empty());  // not tracked: the scene stores neither fields nor points
}

TEST_F(PointStore, ErrorsNameTheFile) {
  const std::string missing = (dir / "nope" / "points_00003.vdb").string();
  std::string msg = error_of([&] { read_points(missing); });
  EXPECT_NE(msg.find(missing), std::string::npos) << msg;
  EXPECT_NE(msg.find("no such file"), std::string::npos) << msg;

  // a field frame is an OpenVDB file, but holds no points
  FieldFrame ff;
  ff.nx = 2, ff.ny = 2, ff.dx_m = 0.01;
  ff.active = {1, 1, 0, 1};
  ff.scalars["pressure"] = {1, 2, 0, 4};
  const std::string frame = frame_path(dir.string(), 0);
  write_frame_vdb(frame, ff);
  msg = error_of([&] { read_points(frame); });
  EXPECT_NE(msg.find(frame), std::string::npos) << msg;
  EXPECT_NE(msg.find("'points'"), std::string::npos) << msg;

  const std::string text = (dir / "text.vdb").string();
  std::ofstream(text) << "not a vdb";
  msg = error_of([&] { read_points(text); });
  EXPECT_NE(msg.find(text), std::string::npos) << msg;
  EXPECT_NE(msg.find("OpenVDB"), std::string::npos) << msg;
}

TEST(PointStoreScene, KeyIsCheckedNamedAndRoundTrips) {
  const SceneTemplate* t = find_scene_template("hydrostatic_bed");
  ASSERT_NE(t, nullptr);
  const std::string src = "<template hydrostatic_bed>";
  auto rejects = [&](const std::vector<std::string>& overrides, const std::string& word) {
    SCOPED_TRACE(overrides.back());
    try {
      parse_scene_text(t->text, src, overrides);
      ADD_FAILURE() << "accepted";
    } catch (const SceneError& e) {
      EXPECT_EQ(e.path, "/outputs/points") << e.what();
      EXPECT_NE(std::string(e.what()).find("/outputs/points: got "), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
  };
  rejects({"outputs.points=1"}, "true or false");
  rejects({"outputs.points=\"yes\""}, "true or false");
  rejects({"outputs.fields=[]", "outputs.movies=[]", "outputs.points=true"}, "no frames");
  rejects({"outputs.frame_interval_s=0", "outputs.fields=[]", "outputs.movies=[]", "outputs.points=true"},
          "no frames");

  EXPECT_FALSE(parse_scene_text(t->text, src).outputs.points);
  const Scene s = parse_scene_text(t->text, src, {"outputs.points=true"});
  EXPECT_TRUE(s.outputs.points);
  EXPECT_EQ(scene_to_json(s)["outputs"]["points"], true);
  EXPECT_TRUE(parse_scene_text(format_scene(s), "again").outputs.points);
  EXPECT_EQ(scene_to_json(parse_scene_text(t->text, src))["outputs"]["points"], false);  // resolved: written out

  // points are a result of the run; a scene without them keeps the hash it had before the key
  const Scene plain = parse_scene_text(t->text, src);
  EXPECT_FALSE(result_defining_json(plain)["outputs"].contains("points"));
  EXPECT_NE(scene_hash(plain), scene_hash(s));
}
