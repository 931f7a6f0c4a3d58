// Issue 13: the strain-rate frames of loose_intrusion show arcs of plastic shear rate
// (0.01-1 1/s) across the bed, two to three plate widths from the plate. They are the plate's
// bearing-failure mechanism in a weak loose bed, not elastic ringing: this file checks the
// signatures that separate the two explanations, on the template itself at a coarse dx.
//
// Why the mechanism is that large: loose poppy seeds (phi_d 0.55) have friction
// 0.53 + (0.55 - 0.60) 5 = 0.28 until sheared, mu_c 0.53 once compacted. Prandtl's mechanism
// under a strip of width B, with tan(phi) = mu, reaches 2 r1 cos(pi/4 - phi/2) past the plate's
// edge, r1 = B / (2 cos(pi/4 + phi/2)) exp(pi/2 tan(phi)): 2.0 B at mu 0.28 and 3.8 B at 0.53.
// Its log-spiral slip lines (nearly circles at these frictions) are centred on the plate's
// corners: the arcs. Measured (dx 2.5 mm, 20 mm into the bed) the flow reaches ~3 B, the same
// in a 0.5 m wide bed, so the side walls do not make it.
//
// What elastic ringing would do instead: waves radiated at the plate's force steps have strain
// ~ v/c, with c = sqrt(M / rho) ~ sqrt(E), so 16x E makes c 4x faster and such a rate ~4x less; they
// leave no lasting compaction; and they would also be there, from the geostatic start-up, with
// the plate held still. Plastic flow of a rate-independent mechanism does not depend on E (the
// elastic part is only "stiff enough"), and in the DPM it compacts the loose bed by
// d phi_d = chi phi_c (phi_c - phi_d) d gamma, which the open material then settles onto.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "engine/io/field_store.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"

using namespace furrow;

namespace {

constexpr double kDx = 0.005;      // 8 cells across the plate: the flow zone, without the arcs' texture
constexpr double kEnd = 0.14;      // plate 19 mm into the 0.2 m bed
constexpr double kFrom = 0.10;     // rates averaged over the frames of the last 0.04 s
constexpr double kFrame = 0.01;    // the template's frame interval
constexpr double kFarWidths = 1.5; // far field: more than 1.5 plate widths from the plate

struct FarField {
  double rate_1_s = 0.0;         // mean strain_rate over far cells, mean over frames in [kFrom, kEnd]
  double packing_start = 0.0;    // mean packing fraction of the far cells at t = 0 ...
  double packing_end = 0.0;      // ... and at the end
  double plastic_strain = 0.0;   // mean plastic strain of the far cells at the end
  double c_m_s = 0.0;
};

Scene template_scene(const std::vector<std::string>& sets) {
  std::vector<std::string> all = {"domain.dx_m=" + std::to_string(kDx), "solver.threads=1",
                                  "solver.end_time_s=" + std::to_string(kEnd)};
  all.insert(all.end(), sets.begin(), sets.end());
  return load_scene((std::filesystem::path(FURROW_SOURCE_DIR) / "scenes" / "loose_intrusion.json").string(), all);
}

// Far cells are fixed once, from the plate's box where it ends in the moving run, so every run
// and every frame averages over the same cells: active cells of the bed (below its top) more than
// kFarWidths plate widths from that box.
struct FarRegion {
  Vec2 lo, hi;  // plate box at kEnd in the moving run
  double bed_top_m = 0.0, reach_m = 0.0;
  static FarRegion of(const Scene& moving) {
    const Body& b = moving.bodies[0];
    const Vec2 centre = b.start_m + kEnd * b.motion.velocity_m_s;
    return {centre - 0.5 * b.shape.size_m, centre + 0.5 * b.shape.size_m, moving.beds[0].max_m.y(),
            kFarWidths * b.shape.size_m.x()};
  }
  bool contains(const FieldFrame& f, int i, int j) const {
    const double x = f.origin_m.x() + (i + 0.5) * f.dx_m, y = f.origin_m.y() + (j + 0.5) * f.dx_m;
    const double d = std::hypot(std::max({lo.x() - x, 0.0, x - hi.x()}), std::max({lo.y() - y, 0.0, y - hi.y()}));
    return d > reach_m && y < bed_top_m;
  }
  double mean(const FieldFrame& f, const std::string& field) const {
    const auto& v = f.scalars.at(field);
    double sum = 0.0;
    int n = 0;
    for (int j = 0; j < f.ny; ++j)
      for (int i = 0; i < f.nx; ++i)
        if (f.active[f.index(i, j)] && contains(f, i, j)) {
          sum += v[f.index(i, j)];
          ++n;
        }
    return n ? sum / n : 0.0;
  }
};

// Runs the scene and reads the far field off frames rasterized as run_scene stores them.
FarField run(const Scene& s, const FarRegion& far) {
  Simulation sim(s);
  RasterSpec r;
  r.nx = sim.grid().nx;
  r.ny = sim.grid().ny;
  r.dx_m = s.domain.dx_m;
  const std::vector<std::string> fields = {"strain_rate", "packing_fraction", "plastic_strain"};
  FarField out;
  out.c_m_s = sim.wave_speed_m_s();
  out.packing_start = far.mean(rasterize(sim.particle_view(), r, fields), "packing_fraction");
  double next = kFrame, rate_sum = 0.0;
  int frames = 0;
  FieldFrame last;
  while (!sim.finished()) {
    sim.step();
    if (sim.time_s() < next - 1e-12 && !sim.finished()) continue;
    next += kFrame;
    last = rasterize(sim.particle_view(), r, fields);
    if (sim.time_s() >= kFrom - 1e-9) {
      rate_sum += far.mean(last, "strain_rate");
      ++frames;
    }
  }
  out.rate_1_s = frames ? rate_sum / frames : 0.0;
  out.packing_end = far.mean(last, "packing_fraction");
  out.plastic_strain = far.mean(last, "plastic_strain");
  return out;
}

}  // namespace

