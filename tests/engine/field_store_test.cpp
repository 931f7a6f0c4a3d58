#include "engine/io/field_store.hpp"

#include "engine/io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

namespace fs = std::filesystem;
using namespace furrow;

namespace {

class FieldStore : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* t = ::testing::UnitTest::GetInstance()->current_test_info();
    dir = fs::temp_directory_path() / ("furrow_store_" + std::to_string(::getpid()) + "_" + t->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A 5x4 frame at dx = 1 cm with a hole: cells with j == 3 and cell (0, 0) hold no material.
FieldFrame small_frame() {
  FieldFrame f;
  f.scene_name = "round \"trip\"";
  f.step = 1234;
  f.time_s = 0.125;
  f.dt_s = 2.5e-5;
  f.dx_m = 0.01;
  f.origin_m = {-0.02, 0.1};
  f.nx = 5;
  f.ny = 4;
  const size_t n = 20;
  f.active.assign(n, 0);
  auto& p = f.scalars["pressure"];
  auto& phi = f.scalars["packing_fraction"];
  p.assign(n, 0.0f);
  phi.assign(n, 0.0f);
  f.velocity_x.assign(n, 0.0f);
  f.velocity_y.assign(n, 0.0f);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 5; ++i) {
      if (i == 0 && j == 0) continue;
      const size_t c = f.index(i, j);
      f.active[c] = 1;
      p[c] = 100.0f * float(i) + 1000.0f * float(j);
      phi[c] = 0.55f + 0.01f * float(i);
      f.velocity_x[c] = 0.1f * float(i) - 0.2f;
      f.velocity_y[c] = -0.05f * float(j);
    }
  f.scalars["pressure"][f.index(1, 0)] = 0.0f;  // active cell holding exactly zero stays active
  BodyOutline b;
  b.name = "plate";
  b.position_m = {0.01, 0.13};
  b.force_N_per_m = {-12.5, 40.25};
  b.outline_m = {{0.0, 0.12}, {0.02, 0.12}, {0.02, 0.14}, {0.0, 0.14}};
  f.bodies = {b};
  return f;
}

// Minimal XML well-formedness: tags balance and nest, one root element. Returns the root name.
std::string xml_root(const std::string& xml) {
  std::vector<std::string> stack;
  std::string root;
  size_t pos = 0;
  while ((pos = xml.find('<', pos)) != std::string::npos) {
    const size_t end = xml.find('>', pos);
    if (end == std::string::npos) throw std::runtime_error("unterminated tag");
    std::string tag = xml.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    if (tag.empty() || tag[0] == '?') continue;
    if (tag[0] == '/') {
      if (stack.empty() || stack.back() != tag.substr(1)) throw std::runtime_error("mismatched </" + tag + ">");
      stack.pop_back();
      continue;
    }
    const bool self_closing = tag.back() == '/';
    const std::string name = tag.substr(0, tag.find_first_of(" \t\n/"));
    if (stack.empty()) {
      if (!root.empty()) throw std::runtime_error("second root element " + name);
      root = name;
    }
    if (!self_closing) stack.push_back(name);
  }
  if (!stack.empty()) throw std::runtime_error("unclosed <" + stack.back() + ">");
  return root;
}

std::string attribute(const std::string& xml, const std::string& element, const std::string& name) {
  const size_t e = xml.find("<" + element);
  if (e == std::string::npos) return "";
  const size_t a = xml.find(" " + name + "=\"", e);
  if (a == std::string::npos || a > xml.find('>', e)) return "";
  const size_t v = a + name.size() + 3;
  return xml.substr(v, xml.find('"', v) - v);
}

size_t count_of(const std::string& s, const std::string& what) {
  size_t n = 0;
  for (size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

std::vector<unsigned char> base64_decode(const std::string& s) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::vector<unsigned char> out;
  uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    const int v = val(c);
    if (v < 0) continue;  // '=' padding
    acc = acc << 6 | uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(uint8_t(acc >> bits));
    }
  }
  return out;
}

