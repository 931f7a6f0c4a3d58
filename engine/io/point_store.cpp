// OpenVDB point files: write_points_vdb / read_points (layout documented in point_store.hpp).
#include "engine/io/point_store.hpp"

#include <openvdb/openvdb.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <openvdb/tree/LeafManager.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>

#include "engine/io/field_store.hpp"
#include "engine/io/vdb_meta.hpp"

namespace furrow {

namespace {

namespace fs = std::filesystem;
namespace vp = openvdb::points;

constexpr const char* kGridName = "points";
constexpr double kPi = 3.14159265358979323846;

// Positions as OpenVDB's point partitioner reads them, straight from the solver's arrays.
struct PositionSource {
  using PosType = openvdb::Vec3d;
  using value_type = openvdb::Vec3d;
  const double* x = nullptr;
  const double* y = nullptr;
  size_t n = 0;
  size_t size() const { return n; }
  void getPos(size_t i, openvdb::Vec3d& xyz) const { xyz = openvdb::Vec3d(x[i], y[i], 0.0); }
};

// One float attribute: value of point i.
struct FloatAttr {
  std::string name, unit;
  std::function<float(size_t)> at;
};

struct PointSources {
  PositionSource pos;
  std::function<float(size_t)> vx, vy;
  std::vector<FloatAttr> scalars;
};

const std::string& unit_of(const char* field) { return find_field(field)->unit; }

// The voxel (i, j, 0) of the points file is the solver's cell (i, j), as in the frame files.
openvdb::math::Transform::Ptr points_transform(double dx_m) {
  auto xform = openvdb::math::Transform::createLinearTransform(dx_m);
  xform->postTranslate(openvdb::Vec3d(0.5 * dx_m, 0.5 * dx_m, 0.0));
  return xform;
}

void write_points(const std::string& path, const PointFrameInfo& info, const PointSources& src) {
  const size_t n = src.pos.n;
  if (!(info.dx_m > 0.0)) throw std::invalid_argument("write_points_vdb: dx_m must be > 0");
  if (n > size_t(std::numeric_limits<int32_t>::max()))
    throw std::invalid_argument("write_points_vdb: " + std::to_string(n) + " points do not fit the int32 id");
  vdb_detail::init_openvdb();
  const auto xform = points_transform(info.dx_m);

  // P is stored voxel-local (float offsets from the voxel centre), so it keeps float precision
  // relative to dx anywhere in the domain. No quantising codec: attributes read back as written.
  const auto index_grid = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(src.pos, *xform);
  auto grid = vp::createPointDataGrid<vp::NullCodec, vp::PointDataGrid>(*index_grid, src.pos, *xform);
  grid->setName(kGridName);
  auto& tree = grid->tree();
  vp::appendAttribute<int32_t>(tree, "id");
  vp::appendAttribute<openvdb::Vec3f>(tree, "v");
  for (const auto& a : src.scalars) vp::appendAttribute<float>(tree, a.name);

  // every attribute of a leaf in one pass; the index leaf lists the leaf's points in file order
  const auto& index_tree = index_grid->tree();
  openvdb::tree::LeafManager<vp::PointDataTree> leaves(tree);
  leaves.foreach([&](vp::PointDataTree::LeafNodeType& leaf, size_t) {
    const auto* index_leaf = index_tree.probeConstLeaf(leaf.origin());
    if (!index_leaf) return;
    const auto& set = leaf.attributeSet();
    vp::AttributeWriteHandle<int32_t> id(leaf.attributeArray(set.find("id")));
    vp::AttributeWriteHandle<openvdb::Vec3f> v(leaf.attributeArray(set.find("v")));
    std::vector<std::unique_ptr<vp::AttributeWriteHandle<float>>> s;
    for (const auto& a : src.scalars)
      s.push_back(std::make_unique<vp::AttributeWriteHandle<float>>(leaf.attributeArray(set.find(a.name))));
    openvdb::Index k = 0;
    for (const auto i : index_leaf->indices()) {
      id.set(k, int32_t(i));
      v.set(k, openvdb::Vec3f(src.vx(i), src.vy(i), 0.0f));
      for (size_t a = 0; a < s.size(); ++a) s[a]->set(k, src.scalars[a].at(i));
      ++k;
    }
  });

  grid->insertMeta("unit_P", openvdb::StringMetadata("m"));
  grid->insertMeta("unit_id", openvdb::StringMetadata("-"));
  grid->insertMeta("unit_v", openvdb::StringMetadata(unit_of("velocity")));
  for (const auto& a : src.scalars) grid->insertMeta("unit_" + a.name, openvdb::StringMetadata(a.unit));

  openvdb::MetaMap meta;
  vdb_detail::put_frame_meta(meta, info.scene_name, info.time_s, info.step, info.dt_s, info.dx_m, info.bodies);
  meta.insertMeta("point_count", openvdb::Int64Metadata(int64_t(n)));

  openvdb::GridPtrVec grids{grid};
  vdb_detail::write_vdb(path, grids, meta);
}

std::function<float(size_t)> from(const std::vector<float>& v) {
  const float* a = v.data();
  return [a](size_t i) { return a[i]; };
}
std::function<float(size_t)> from(ScalarArray a) {
  return [a](size_t i) { return float(a[i]); };
}
std::function<float(size_t)> disc_radius(std::function<float(size_t)> volume) {
  return [volume](size_t i) { return float(std::sqrt(double(volume(i)) / kPi)); };
}

}  // namespace

void write_points_vdb(const std::string& path, const PointFrame& f) {
  const size_t n = f.x_m.size();
  auto need = [&](size_t size, const char* what, bool optional) {
    if (size == n || (optional && size == 0)) return;
    throw std::invalid_argument(std::string("write_points_vdb: ") + what + " has " + std::to_string(size) +
                                " values for " + std::to_string(n) + " points" + (optional ? " (or none)" : ""));
  };
  need(f.y_m.size(), "y_m", false);
  need(f.vx_m_s.size(), "vx_m_s", false);
  need(f.vy_m_s.size(), "vy_m_s", false);
  need(f.volume_m2.size(), "volume_m2", false);
  PointSources src;
  src.pos = {f.x_m.data(), f.y_m.data(), n};
  src.vx = from(f.vx_m_s);
  src.vy = from(f.vy_m_s);
  src.scalars.push_back({"volume", "m^2", from(f.volume_m2)});
  src.scalars.push_back({"pscale", "m", disc_radius(from(f.volume_m2))});
  const std::pair<const char*, const std::vector<float>*> optional[] = {
      {"pressure", &f.pressure_Pa},       {"packing_fraction", &f.packing_fraction},
      {"strain_rate", &f.strain_rate_1_s}, {"plastic_strain", &f.plastic_strain},
      {"phi_d", &f.phi_d}};
  for (const auto& [name, v] : optional) {
    need(v->size(), name, true);
    if (!v->empty()) src.scalars.push_back({name, unit_of(name), from(*v)});
  }
  write_points(path, f, src);
}

void write_points_vdb(const std::string& path, const PointFrameInfo& info, const ParticleView& p) {
  if (!p.x_m || !p.y_m || !p.vx_m_s || !p.vy_m_s || !p.mass_kg || !p.volume_m2)
    throw std::invalid_argument("write_points_vdb: the particle view needs positions, velocity, mass and volume");
  PointSources src;
  src.pos = {p.x_m, p.y_m, p.count};
  src.vx = from(p.vx_m_s);
  src.vy = from(p.vy_m_s);
  src.scalars.push_back({"volume", "m^2", from(p.volume_m2)});
  src.scalars.push_back({"pscale", "m", disc_radius(from(p.volume_m2))});
  if (p.pressure_Pa) src.scalars.push_back({"pressure", unit_of("pressure"), from(p.pressure_Pa)});
  if (p.grain_density_kg_m3) {
    const ScalarArray m = p.mass_kg, V = p.volume_m2, rho = p.grain_density_kg_m3;
    src.scalars.push_back({"packing_fraction", unit_of("packing_fraction"),
                           [m, V, rho](size_t i) { return float(m[i] / (rho[i] * V[i])); }});
  }
  if (p.strain_rate_1_s) src.scalars.push_back({"strain_rate", unit_of("strain_rate"), from(p.strain_rate_1_s)});
  if (p.plastic_strain) src.scalars.push_back({"plastic_strain", unit_of("plastic_strain"), from(p.plastic_strain)});
  if (p.phi_d) src.scalars.push_back({"phi_d", unit_of("phi_d"), from(p.phi_d)});
  write_points(path, info, src);
}

PointFrame read_points(const std::string& path) {
  const char* who = "read_points";
  const char* kind = "points file";
  const vdb_detail::VdbContents contents = vdb_detail::read_vdb(path, who);
  auto fail = [&](const std::string& what) { throw std::runtime_error(std::string(who) + ": " + path + ": " + what); };

  vp::PointDataGrid::Ptr grid;
  for (const auto& base : *contents.grids)
    if (base->getName() == kGridName) grid = openvdb::GridBase::grid<vp::PointDataGrid>(base);
  if (!grid) fail(std::string("no point data grid '") + kGridName + "' (not a Furrow points file?)");

  const openvdb::MetaMap& meta = *contents.meta;
  PointFrame f;
  f.scene_name = vdb_detail::file_meta<std::string>(meta, "scene", path, who, kind);
  f.time_s = vdb_detail::file_meta<double>(meta, "time_s", path, who, kind);
  f.step = vdb_detail::file_meta<int64_t>(meta, "step", path, who, kind);
  f.dt_s = vdb_detail::file_meta<double>(meta, "dt_s", path, who, kind);
  f.dx_m = vdb_detail::file_meta<double>(meta, "dx_m", path, who, kind);
  const int64_t count = vdb_detail::file_meta<int64_t>(meta, "point_count", path, who, kind);
  f.bodies = vdb_detail::bodies_meta(meta, path, who, kind);
  if (!(f.dx_m > 0.0)) fail("metadata dx_m must be positive");
  const auto& tree = grid->tree();
  const uint64_t stored = vp::pointCount(tree);
  if (count < 0 || uint64_t(count) != stored)
    fail("metadata point_count is " + std::to_string(count) + " but the grid holds " + std::to_string(stored) +
         " points");
  const size_t n = size_t(count);

  f.x_m.resize(n), f.y_m.resize(n), f.vx_m_s.resize(n), f.vy_m_s.resize(n), f.volume_m2.resize(n);
  // optional attributes: present in the file (every leaf has the same descriptor) or left empty
  const std::pair<const char*, std::vector<float>*> optional[] = {
      {"pressure", &f.pressure_Pa},       {"packing_fraction", &f.packing_fraction},
      {"strain_rate", &f.strain_rate_1_s}, {"plastic_strain", &f.plastic_strain},
      {"phi_d", &f.phi_d}};
  std::vector<std::pair<std::string, float*>> scalars = {{"volume", f.volume_m2.data()}};
  if (auto leaf = tree.cbeginLeaf()) {
    const auto& d = leaf->attributeSet().descriptor();
    for (const char* required : {"P", "id", "v", "volume"})
      if (d.find(required) == vp::AttributeSet::INVALID_POS)
        fail(std::string("attribute '") + required + "' is missing (not a Furrow points file?)");
    for (const auto& [name, v] : optional)
      if (d.find(name) != vp::AttributeSet::INVALID_POS) {
        v->resize(n);
        scalars.emplace_back(name, v->data());
      }
  }

  std::vector<uint8_t> seen(n, 0);
  const openvdb::math::Transform& xform = grid->transform();
  for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
    const auto& set = leaf->attributeSet();
    auto array = [&](const std::string& name) -> const vp::AttributeArray& {
      const size_t pos = set.find(name);
      if (pos == vp::AttributeSet::INVALID_POS) {
        const openvdb::Coord o = leaf->origin();
        fail("attribute '" + name + "' is missing in the leaf at voxel (" + std::to_string(o.x()) + ", " +
             std::to_string(o.y()) + ", " + std::to_string(o.z()) + ")");
      }
      return *set.getConst(pos);
    };
    try {
      vp::AttributeHandle<openvdb::Vec3f> P(array("P")), v(array("v"));
      vp::AttributeHandle<int32_t> id(array("id"));
      std::vector<std::unique_ptr<vp::AttributeHandle<float>>> s;
      for (const auto& a : scalars) s.push_back(std::make_unique<vp::AttributeHandle<float>>(array(a.first)));
      for (auto it = leaf->beginIndexAll(); it; ++it) {
        const openvdb::Index k = *it;
        const int32_t i = id.get(k);
        if (i < 0 || size_t(i) >= n || seen[size_t(i)])
          fail("attribute 'id' holds " + std::to_string(i) + (i >= 0 && size_t(i) < n ? " twice" : "") +
               "; expected each of 0.." + std::to_string(int64_t(n) - 1) + " once");
        seen[size_t(i)] = 1;
        const openvdb::Vec3d xyz = xform.indexToWorld(it.getCoord().asVec3d() + openvdb::Vec3d(P.get(k)));
        f.x_m[size_t(i)] = xyz.x();
        f.y_m[size_t(i)] = xyz.y();
        const openvdb::Vec3f vel = v.get(k);
        f.vx_m_s[size_t(i)] = vel.x();
        f.vy_m_s[size_t(i)] = vel.y();
        for (size_t a = 0; a < s.size(); ++a) scalars[a].second[size_t(i)] = s[a]->get(k);
      }
    } catch (const openvdb::Exception& e) {
      fail(std::string("attributes of an unexpected type (") + e.what() + ")");
    }
  }
  return f;
}

std::string points_path(const std::string& run_dir, int64_t index) {
  if (index < 0) throw std::invalid_argument("points_path: negative frame index");
  char name[48];
  std::snprintf(name, sizeof name, "points_%05lld.vdb", static_cast<long long>(index));
  return (fs::path(run_dir) / "frames" / name).string();
}

}  // namespace furrow