TEST(LooseIntrusionFarField, ArcsArePlasticFlowThatCompactsNotElasticRinging) {
  const std::string E16 = "materials.poppy_seeds.youngs_modulus_Pa=3.2e7";  // template: 2e6
  const std::string held = "bodies.plate.motion.velocity_m_s=[0,0]";
  const Scene moving = template_scene({});
  const FarRegion far = FarRegion::of(moving);
  FarField base, stiff, still, ringing;
  // the stiff run (4x the steps) takes about as long as the other three together: its own thread
  std::thread t([&] { stiff = run(template_scene({E16}), far); });
  base = run(moving, far);
  still = run(template_scene({held, "solver.end_displacement_m=null"}), far);
  // control: a bed started stress-free settles and rings (scenes/README.md, beds[].geostatic)
  ringing = run(template_scene({held, "solver.end_displacement_m=null", "beds.0.geostatic=false"}), far);
  t.join();
  const double v = moving.bodies[0].motion.velocity_m_s.norm(), L = moving.bodies[0].shape.size_m.x();
  RecordProperty("far_rate_E", std::to_string(base.rate_1_s));
  RecordProperty("far_rate_16E", std::to_string(stiff.rate_1_s));
  RecordProperty("far_rate_held", std::to_string(still.rate_1_s));
  RecordProperty("far_rate_held_stress_free_start", std::to_string(ringing.rate_1_s));
  std::printf("far-field plastic rate: E %.4g, 16E %.4g, plate held %.3g, held from stress-free %.3g 1/s (c %.1f, %.1f m/s)\n",
              base.rate_1_s, stiff.rate_1_s, still.rate_1_s, ringing.rate_1_s, base.c_m_s, stiff.c_m_s);
  ASSERT_NEAR(stiff.c_m_s / base.c_m_s, 4.0, 1e-9);

  // 1. The plate makes it: held still (2 mm above the bed), the bed after its geostatic start
  //    shows nothing a user would see. The renderer's log scale spans four decades below its top,
  //    which for a moving plate is of order v/L; measured ~1e-7 1/s.
  EXPECT_LT(still.rate_1_s, 1e-4 * v / L);
  // and with the plate it is far above that floor (measured ~0.09 1/s at this dx)
  EXPECT_GT(base.rate_1_s, 1e-2 * v / L);
  // The metric does see ringing when there is some: started stress-free, the bed still rings
  // at 0.1 s and yields where the waves overload it (measured 4e-4 1/s, 2500x the geostatic
  // start, and 12x less at 16x E, as waves should) -- yet 200x below the plate's far field.
  EXPECT_GT(ringing.rate_1_s, 100.0 * still.rate_1_s);
  EXPECT_LT(ringing.rate_1_s, 0.1 * base.rate_1_s);

  // 2. Not elastic: ringing would fall ~4x with 16x E. The bounds sit halfway (in log) between
  //    no dependence (1) and the wave prediction (4), either way; measured ratio ~0.93.
  const double ratio = base.rate_1_s / stiff.rate_1_s;
  EXPECT_LT(ratio, 2.0) << "E " << base.rate_1_s << ", 16E " << stiff.rate_1_s;
  EXPECT_GT(ratio, 0.5) << "E " << base.rate_1_s << ", 16E " << stiff.rate_1_s;

  // 3. It leaves compaction, the same for both E, and as much as the DPM law gives for the plastic
  //    strain the far cells record: d phi = chi phi_c (phi_c - phi_i) gamma = 5 0.6 0.05 gamma
  //    (gamma << 1/(chi phi_c)). 25%: phi trails phi_d while open material settles, and the cell
  //    means mix particles of different strain; measured 1.04 (E) and 0.95 (16E).
  const double chi = moving.materials[0].chi, phi_c = moving.materials[0].phi_c,
               phi_i = moving.beds[0].packing_fraction;
  for (const FarField* f : {&base, &stiff}) {
    const double dphi = f->packing_end - f->packing_start;
    const double law = chi * phi_c * (phi_c - phi_i) * f->plastic_strain;
    std::printf("far field: plastic strain %.4g, compaction %.3g, law %.3g\n", f->plastic_strain, dphi, law);
    EXPECT_GT(f->plastic_strain, 0.0);
    EXPECT_NEAR(dphi / law, 1.0, 0.25) << "d phi " << dphi << ", law " << law;
  }
  const double dphi_ratio = (base.packing_end - base.packing_start) / (stiff.packing_end - stiff.packing_start);
  EXPECT_NEAR(dphi_ratio, 1.0, 0.25);
}
