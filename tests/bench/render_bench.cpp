// Milliseconds per 1280x720 movie frame (render + read-back) for a 400 x 250 = 10^5-cell field
// with colorbar, time stamp, title and a body outline; drawn blended at about the image's
// resolution (the default), as flat cells (the baseline in the same run), and with the force panel.
// Target: <= 100 ms per frame.
#include <benchmark/benchmark.h>

#include <cmath>

#include "render/frame_renderer.hpp"
#include "render/point_splat.hpp"
#include "tests/render/synthetic_frames.hpp"

using namespace furrow;
using namespace furrow::render;

namespace {
FieldFrame bench_frame() {
  // 1.0 m x 0.625 m bed at 2.5 mm, material up to 0.5 m, a plate in it
  FieldFrame f = test::hydrostatic_frame(400, 250, 0.0025, 0.5);
  f.bodies.push_back(test::box_body("plate", 0.45, 0.40, 0.55, 0.46));
  return f;
}

ForcePanel bench_panel() {
  ForcePanel panel;
  ForceSeries s;
  s.label = "plate";
  for (int k = 0; k <= 2000; ++k) {
    s.t_s.push_back(5e-4 * k);
    s.x.push_back(0.05 * k);
    s.y.push_back(40.0 * std::sqrt(double(k)));
  }
  panel.series.push_back(s);
  return panel;
}

void run(benchmark::State& state, bool with_panel, bool smooth = true) {
  FrameStyle style;
  style.smooth = smooth;
  style.field = "pressure";
  style.range = {0.0, test::kRhoBulk_kg_m3 * test::kG_m_s2 * 0.5, false};
  if (with_panel) style.panel = bench_panel();
  FrameRenderer r(style);
  FieldFrame f = bench_frame();
  int k = 0;
  for (auto _ : state) {
    f.time_s = 0.0005 * (k++ % 2000);  // the panel curve changes every frame, as in a movie
    RgbImage img = r.render(f);
    benchmark::DoNotOptimize(img.rgb.data());
  }
  state.counters["cells"] = double(f.nx) * f.ny;
}
// The material points drawn as discs: 3.2 x 10^5 points (4 a cell in the material) splatted at 4 texels a cell
// and drawn, as `furrow render --points` does each frame.
void run_points(benchmark::State& state) {
  FrameStyle style;
  style.field = "pressure";
  style.smooth = false;
  style.range = {0.0, test::kRhoBulk_kg_m3 * test::kG_m_s2 * 0.5, false};
  FrameRenderer r(style);
  const FieldFrame grid = bench_frame();
  PointFrame pts;
  pts.dx_m = grid.dx_m;
  pts.bodies = grid.bodies;
  for (int j = 0; j < 2 * 200; ++j)
    for (int i = 0; i < 2 * grid.nx; ++i) {
      pts.x_m.push_back((i + 0.5) * grid.dx_m / 2), pts.y_m.push_back((j + 0.5) * grid.dx_m / 2);
      pts.vx_m_s.push_back(0.f), pts.vy_m_s.push_back(0.f);
      pts.volume_m2.push_back(float(grid.dx_m * grid.dx_m / 4));
      pts.pressure_Pa.push_back(float(test::kRhoBulk_kg_m3 * test::kG_m_s2 * (0.5 - pts.y_m.back())));
    }
  for (auto _ : state) {
    RgbImage img = r.render(splat_points(pts, grid, 4, {"pressure"}, "bench"));
    benchmark::DoNotOptimize(img.rgb.data());
  }
  state.counters["points"] = double(pts.size());
}
}  // namespace

static void BM_RenderFrame1280x720(benchmark::State& s) { run(s, false); }
static void BM_RenderPoints1280x720(benchmark::State& s) { run_points(s); }
static void BM_RenderFrame1280x720_ForcePanel(benchmark::State& s) { run(s, true); }
static void BM_RenderFrame1280x720_Cells(benchmark::State& s) { run(s, false, false); }
BENCHMARK(BM_RenderFrame1280x720)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_RenderFrame1280x720_ForcePanel)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_RenderFrame1280x720_Cells)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_RenderPoints1280x720)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_MAIN();
