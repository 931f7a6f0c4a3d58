// Point store: the material points of one frame as an OpenVDB PointDataGrid (Houdini reads it as
// a point cloud), <run>/frames/points_00042.vdb beside frame_00042.vdb when the scene asks for
// outputs.points.
//
// File layout: one PointDataGrid named `points`, voxel size dx; voxel (i, j, 0) is the solver's
// cell (i, j) (centred at ((i+0.5) dx, (j+0.5) dx, 0), as in the frame files), z = 0 for every
// point (plane-strain slab). Attributes, one value per point, no quantisation:
//   P                 Vec3f   position (OpenVDB's: voxel-local offset, so full float precision
//                             within the cell whatever the domain size)
//   id                int32   the particle's index in the solver's arrays when the frame was written
//   v                 Vec3f   velocity (vx, vy, 0), m/s
//   volume            float   area per metre out of plane, m^2
//   pscale            float   sqrt(volume / pi): the radius of a disc of that area (Houdini's size)
//   pressure          float   Pa
//   packing_fraction  float   m / (rho_g V)
//   strain_rate       float   1/s (when the solver tracks it)
//   plastic_strain    float   (when the solver tracks it)
//   phi_d             float   (DPM runs only)
// OpenVDB orders points by voxel; read_points() puts them back in `id` order. Grid metadata
// `unit_<attribute>` gives each attribute's unit. File metadata as the frame files' (scene,
// time_s, step, dt_s, dx_m, dimension = 2, furrow_version, bodies_json) plus point_count.
// Blosc compression when OpenVDB has it; written atomically.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "engine/fields.hpp"

namespace furrow {

// What a points file says about its frame besides the points.
struct PointFrameInfo {
  std::string scene_name;
  int64_t step = 0;
  double time_s = 0.0, dt_s = 0.0, dx_m = 0.0;
  std::vector<BodyOutline> bodies;
};

// The points of one frame, structure of arrays in the solver's particle order. x_m, y_m,
// vx_m_s, vy_m_s and volume_m2 always hold one value per point; the other arrays hold one per
// point or are empty (not stored).
struct PointFrame : PointFrameInfo {
  std::vector<double> x_m, y_m;
  std::vector<float> vx_m_s, vy_m_s;
  std::vector<float> volume_m2;
  std::vector<float> pressure_Pa;
  std::vector<float> packing_fraction;
  std::vector<float> strain_rate_1_s;
  std::vector<float> plastic_strain;
  std::vector<float> phi_d;
  size_t size() const { return x_m.size(); }
};

// Writes a points file (layout above), creating the parent directory if needed. Throws
// std::invalid_argument for an inconsistent frame (array sizes, dx_m <= 0, more than 2^31 - 1
// points) and std::runtime_error naming the file when writing fails.
void write_points_vdb(const std::string& path, const PointFrame& f);

// The same straight from the solver's arrays, without an intermediate copy: the optional
// attributes are those whose arrays `p` has (packing_fraction needs mass and grain density).
// Needs positions, velocity, mass and volume.
void write_points_vdb(const std::string& path, const PointFrameInfo& info, const ParticleView& p);

// Reads a points file back, points in `id` order. Throws std::runtime_error naming the file and
// what is missing when it does not exist, is not an OpenVDB file, holds no `points` grid, lacks
// metadata or a required attribute (P, id, v, volume), or its ids are not 0..point_count-1.
PointFrame read_points(const std::string& path);

// <run_dir>/frames/points_00042.vdb (at least five digits, numbered as frame_path's frames).
std::string points_path(const std::string& run_dir, int64_t index);

}  // namespace furrow
