// Field store costs (target: storing a frame of 10^5 cells in OpenVDB takes <= 50 ms).
// Frame: 400 x 250 cells, all holding material, with velocity, pressure, strain_rate and
// packing_fraction (plus the free `density` alias); values are noisy so compression is not flattered.
// "CPU" is the whole process (all threads), so it stays meaningful on a loaded machine.
#include "engine/io/field_store.hpp"

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <algorithm>
#include <cmath>
#include <random>

namespace fs = std::filesystem;
using namespace furrow;

namespace {

constexpr int kNx = 400, kNy = 250;
constexpr double kDx = 0.0025;
const std::vector<std::string> kFields = {"velocity", "pressure", "strain_rate", "packing_fraction"};

struct Particles {
  std::vector<double> x, y, m, V, rho_g, vx, vy, p, sr;
  ParticleView view() const {
    ParticleView v;
    v.count = x.size();
    v.x_m = x.data(), v.y_m = y.data(), v.mass_kg = m.data(), v.volume_m2 = V.data();
    v.grain_density_kg_m3 = rho_g.data(), v.vx_m_s = vx.data(), v.vy_m_s = vy.data();
    v.pressure_Pa = p.data(), v.strain_rate_1_s = sr.data();
    return v;
  }
};

// 2 x 2 particles per cell over the whole grid (4 x 10^5), shuffled as a solver's arrays drift.
const Particles& particles() {
  static const Particles ps = [] {
    Particles ps;
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<std::pair<double, double>> pos;
    for (int j = 0; j < 2 * kNy; ++j)
      for (int i = 0; i < 2 * kNx; ++i) pos.emplace_back((i + u(rng)) * kDx / 2, (j + u(rng)) * kDx / 2);
    std::shuffle(pos.begin(), pos.end(), rng);
    for (const auto& [x, y] : pos) {
      const double V = kDx * kDx / 4;
      ps.x.push_back(x), ps.y.push_back(y), ps.V.push_back(V), ps.rho_g.push_back(2500.0);
      ps.m.push_back(2500.0 * (0.58 + 0.04 * u(rng)) * V);
      ps.vx.push_back(0.1 * u(rng)), ps.vy.push_back(-0.1 * u(rng));
      ps.p.push_back(1500.0 * 9.81 * (kNy * kDx - y)), ps.sr.push_back(std::exp(8.0 * u(rng) - 4.0));
    }
    return ps;
  }();
  return ps;
}

FieldFrame frame() {
  FieldFrame f = rasterize(particles().view(), {kNx, kNy, kDx, {0.0, 0.0}}, kFields);
  f.scene_name = "bench";
  f.time_s = 0.5;
  f.step = 20000;
  f.dt_s = 2.5e-5;
  return f;
}

fs::path bench_dir() {
  const fs::path d = fs::temp_directory_path() / ("furrow_store_bench_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

void BM_WriteFrameVdb(benchmark::State& state) {
  const FieldFrame f = frame();
  const fs::path dir = bench_dir();
  const std::string path = frame_path(dir.string(), 1);
  for (auto _ : state) write_frame_vdb(path, f);
  state.counters["cells"] = double(f.nx) * f.ny;
  state.counters["file_MB"] = double(fs::file_size(path)) / 1e6;
  fs::remove_all(dir);
}
BENCHMARK(BM_WriteFrameVdb)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_ReadFrame(benchmark::State& state) {
  const fs::path dir = bench_dir();
  const std::string path = frame_path(dir.string(), 1);
  write_frame_vdb(path, frame());
  for (auto _ : state) benchmark::DoNotOptimize(read_frame(path));
  fs::remove_all(dir);
}
BENCHMARK(BM_ReadFrame)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_WriteVti(benchmark::State& state) {
  const FieldFrame f = frame();
  const fs::path dir = bench_dir();
  const std::string path = frame_path(dir.string(), 1, "vti");
  for (auto _ : state) write_vti(path, f);
  state.counters["file_MB"] = double(fs::file_size(path)) / 1e6;
  fs::remove_all(dir);
}
BENCHMARK(BM_WriteVti)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_Rasterize(benchmark::State& state) {
  const ParticleView v = particles().view();
  for (auto _ : state) benchmark::DoNotOptimize(rasterize(v, {kNx, kNy, kDx, {0.0, 0.0}}, kFields));
  state.counters["particles"] = double(v.count);
}
BENCHMARK(BM_Rasterize)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
