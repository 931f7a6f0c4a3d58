// Internals shared by the OpenVDB frame files (vdb_io.cpp) and point files (point_store.cpp): the
// library's one-time set-up, the file metadata both carry (scene, time_s, step, dt_s, dx_m,
// dimension, furrow_version, bodies_json) and reading a whole file. Not part of the engine's API.
#pragma once
#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>

#include <cstdint>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/io/atomic_file.hpp"
#include "engine/io/field_store.hpp"
#include "engine/fields.hpp"

namespace furrow::vdb_detail {

inline void init_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

inline nlohmann::json bodies_to_json(const std::vector<BodyOutline>& bodies) {
  auto vec = [](const Eigen::Vector2d& v) { return nlohmann::json::array({v.x(), v.y()}); };
  nlohmann::json out = nlohmann::json::array();
  for (const auto& b : bodies) {
    nlohmann::json outline = nlohmann::json::array();
    for (const auto& v : b.outline_m) outline.push_back(vec(v));
    out.push_back({{"name", b.name},
                   {"position_m", vec(b.position_m)},
                   {"force_N_per_m", vec(b.force_N_per_m)},
                   {"outline_m", outline}});
  }
  return out;
}

inline std::vector<BodyOutline> bodies_from_json(const nlohmann::json& j) {
  auto vec = [](const nlohmann::json& a) { return Eigen::Vector2d(a.at(0).get<double>(), a.at(1).get<double>()); };
  std::vector<BodyOutline> bodies;
  for (const auto& jb : j) {
    BodyOutline b;
    b.name = jb.at("name").get<std::string>();
    b.position_m = vec(jb.at("position_m"));
    b.force_N_per_m = vec(jb.at("force_N_per_m"));
    for (const auto& v : jb.at("outline_m")) b.outline_m.push_back(vec(v));
    bodies.push_back(std::move(b));
  }
  return bodies;
}

// The metadata every Furrow VDB file carries; each file type adds its own keys.
inline void put_frame_meta(openvdb::MetaMap& meta, const std::string& scene_name, double time_s, int64_t step,
                           double dt_s, double dx_m, const std::vector<BodyOutline>& bodies) {
  meta.insertMeta("scene", openvdb::StringMetadata(scene_name));
  meta.insertMeta("time_s", openvdb::DoubleMetadata(time_s));
  meta.insertMeta("step", openvdb::Int64Metadata(step));
  meta.insertMeta("dt_s", openvdb::DoubleMetadata(dt_s));
  meta.insertMeta("dx_m", openvdb::DoubleMetadata(dx_m));
  meta.insertMeta("dimension", openvdb::Int32Metadata(2));
  meta.insertMeta("furrow_version", openvdb::StringMetadata(FURROW_VERSION));
  meta.insertMeta("bodies_json", openvdb::StringMetadata(bodies_to_json(bodies).dump()));
}

// who: the reading function ("read_frame"); kind: what the file should have been ("frame").
template <class T>
T file_meta(const openvdb::MetaMap& meta, const std::string& key, const std::string& path, const char* who,
            const char* kind) {
  auto m = meta.getMetadata<openvdb::TypedMetadata<T>>(key);
  if (!m)
    throw std::runtime_error(std::string(who) + ": " + path + ": metadata '" + key +
                             "' is missing or has the wrong type (not a Furrow " + kind + "?)");
  return m->value();
}

inline std::vector<BodyOutline> bodies_meta(const openvdb::MetaMap& meta, const std::string& path, const char* who,
                                            const char* kind) {
  try {
    return bodies_from_json(nlohmann::json::parse(file_meta<std::string>(meta, "bodies_json", path, who, kind)));
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string(who) + ": " + path + ": metadata 'bodies_json' is malformed: " + e.what());
  }
}

struct VdbContents {
  openvdb::MetaMap::Ptr meta;
  openvdb::GridPtrVecPtr grids;
};

// Every grid and the file metadata, read now (the file may be replaced while the caller holds them).
inline VdbContents read_vdb(const std::string& path, const char* who) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw std::runtime_error(std::string(who) + ": no such file " + path);
  init_openvdb();
  VdbContents c;
  try {
    openvdb::io::File file(path);
    file.open(false);
    c.meta = file.getMetadata();
    c.grids = file.getGrids();
    file.close();
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string(who) + ": " + path + ": not a readable OpenVDB file (" + e.what() + ")");
  }
  return c;
}

// Writes grids and file metadata to `path` atomically, Blosc-compressed when OpenVDB has it.
inline void write_vdb(const std::string& path, const openvdb::GridPtrVec& grids, const openvdb::MetaMap& meta) {
  write_atomically(path, [&](const std::string& tmp) {
    openvdb::io::File file(tmp);
    if (openvdb::io::Archive::hasBloscCompression())
      file.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
    file.write(grids, meta);
    file.close();
  });
}

}  // namespace furrow::vdb_detail
