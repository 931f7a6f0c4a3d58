// The one registry of output fields (name, unit, how to show it) and the per-frame data handed
// from the solver to the field store and from the store to the renderer.
#pragma once
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace furrow {

struct FieldInfo {
  std::string name;         // grid name in VDB files and scene "outputs.fields"
  std::string unit;         // for colorbars and CSV headers
  std::string label;        // human title, e.g. "Pressure"
  bool vector = false;      // velocity only
  bool log_scale = false;   // strain rate is shown on a log scale
  bool dpm_only = false;    // phi_d exists only when the scene's material is DPM
};

// All fields Furrow can store, in a stable order.
const std::vector<FieldInfo>& field_registry();
const FieldInfo* find_field(const std::string& name);

// A read-only particle array stored as double or float (the solver stores some quantities as
// float: engine/README.md, "Stored precision"); reads give double.
class ScalarArray {
 public:
  ScalarArray() = default;
  ScalarArray(std::nullptr_t) {}
  ScalarArray(const double* a) : f64_(a) {}
  ScalarArray(const float* a) : f32_(a) {}
  double operator[](size_t i) const { return f64_ ? f64_[i] : double(f32_[i]); }
  explicit operator bool() const { return f64_ || f32_; }

 private:
  const double* f64_ = nullptr;
  const float* f32_ = nullptr;
};

// Read-only view of particle arrays (structure of arrays) for rasterization. Null arrays mean
// "not computed for this run" and the corresponding fields are skipped.
struct ParticleView {
  size_t count = 0;
  const double* x_m = nullptr;
  const double* y_m = nullptr;
  ScalarArray mass_kg;                    // per metre out of plane
  ScalarArray volume_m2;                  // current area (per metre out of plane)
  ScalarArray vx_m_s;
  ScalarArray vy_m_s;
  ScalarArray pressure_Pa;
  ScalarArray strain_rate_1_s;            // equivalent plastic shear rate
  ScalarArray plastic_strain;             // equivalent plastic shear strain
  ScalarArray phi_d;                      // DPM state
  ScalarArray grain_density_kg_m3;        // per particle rho_g (packing = m / (rho_g V))
};

// A body as drawn in a frame: its outline polygon in world coordinates and the force it feels.
struct BodyOutline {
  std::string name;
  std::vector<Eigen::Vector2d> outline_m;  // closed loop, counter-clockwise
  Eigen::Vector2d position_m{0, 0};
  Eigen::Vector2d force_N_per_m{0, 0};
};

// Fields rasterized on cells (cell (i,j) centre at origin + (i+0.5, j+0.5) dx). Row-major, i fastest.
struct FieldFrame {
  std::string scene_name;
  int64_t step = 0;
  double time_s = 0.0, dt_s = 0.0, dx_m = 0.0;
  Eigen::Vector2d origin_m{0, 0};
  int nx = 0, ny = 0;
  std::vector<uint8_t> active;                        // 1 where material is present
  std::map<std::string, std::vector<float>> scalars;  // name -> nx*ny values
  std::vector<float> velocity_x, velocity_y;          // empty unless "velocity" requested
  std::vector<BodyOutline> bodies;
  size_t index(int i, int j) const { return size_t(j) * size_t(nx) + size_t(i); }
};

}  // namespace furrow
