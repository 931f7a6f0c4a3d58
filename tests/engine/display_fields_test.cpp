// Stored fields read as continuous fields: a flowing zone has no cells that read as still because
// of how points fell into cells on one step, the free surface stays where the material is, and a
// shear band keeps its width.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/analysis.hpp"
#include "engine/io/field_store.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"

using namespace furrow;

namespace {
RasterSpec spec_of(const Simulation& sim, double dx, RasterTransfer transfer) {
  RasterSpec r;
  r.nx = sim.grid().nx;
  r.ny = sim.grid().ny;
  r.dx_m = dx;
  r.transfer = transfer;
  return r;
}
}  // namespace

// plate_intrusion as shipped (dx 10 mm), the plate 15 to 75 mm deep, a frame every 20 ms: the
// flowing zone's cells that read below 1e-3 1/s. Per-cell averages leave a few percent of them
// (a rate-independent model's point is elastic, rate 0, on some steps of a steady flow); the
// B-spline transfer reads the flow around each cell. The cell average's count shows the measure
// can fail: it is the same measure on the same particles.
TEST(DisplayFields, PlateIntrusionStrainRateHasNoSpecksInItsFlowingZone) {
  const SceneTemplate* t = find_scene_template("plate_intrusion");
  ASSERT_NE(t, nullptr);
  Scene scene = parse_scene_text(t->text, "<template plate_intrusion>");
  scene.solver.end_displacement_m = 0.09;
  Simulation sim(scene);
  const double dx = scene.domain.dx_m;
  FlowHoles smooth, cells;
  double next_s = 0.3;  // the plate starts 15 mm above the bed at 0.1 m/s
  int frames = 0;
  bool same_mask = true;
  int64_t filled = 0;
  while (!sim.finished()) {
    sim.step();
    if (sim.time_s() < next_s) continue;
    next_s += 0.02;
    const FieldFrame a = rasterize(sim.particle_view(), spec_of(sim, dx, RasterTransfer::quadratic_bspline), {"strain_rate"});
    const FieldFrame b = rasterize(sim.particle_view(), spec_of(sim, dx, RasterTransfer::cell_average), {"strain_rate"});
    // the B-spline mask is the cells' plus holes inside the material: each added cell has at
    // least 5 of its 8 neighbours holding points (never a cell outside the surface)
    for (int j = 0; j < a.ny; ++j)
      for (int i = 0; i < a.nx; ++i) {
        const size_t c = a.index(i, j);
        if (b.active[c] && !a.active[c]) same_mask = false;
        if (!a.active[c] || b.active[c]) continue;
        int around = 0;
        for (int q = std::max(j - 1, 0); q <= std::min(j + 1, a.ny - 1); ++q)
          for (int r = std::max(i - 1, 0); r <= std::min(i + 1, a.nx - 1); ++r) around += b.active[a.index(r, q)];
        if (around < 5) same_mask = false;
        ++filled;
      }
    const FlowHoles ha = count_flow_holes(a, "strain_rate"), hb = count_flow_holes(b, "strain_rate");
    smooth.flowing += ha.flowing, smooth.holes += ha.holes;
    cells.flowing += hb.flowing, cells.holes += hb.holes;
    ++frames;
  }
  RecordProperty("holes_bspline", std::to_string(smooth.fraction()));
  RecordProperty("holes_cell_average", std::to_string(cells.fraction()));
  ASSERT_GE(frames, 25);
  ASSERT_GT(cells.flowing, 1000);
  EXPECT_TRUE(same_mask) << "the transfer moved the free surface";
  RecordProperty("holes_filled", std::to_string(filled));
  EXPECT_LE(smooth.fraction(), 0.005) << smooth.holes << " of " << smooth.flowing;
  EXPECT_GT(cells.fraction(), 0.01) << cells.holes << " of " << cells.flowing;  // the measure sees specks
}