// Decoded payload (after the UInt32 byte count) of the DataArray called `name`.
std::vector<unsigned char> vti_array(const std::string& xml, const std::string& name) {
  const size_t a = xml.find("Name=\"" + name + "\"");
  if (a == std::string::npos) return {};
  const size_t b = xml.find('>', a) + 1;
  auto bytes = base64_decode(xml.substr(b, xml.find('<', b) - b));
  uint32_t n = 0;
  std::memcpy(&n, bytes.data(), 4);
  EXPECT_EQ(size_t(n) + 4, bytes.size()) << name;
  return {bytes.begin() + 4, bytes.end()};
}

// ---------------------------------------------------------------------------------------------
// OpenVDB frames

TEST_F(FieldStore, VdbRoundTripKeepsValuesMetadataAndLayout) {
  const FieldFrame f = small_frame();
  const std::string path = frame_path(dir.string(), 42);
  EXPECT_EQ(fs::path(path), dir / "frames" / "frame_00042.vdb");
  write_frame_vdb(path, f);
  write_frame_vdb(path, f);  // replacing a frame leaves no temporary file behind
  ASSERT_EQ(std::distance(fs::directory_iterator(dir / "frames"), fs::directory_iterator()), 1);
  ASSERT_TRUE(fs::exists(path));

  const FieldFrame r = read_frame(path);
  EXPECT_EQ(r.scene_name, f.scene_name);
  EXPECT_EQ(r.step, 1234);
  EXPECT_EQ(r.time_s, 0.125);
  EXPECT_EQ(r.dt_s, 2.5e-5);
  EXPECT_EQ(r.dx_m, 0.01);
  EXPECT_EQ(r.origin_m, f.origin_m);
  EXPECT_EQ(r.nx, 5);
  EXPECT_EQ(r.ny, 4);
  EXPECT_EQ(r.active, f.active);
  ASSERT_EQ(r.scalars.size(), 2u);  // the `density` alias is not read back as bulk density
  EXPECT_EQ(r.scalars.at("pressure"), f.scalars.at("pressure"));
  EXPECT_EQ(r.scalars.at("packing_fraction"), f.scalars.at("packing_fraction"));
  EXPECT_EQ(r.velocity_x, f.velocity_x);
  EXPECT_EQ(r.velocity_y, f.velocity_y);
  ASSERT_EQ(r.bodies.size(), 1u);
  EXPECT_EQ(r.bodies[0].name, "plate");
  EXPECT_EQ(r.bodies[0].position_m, f.bodies[0].position_m);
  EXPECT_EQ(r.bodies[0].force_N_per_m, f.bodies[0].force_N_per_m);
  EXPECT_EQ(r.bodies[0].outline_m, f.bodies[0].outline_m);
}

