// OpenVDB frame files: write_frame_vdb / read_frame (layout documented in field_store.hpp).
#include "engine/io/field_store.hpp"

#include <openvdb/openvdb.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "engine/io/vdb_meta.hpp"

namespace furrow {

namespace {

using vdb_detail::init_openvdb;

constexpr const char* kPackingAlias = "density";  // Blender shows a grid of this name unasked
constexpr const char* kCopyOfKey = "copy_of";

void check_frame(const FieldFrame& f) {
  auto bad = [](const std::string& what) {
    throw std::invalid_argument("write_frame_vdb: " + what);
  };
  if (f.nx <= 0 || f.ny <= 0 || !(f.dx_m > 0.0)) bad("frame needs nx, ny > 0 and dx_m > 0");
  const size_t n = size_t(f.nx) * size_t(f.ny);
  if (f.active.size() != n) bad("active mask has " + std::to_string(f.active.size()) +
                                " cells, expected nx*ny = " + std::to_string(n));
  for (const auto& [name, v] : f.scalars) {
    const FieldInfo* info = find_field(name);
    if (!info || info->vector) bad("'" + name + "' is not a scalar field of the registry");
    if (v.size() != n) bad("field '" + name + "' has " + std::to_string(v.size()) + " cells");
  }
  if (f.velocity_x.size() != f.velocity_y.size() || (!f.velocity_x.empty() && f.velocity_x.size() != n))
    bad("velocity components must both have nx*ny cells");
  if (f.scalars.empty() && f.velocity_x.empty()) bad("frame has no fields to store");
}

// A grid holding value_at(c) in each active cell c = index(i, j) at voxel (i, j, 0).
template <class GridT, class ValueAt>
typename GridT::Ptr make_grid(const FieldFrame& f, const std::string& name, const std::string& unit,
                              const openvdb::math::Transform& xform, ValueAt value_at) {
  auto grid = GridT::create(typename GridT::ValueType(0));
  grid->setName(name);
  grid->setTransform(xform.copy());
  grid->insertMeta("unit", openvdb::StringMetadata(unit));
  // fill one 8x8 (x1 layer) block of cells per leaf directly: cheaper than voxel-by-voxel access
  using LeafT = typename GridT::TreeType::LeafNodeType;
  constexpr int kDim = int(LeafT::DIM);
  for (int j0 = 0; j0 < f.ny; j0 += kDim)
    for (int i0 = 0; i0 < f.nx; i0 += kDim) {
      auto leaf = std::make_unique<LeafT>(openvdb::Coord(i0, j0, 0), typename GridT::ValueType(0));
      for (int j = j0; j < std::min(j0 + kDim, f.ny); ++j)
        for (int i = i0; i < std::min(i0 + kDim, f.nx); ++i) {
          const size_t c = f.index(i, j);
          if (f.active[c]) leaf->setValueOn(LeafT::coordToOffset(openvdb::Coord(i, j, 0)), value_at(c));
        }
      if (!leaf->isEmpty()) grid->tree().addLeaf(leaf.release());
    }
  return grid;
}

}  // namespace

void write_frame_vdb(const std::string& path, const FieldFrame& f) {
  check_frame(f);
  init_openvdb();
  auto xform = openvdb::math::Transform::createLinearTransform(f.dx_m);
  xform->postTranslate(openvdb::Vec3d(f.origin_m.x() + 0.5 * f.dx_m, f.origin_m.y() + 0.5 * f.dx_m, 0.0));

  // grids in registry order; each is built independently, so build them in parallel
  std::vector<const FieldInfo*> present;
  for (const auto& info : field_registry())
    if (info.vector ? !f.velocity_x.empty() : f.scalars.count(info.name) > 0) present.push_back(&info);
  openvdb::GridPtrVec grids(present.size());
  tbb::parallel_for(size_t(0), present.size(), [&](size_t g) {
    const FieldInfo& info = *present[g];
    if (info.vector) {
      grids[g] = make_grid<openvdb::Vec3SGrid>(f, info.name, info.unit, *xform, [&](size_t c) {
        return openvdb::Vec3s(f.velocity_x[c], f.velocity_y[c], 0.0f);
      });
    } else {
      const float* v = f.scalars.at(info.name).data();
      auto grid = make_grid<openvdb::FloatGrid>(f, info.name, info.unit, *xform, [v](size_t c) { return v[c]; });
      grid->setGridClass(openvdb::GRID_FOG_VOLUME);
      grids[g] = grid;
    }
  });
  for (size_t g = 0; g < present.size(); ++g) {
    if (present[g]->name != "packing_fraction" || f.scalars.count(kPackingAlias)) continue;
    auto alias = grids[g]->copyGrid();  // shares the tree: written once, as an instance
    alias->setName(kPackingAlias);
    alias->insertMeta(kCopyOfKey, openvdb::StringMetadata("packing_fraction"));
    grids.push_back(alias);
  }

  openvdb::MetaMap meta;  // a sorted map: the order of insertion does not reach the file
  vdb_detail::put_frame_meta(meta, f.scene_name, f.time_s, f.step, f.dt_s, f.dx_m, f.bodies);
  meta.insertMeta("nx", openvdb::Int32Metadata(f.nx));
  meta.insertMeta("ny", openvdb::Int32Metadata(f.ny));
  meta.insertMeta("origin_x_m", openvdb::DoubleMetadata(f.origin_m.x()));
  meta.insertMeta("origin_y_m", openvdb::DoubleMetadata(f.origin_m.y()));

  vdb_detail::write_vdb(path, grids, meta);
}

namespace {

template <class T>
T file_meta(const openvdb::MetaMap& meta, const std::string& key, const std::string& path) {
  return vdb_detail::file_meta<T>(meta, key, path, "read_frame", "frame");
}

// Marks the grid's active voxels in f.active and hands each (cell, value) to `store`.
template <class GridT, class Store>
void read_grid(const GridT& grid, FieldFrame& f, const std::string& path, Store store) {
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    if (!it.isVoxelValue())
      throw std::runtime_error("read_frame: " + path + ": grid '" + grid.getName() + "' has an active tile");
    const openvdb::Coord xyz = it.getCoord();
    if (xyz.z() != 0 || xyz.x() < 0 || xyz.x() >= f.nx || xyz.y() < 0 || xyz.y() >= f.ny)
      throw std::runtime_error("read_frame: " + path + ": grid '" + grid.getName() +
                               "' has a voxel outside the " + std::to_string(f.nx) + "x" +
                               std::to_string(f.ny) + "x1 frame");
    const size_t c = f.index(xyz.x(), xyz.y());
    f.active[c] = 1;
    store(c, *it);
  }
}

}  // namespace

