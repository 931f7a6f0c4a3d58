// Field store: particles -> cell fields (rasterize), cell fields <-> OpenVDB frame files, and a
// ParaView time series (.pvd + one .vti per frame). Field names and units come from
// field_registry(); nothing here keeps its own list of fields except the rasterizer's table of
// which particle array feeds which field.
//
// Frame files (OpenVDB and ParaView), one per frame: <run>/frames/frame_00042.vdb holding
//   - `velocity`: Vec3SGrid (vx, vy, 0);
//   - one FloatGrid per scalar field, named as in the registry (pressure, strain_rate, ...);
//   - `density`: when packing_fraction is stored and the bulk density field is not, a copy of
//     packing_fraction (sharing its tree, so it costs nothing on disk) named `density`, because
//     Blender shows a grid called `density` with no setup. It carries grid metadata
//     copy_of = "packing_fraction" and unit "-"; read_frame() skips it, so a round trip does not
//     invent a bulk-density field.
// Every grid: voxel size dx, voxel (i, j, 0) centred at origin + ((i+0.5) dx, (j+0.5) dx, 0) (a
// one-voxel slab, z in [-dx/2, dx/2]), background 0, only cells with material active, grid
// metadata "unit". File metadata: scene, time_s, step, dt_s, dx_m, nx, ny, origin_x_m,
// origin_y_m, dimension = 2, furrow_version and bodies_json (outlines and forces, so one frame
// renders on its own). Blosc compression when OpenVDB has it. All writes are atomic (temporary
// file in the same directory, then rename).
#pragma once
#include "engine/fields.hpp"

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace furrow {

// How point values reach a cell.
//  - quadratic_bspline (stored frames): every point within 1.5 cells of the cell's centre, weighted
//    by the quadratic B-spline of its offset (the solver's default kernel) times its mass. A cell
//    reads the flow around it, not only the 2-4 points it happens to hold this step: in a flowing
//    zone of a rate-independent model a point is elastic (rate 0) on some steps, and with
//    per-cell averages 4.9% of the flowing cells of plate_intrusion read as zero-rate specks.
//  - cell_average: only the points inside the cell, equal weights per unit mass (the mosaic).
// A cell is active when it holds a point itself, so the free surface stays where the material is
// (the kernel widens nothing into the air); with the B-spline, an empty cell is also active when
// the kernel finds more than 0.4 of a cell's volume around it: a hole inside the material (points
// pulled apart behind a body's corner) that a cell above a flat surface (0.16) or a one-cell notch
// in it (0.37) never reaches.
enum class RasterTransfer { quadratic_bspline, cell_average };

// The cell grid fields are rasterized on; cell (i, j) spans origin + [i, i+1) x [j, j+1) dx.
struct RasterSpec {
  int nx = 0, ny = 0;
  double dx_m = 0.0;
  Eigen::Vector2d origin_m{0, 0};
  RasterTransfer transfer = RasterTransfer::quadratic_bspline;
};

// Bins every particle into the cell containing its position (particles outside the grid are
// ignored) and returns mass-weighted averages (weights w m, w from spec.transfer) of the
// requested fields:
//   velocity, pressure, strain_rate, plastic_strain, phi_d: sum(w m q) / sum(w m)
//   packing_fraction: sum(w m) / sum(w rho_g V)  (the mass-weighted mean of phi = m / (rho_g V))
//   density:          sum(w m) / sum(w V)        (bulk density)
// A cell is active as above (cell_average: when its own particles carry mass); inactive cells hold
// 0. Only the requested
// fields are computed. Throws std::invalid_argument for an unknown field name, for a requested
// field whose particle array is null (asking for phi_d in an NDPM run is a caller bug, not
// something to skip silently), for missing positions/mass/volume and for a bad spec.
// Scene name, time, step, dt and bodies are left for the caller to set. The result does not
// depend on the number of threads (each cell sums its neighbourhood's particles in a fixed order).
FieldFrame rasterize(const ParticleView& p, const RasterSpec& spec,
                     const std::vector<std::string>& fields);

// Writes one frame (layout above). Creates the parent directory if needed. Throws
// std::invalid_argument for an inconsistent frame (sizes, unregistered field, no fields at all)
// and std::runtime_error naming the file when writing fails.
void write_frame_vdb(const std::string& path, const FieldFrame& f);

// Reads a frame written by write_frame_vdb back (grid layout from the file metadata, active mask
// from the active voxels). Throws std::runtime_error naming the file (and the key) when it is
// missing, unreadable or lacks what write_frame_vdb stores.
FieldFrame read_frame(const std::string& vdb_path);

// <run_dir>/frames/frame_00042.<ext> (at least five digits).
std::string frame_path(const std::string& run_dir, int64_t index, const std::string& ext = "vdb");

// <run_dir>/frames/frame_NNNNN.vdb files sorted by frame number (temporary files are ignored).
// Throws std::runtime_error naming the folder when <run_dir>/frames does not exist.
std::vector<std::string> list_frames(const std::string& run_dir);

// ParaView: VTK XML ImageData of the frame's cells (CellData arrays named as the fields, velocity
// with 3 components, vtkGhostType hiding inactive cells; base64 inline Float32, little endian),
// and a .pvd collection pointing at such files by path relative to the .pvd.
void write_vti(const std::string& path, const FieldFrame& f);
struct PvdEntry {
  double time_s = 0.0;
  std::string file;  // relative to the .pvd, e.g. "frames/frame_00042.vti"
};
void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries);

}  // namespace furrow