TEST_F(FieldStore, VdbFileHasNamedGridsUnitsTransformAndSparseActiveSet) {
  const FieldFrame f = small_frame();
  const std::string path = (dir / "f.vdb").string();
  write_frame_vdb(path, f);

  openvdb::initialize();
  openvdb::io::File file(path);
  file.open(false);
  auto meta = file.getMetadata();
  EXPECT_EQ(meta->metaValue<double>("time_s"), 0.125);
  EXPECT_EQ(meta->metaValue<int64_t>("step"), 1234);
  EXPECT_EQ(meta->metaValue<double>("dt_s"), 2.5e-5);
  EXPECT_EQ(meta->metaValue<double>("dx_m"), 0.01);
  EXPECT_EQ(meta->metaValue<int32_t>("dimension"), 2);
  EXPECT_EQ(meta->metaValue<std::string>("scene"), f.scene_name);
  EXPECT_NE(meta->metaValue<std::string>("bodies_json").find("\"plate\""), std::string::npos);
  auto grids = file.getGrids();
  file.close();

  std::map<std::string, openvdb::GridBase::Ptr> by_name;
  for (const auto& g : *grids) by_name[g->getName()] = g;
  ASSERT_EQ(grids->size(), 4u);
  ASSERT_EQ(by_name.size(), 4u);
  for (const char* name : {"velocity", "pressure", "packing_fraction", "density"}) EXPECT_EQ(by_name.count(name), 1u) << name;

  for (const auto& g : *grids) {
    SCOPED_TRACE(g->getName());
    const std::string expected_unit = g->getName() == "velocity" ? "m/s" : g->getName() == "pressure" ? "Pa" : "-";
    EXPECT_EQ(g->metaValue<std::string>("unit"), expected_unit);
    EXPECT_EQ(bool(g->getMetadata<openvdb::StringMetadata>("copy_of")), g->getName() == "density");
    EXPECT_NEAR(g->voxelSize().x(), 0.01, 1e-15);
    EXPECT_NEAR(g->voxelSize().z(), 0.01, 1e-15);
    EXPECT_EQ(g->activeVoxelCount(), 14u);  // 15 cells in rows 0..2 minus the empty (0, 0)
    // voxel (i, j, 0) centre at origin + (i + 1/2, j + 1/2) dx, z = 0
    const openvdb::Vec3d w = g->indexToWorld(openvdb::Coord(3, 2, 0));
    EXPECT_NEAR(w.x(), -0.02 + 3.5 * 0.01, 1e-12);
    EXPECT_NEAR(w.y(), 0.1 + 2.5 * 0.01, 1e-12);
    EXPECT_NEAR(w.z(), 0.0, 1e-15);
    // the alias shares packing_fraction's tree and is stored as an instance of it
    if (openvdb::io::Archive::hasBloscCompression() && g->getName() != "density") {
      EXPECT_NE(g->metaValue<std::string>("file_compression").find("blosc"), std::string::npos);
    }
  }

  auto pressure = openvdb::gridPtrCast<openvdb::FloatGrid>(by_name["pressure"]);
  auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(by_name["density"]);
  auto velocity = openvdb::gridPtrCast<openvdb::Vec3SGrid>(by_name["velocity"]);
  ASSERT_TRUE(pressure && density && velocity);
  auto pa = pressure->getConstAccessor();
  EXPECT_FALSE(pa.isValueOn(openvdb::Coord(0, 0, 0)));  // no material
  EXPECT_FALSE(pa.isValueOn(openvdb::Coord(2, 3, 0)));
  EXPECT_FALSE(pa.isValueOn(openvdb::Coord(2, 1, 1)));  // slab is one voxel thick
  EXPECT_EQ(pa.getValue(openvdb::Coord(0, 0, 0)), 0.0f);
  EXPECT_TRUE(pa.isValueOn(openvdb::Coord(1, 0, 0)));  // active although its pressure is 0
  EXPECT_EQ(pa.getValue(openvdb::Coord(1, 0, 0)), 0.0f);
  EXPECT_EQ(pa.getValue(openvdb::Coord(4, 2, 0)), 2400.0f);
  EXPECT_EQ(density->tree().getValue(openvdb::Coord(3, 1, 0)), 0.58f);  // packing fraction copy
  const openvdb::Vec3s v = velocity->tree().getValue(openvdb::Coord(4, 2, 0));
  EXPECT_EQ(v, openvdb::Vec3s(0.1f * 4 - 0.2f, -0.1f, 0.0f));
}

TEST_F(FieldStore, BulkDensityIsNotShadowedByThePackingAlias) {
  FieldFrame f = small_frame();
  f.scalars["density"] = std::vector<float>(20, 1500.0f);
  const std::string path = (dir / "f.vdb").string();
  write_frame_vdb(path, f);
  const FieldFrame r = read_frame(path);
  ASSERT_EQ(r.scalars.count("density"), 1u);
  EXPECT_EQ(r.scalars.at("density")[f.index(2, 2)], 1500.0f);
  EXPECT_EQ(r.scalars.at("density")[f.index(2, 3)], 0.0f);  // inactive cell
}

TEST_F(FieldStore, WriteRejectsInconsistentFrames) {
  FieldFrame f = small_frame();
  f.scalars["pressure"].pop_back();
  EXPECT_THROW(write_frame_vdb((dir / "a.vdb").string(), f), std::invalid_argument);
  f = small_frame();
  f.scalars["temperature"] = std::vector<float>(20, 1.0f);
  EXPECT_THROW(write_frame_vdb((dir / "b.vdb").string(), f), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "a.vdb"));
  EXPECT_FALSE(fs::exists(dir / "b.vdb"));
}