// A band of points shearing at 1 1/s, 4 cells wide, in a still block: above half its peak, the
// rasterized band is at most one cell wider (the kernel's reach is 1.5 cells, but a symmetric
// kernel keeps a step's half-height where the step is).
TEST(DisplayFields, ShearBandKeepsItsWidth) {
  const double dx = 0.01;
  const int nx = 10, ny = 30, band_j0 = 13, band_j1 = 17;
  std::vector<double> x, y, m, V, rate;
  for (int j = 0; j < 2 * ny; ++j)
    for (int i = 0; i < 2 * nx; ++i) {
      x.push_back((i + 0.5) * dx / 2), y.push_back((j + 0.5) * dx / 2);
      m.push_back(1.0), V.push_back(dx * dx / 4 / 0.6);
      rate.push_back(j >= 2 * band_j0 && j < 2 * band_j1 ? 1.0 : 0.0);
    }
  ParticleView p;
  p.count = x.size();
  p.x_m = x.data(), p.y_m = y.data(), p.mass_kg = m.data(), p.volume_m2 = V.data(), p.strain_rate_1_s = rate.data();
  const FieldFrame f = rasterize(p, {nx, ny, dx, {0.0, 0.0}}, {"strain_rate"});
  const auto& v = f.scalars.at("strain_rate");
  float peak = 0;
  for (float r : v) peak = std::max(peak, r);
  int wide = 0;
  for (int j = 0; j < ny; ++j) wide += v[f.index(5, j)] >= 0.5f * peak;
  EXPECT_NEAR(peak, 1.0, 0.05);
  EXPECT_GE(wide, band_j1 - band_j0);
  EXPECT_LE(wide, band_j1 - band_j0 + 1);
  // every cell holds points: the mask is the block, nothing beyond it
  EXPECT_EQ(std::count(f.active.begin(), f.active.end(), 1), nx * ny);
}

// Mass-weighted with the kernel: a uniform field stays uniform to round-off, also in the cells at
// the free surface and the walls, whose neighbourhoods are one-sided.
TEST(DisplayFields, UniformFieldsStayUniformUpToTheSurface) {
  const double dx = 0.01;
  std::vector<double> x, y, m, V, rho, pres;
  for (int j = 0; j < 14; ++j)
    for (int i = 4; i < 36; ++i) {
      x.push_back((i + 0.5) * dx / 2), y.push_back((j + 0.5) * dx / 2);
      m.push_back(0.6 * 2500 * dx * dx / 4), V.push_back(dx * dx / 4), rho.push_back(2500), pres.push_back(123.0);
    }
  ParticleView p;
  p.count = x.size();
  p.x_m = x.data(), p.y_m = y.data(), p.mass_kg = m.data(), p.volume_m2 = V.data();
  p.grain_density_kg_m3 = rho.data(), p.pressure_Pa = pres.data();
  const FieldFrame f = rasterize(p, {20, 10, dx, {0.0, 0.0}}, {"packing_fraction", "density", "pressure"});
  for (size_t c = 0; c < f.active.size(); ++c) {
    if (!f.active[c]) continue;
    EXPECT_NEAR(f.scalars.at("packing_fraction")[c], 0.6, 1e-6);
    EXPECT_NEAR(f.scalars.at("density")[c], 1500.0, 1e-3);
    EXPECT_NEAR(f.scalars.at("pressure")[c], 123.0, 1e-4);
  }
  EXPECT_EQ(std::count(f.active.begin(), f.active.end(), 1), 16 * 7);
}

// Points pulled apart behind a body's corner leave cells with no point inside the material: the
// kernel fills such a hole (and gives it its neighbours' values), but not a one-cell notch in the
// surface nor the cells above it, which hold no material.
TEST(DisplayFields, AHoleInsideIsFilledANotchInTheSurfaceIsNot) {
  const double dx = 0.01;
  const int nx = 12, ny = 12, top = 8, hole_i = 5, hole_j = 4, notch_i = 8;
  std::vector<double> x, y, m, V, pres;
  for (int j = 0; j < 2 * top; ++j)
    for (int i = 0; i < 2 * nx; ++i) {
      const int ci = i / 2, cj = j / 2;
      if ((ci == hole_i && cj == hole_j) || (ci == notch_i && cj == top - 1)) continue;
      x.push_back((i + 0.5) * dx / 2), y.push_back((j + 0.5) * dx / 2);
      m.push_back(1.0), V.push_back(dx * dx / 4), pres.push_back(50.0);
    }
  ParticleView p;
  p.count = x.size();
  p.x_m = x.data(), p.y_m = y.data(), p.mass_kg = m.data(), p.volume_m2 = V.data(), p.pressure_Pa = pres.data();
  const FieldFrame f = rasterize(p, {nx, ny, dx, {0.0, 0.0}}, {"pressure"});
  EXPECT_EQ(f.active[f.index(hole_i, hole_j)], 1);
  EXPECT_NEAR(f.scalars.at("pressure")[f.index(hole_i, hole_j)], 50.0, 1e-4);
  EXPECT_EQ(f.active[f.index(notch_i, top - 1)], 0);
  for (int i = 0; i < nx; ++i) EXPECT_EQ(f.active[f.index(i, top)], 0) << i;  // air stays air
  const FieldFrame cells = rasterize(p, {nx, ny, dx, {0.0, 0.0}, RasterTransfer::cell_average}, {"pressure"});
  EXPECT_EQ(cells.active[cells.index(hole_i, hole_j)], 0);  // the per-cell mask keeps the hole
}