FieldFrame read_frame(const std::string& vdb_path) {
  const vdb_detail::VdbContents contents = vdb_detail::read_vdb(vdb_path, "read_frame");
  const openvdb::MetaMap::Ptr& meta = contents.meta;
  const openvdb::GridPtrVecPtr& grids = contents.grids;

  FieldFrame f;
  f.scene_name = file_meta<std::string>(*meta, "scene", vdb_path);
  f.time_s = file_meta<double>(*meta, "time_s", vdb_path);
  f.step = file_meta<int64_t>(*meta, "step", vdb_path);
  f.dt_s = file_meta<double>(*meta, "dt_s", vdb_path);
  f.dx_m = file_meta<double>(*meta, "dx_m", vdb_path);
  f.nx = file_meta<int32_t>(*meta, "nx", vdb_path);
  f.ny = file_meta<int32_t>(*meta, "ny", vdb_path);
  f.origin_m = {file_meta<double>(*meta, "origin_x_m", vdb_path), file_meta<double>(*meta, "origin_y_m", vdb_path)};
  if (f.nx <= 0 || f.ny <= 0 || !(f.dx_m > 0.0))
    throw std::runtime_error("read_frame: " + vdb_path + ": metadata nx, ny, dx_m must be positive");
  f.bodies = vdb_detail::bodies_meta(*meta, vdb_path, "read_frame", "frame");

  const size_t n = size_t(f.nx) * size_t(f.ny);
  f.active.assign(n, 0);
  for (const auto& base : *grids) {
    const std::string name = base->getName();
    const FieldInfo* info = find_field(name);
    if (!info || base->getMetadata<openvdb::StringMetadata>(kCopyOfKey)) continue;  // alias or foreign
    if (info->vector) {
      auto grid = openvdb::GridBase::grid<openvdb::Vec3SGrid>(base);
      if (!grid) throw std::runtime_error("read_frame: " + vdb_path + ": grid '" + name + "' is not a Vec3SGrid");
      f.velocity_x.assign(n, 0.0f);
      f.velocity_y.assign(n, 0.0f);
      read_grid(*grid, f, vdb_path, [&](size_t c, const openvdb::Vec3s& v) {
        f.velocity_x[c] = v.x();
        f.velocity_y[c] = v.y();
      });
    } else {
      auto grid = openvdb::GridBase::grid<openvdb::FloatGrid>(base);
      if (!grid) throw std::runtime_error("read_frame: " + vdb_path + ": grid '" + name + "' is not a FloatGrid");
      auto& values = f.scalars[name];
      values.assign(n, 0.0f);
      read_grid(*grid, f, vdb_path, [&](size_t c, float v) { values[c] = v; });
    }
  }
  return f;
}

}  // namespace furrow