TEST_F(FieldStore, ReadErrorsNameTheFile) {
  auto message = [](const std::string& path) {
    try {
      read_frame(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  const std::string missing = (dir / "missing.vdb").string();
  EXPECT_NE(message(missing).find(missing), std::string::npos);

  const std::string garbage = (dir / "garbage.vdb").string();
  std::ofstream(garbage) << "this is not a VDB file";
  EXPECT_NE(message(garbage).find(garbage), std::string::npos) << message(garbage);

  // a valid VDB that is not a Furrow frame: the missing key is named
  openvdb::initialize();
  const std::string foreign = (dir / "foreign.vdb").string();
  openvdb::io::File((foreign)).write({openvdb::FloatGrid::create()});
  const std::string m = message(foreign);
  EXPECT_NE(m.find(foreign), std::string::npos) << m;
  EXPECT_NE(m.find("'scene'"), std::string::npos) << m;
}

TEST_F(FieldStore, ListFramesSortsByNumberAndIgnoresOtherFiles) {
  for (int64_t k : {10, 2, 100000, 7}) write_file_atomic(frame_path(dir.string(), k), "x");
  write_file_atomic((dir / "frames" / ".frame_00003.vdb.tmp1_0").string(), "x");
  write_file_atomic(frame_path(dir.string(), 2, "vti"), "x");
  write_file_atomic((dir / "frames" / "frame_x1.vdb").string(), "x");
  const auto frames = list_frames(dir.string());
  std::vector<std::string> names;
  for (const auto& p : frames) names.push_back(fs::path(p).filename().string());
  EXPECT_EQ(names, (std::vector<std::string>{"frame_00002.vdb", "frame_00007.vdb", "frame_00010.vdb",
                                             "frame_100000.vdb"}));
  EXPECT_THROW(list_frames((dir / "nope").string()), std::runtime_error);
}

// ---------------------------------------------------------------------------------------------
// Rasterization

constexpr double kGrainDensity = 2500.0;  // kg/m^3
constexpr double kPhi = 0.6;

// Particles 2x2 per cell filling cells [i0, i1) x [0, jtop) of a grid of spacing dx, each of area
// dx^2/4 and packing kPhi, optionally jittered inside its quarter cell.
struct Bed {
  std::vector<double> x, y, m, V, rho_g, vx, vy, p;
  ParticleView view() const {
    ParticleView v;
    v.count = x.size();
    v.x_m = x.data();
    v.y_m = y.data();
    v.mass_kg = m.data();
    v.volume_m2 = V.data();
    v.grain_density_kg_m3 = rho_g.data();
    v.vx_m_s = vx.data();
    v.vy_m_s = vy.data();
    v.pressure_Pa = p.data();
    return v;
  }
};
Bed make_bed(double dx, int i0, int i1, int jtop, double jitter, double g = 9.81) {
  Bed b;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  const double V = dx * dx / 4, height = jtop * dx;
  for (int j = 0; j < 2 * jtop; ++j)
    for (int i = 2 * i0; i < 2 * i1; ++i) {
      b.x.push_back((i + 0.5 + u(rng)) * dx / 2);
      b.y.push_back((j + 0.5 + u(rng)) * dx / 2);
      b.V.push_back(V);
      b.rho_g.push_back(kGrainDensity);
      b.m.push_back(kGrainDensity * kPhi * V);
      b.vx.push_back(0.0);
      b.vy.push_back(0.0);
      b.p.push_back(kGrainDensity * kPhi * g * (height - b.y.back()));  // hydrostatic
    }
  return b;
}

TEST(Rasterize, UniformBedHasItsPackingFractionAndBulkDensity) {
  const double dx = 0.01;
  const Bed bed = make_bed(dx, 2, 18, 7, 0.0);
  const FieldFrame f = rasterize(bed.view(), {20, 10, dx, {0.0, 0.0}}, {"packing_fraction", "density"});
  EXPECT_EQ(f.nx, 20);
  EXPECT_EQ(f.ny, 10);
  EXPECT_TRUE(f.velocity_x.empty());
  EXPECT_EQ(f.scalars.size(), 2u);
  int active = 0;
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 20; ++i) {
      const size_t c = f.index(i, j);
      const bool inside = i >= 2 && i < 18 && j < 7;
      ASSERT_EQ(f.active[c], inside ? 1 : 0) << i << "," << j;
      active += f.active[c];
      if (!inside) {
        EXPECT_EQ(f.scalars.at("packing_fraction")[c], 0.0f);
        continue;
      }
      EXPECT_NEAR(f.scalars.at("packing_fraction")[c], kPhi, 0.01);
      EXPECT_NEAR(f.scalars.at("density")[c], kPhi * kGrainDensity, 1e-3 * kPhi * kGrainDensity);
    }
  EXPECT_EQ(active, 16 * 7);
}

TEST(Rasterize, HydrostaticPressureIsLinearInDepthWithSlopeRhoG) {
  const double dx = 0.005, g = 9.81;
  const int jtop = 30;
  const Bed bed = make_bed(dx, 0, 40, jtop, 0.45, g);  // positions jittered within quarter cells
  const FieldFrame f = rasterize(bed.view(), {40, 40, dx, {0.0, 0.0}}, {"pressure"});
  // least-squares line p = a + b * depth over every active cell (depth of the cell centre)
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (int j = 0; j < f.ny; ++j)
    for (int i = 0; i < f.nx; ++i) {
      const size_t c = f.index(i, j);
      EXPECT_EQ(f.active[c], j < jtop ? 1 : 0);
      if (!f.active[c]) continue;
      const double depth = jtop * dx - (j + 0.5) * dx, p = f.scalars.at("pressure")[c];
      sx += depth, sy += p, sxx += depth * depth, sxy += depth * p, ++n;
    }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  const double rho_g = kPhi * kGrainDensity * g;
  EXPECT_NEAR(slope, rho_g, 0.02 * rho_g);
  const double intercept = (sy - slope * sx) / n;
  EXPECT_NEAR(intercept, 0.0, rho_g * dx / 4);  // zero pressure at the free surface
}

TEST(Rasterize, AveragesAreMassWeighted) {
  // (the per-cell transfer: each cell its own points; the B-spline one is display_fields_test's)
  // two particles in cell (1, 0) of a 3x1 grid with dx = 0.1, plus particles outside / invalid
  const double nan = std::nan("");
  std::vector<double> x = {0.12, 0.18, -0.05, 0.31, nan}, y = {0.05, 0.02, 0.05, 0.05, 0.05};
  std::vector<double> m = {1.0, 3.0, 5.0, 5.0, 5.0}, V = {0.001, 0.003, 1, 1, 1};
  std::vector<double> rho = {2000, 1000, 1, 1, 1}, vx = {1.0, -1.0, 9, 9, 9}, vy = {2.0, 0.0, 9, 9, 9};
  std::vector<double> sr = {10.0, 2.0, 9, 9, 9};
  ParticleView p;
  p.count = x.size();
  p.x_m = x.data(), p.y_m = y.data(), p.mass_kg = m.data(), p.volume_m2 = V.data();
  p.grain_density_kg_m3 = rho.data(), p.vx_m_s = vx.data(), p.vy_m_s = vy.data();
  p.strain_rate_1_s = sr.data();
  const FieldFrame f =
      rasterize(p, {3, 1, 0.1, {0.0, 0.0}, RasterTransfer::cell_average},
                {"velocity", "strain_rate", "packing_fraction", "density"});
  EXPECT_EQ(f.active, (std::vector<uint8_t>{0, 1, 0}));
  EXPECT_NEAR(f.velocity_x[1], (1.0 * 1 - 3.0 * 1) / 4, 1e-6);
  EXPECT_NEAR(f.velocity_y[1], (1.0 * 2) / 4, 1e-6);
  EXPECT_NEAR(f.scalars.at("strain_rate")[1], (10.0 + 3 * 2.0) / 4, 1e-6);
  EXPECT_NEAR(f.scalars.at("packing_fraction")[1], 4.0 / (2000 * 0.001 + 1000 * 0.003), 1e-6);
  EXPECT_NEAR(f.scalars.at("density")[1], 4.0 / 0.004, 1e-3);
  EXPECT_EQ(f.velocity_x[0], 0.0f);
}

TEST(Rasterize, RejectsUnknownOrUnavailableFields) {
  const Bed bed = make_bed(0.01, 0, 2, 2, 0.0);
  const RasterSpec spec{4, 4, 0.01, {0.0, 0.0}};
  EXPECT_THROW(rasterize(bed.view(), spec, {"temperature"}), std::invalid_argument);
  EXPECT_THROW(rasterize(bed.view(), spec, {"phi_d"}), std::invalid_argument);  // no DPM state
  EXPECT_THROW(rasterize(bed.view(), {0, 4, 0.01, {0, 0}}, {"pressure"}), std::invalid_argument);
  const FieldFrame f = rasterize(bed.view(), spec, {});
  EXPECT_TRUE(f.scalars.empty());
  EXPECT_EQ(std::count(f.active.begin(), f.active.end(), 1), 4);
}

// ---------------------------------------------------------------------------------------------
// ParaView export

TEST_F(FieldStore, VtiIsWellFormedImageDataWithCellArrays) {
  const FieldFrame f = small_frame();
  const fs::path path = dir / "frames" / "frame_00042.vti";
  write_vti(path.string(), f);
  const std::string xml = slurp(path);
  ASSERT_EQ(xml_root(xml), "VTKFile");
  EXPECT_EQ(attribute(xml, "VTKFile", "type"), "ImageData");
  EXPECT_EQ(attribute(xml, "ImageData", "WholeExtent"), "0 5 0 4 0 0");  // point extents: 5x4 cells
  EXPECT_EQ(attribute(xml, "ImageData", "Origin"), "-0.02 0.1 0");
  EXPECT_EQ(attribute(xml, "ImageData", "Spacing"), "0.01 0.01 0.01");
  const std::string cells = xml.substr(xml.find("<CellData"), xml.find("</CellData>") - xml.find("<CellData"));
  EXPECT_EQ(count_of(cells, "<DataArray"), 4u);  // velocity, pressure, packing_fraction, vtkGhostType

  auto pressure = vti_array(xml, "pressure");
  ASSERT_EQ(pressure.size(), 20 * sizeof(float));
  float p42;
  std::memcpy(&p42, pressure.data() + f.index(4, 2) * sizeof(float), sizeof p42);
  EXPECT_EQ(p42, 2400.0f);
  auto velocity = vti_array(xml, "velocity");
  ASSERT_EQ(velocity.size(), 3 * 20 * sizeof(float));
  float v[3];
  std::memcpy(v, velocity.data() + 3 * f.index(4, 2) * sizeof(float), sizeof v);
  EXPECT_EQ(v[0], 0.1f * 4 - 0.2f);
  EXPECT_EQ(v[1], -0.1f);
  EXPECT_EQ(v[2], 0.0f);
  auto ghost = vti_array(xml, "vtkGhostType");
  ASSERT_EQ(ghost.size(), 20u);
  EXPECT_EQ(ghost[f.index(0, 0)], 32);  // hidden: no material
  EXPECT_EQ(ghost[f.index(1, 0)], 0);
}

TEST_F(FieldStore, PvdListsFramesInOrder) {
  const fs::path path = dir / "frames.pvd";
  write_pvd(path.string(), {{0.0, "frames/frame_00000.vti"}, {0.05, "frames/frame_00001.vti"}});
  const std::string xml = slurp(path);
  ASSERT_EQ(xml_root(xml), "VTKFile");
  EXPECT_EQ(attribute(xml, "VTKFile", "type"), "Collection");
  EXPECT_EQ(count_of(xml, "<DataSet "), 2u);
  EXPECT_EQ(attribute(xml, "DataSet", "file"), "frames/frame_00000.vti");
  const std::string second = xml.substr(xml.rfind("<DataSet"));
  EXPECT_EQ(attribute(second, "DataSet", "timestep"), "0.05");
  EXPECT_EQ(attribute(second, "DataSet", "file"), "frames/frame_00001.vti");
}

}  // namespace
