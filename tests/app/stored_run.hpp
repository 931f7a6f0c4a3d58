// A small stored run for CLI tests of `furrow render` and `furrow inspect`: frames/ written by the
// field store (a hydrostatic bed 0.4 x 0.25 m in 5 mm cells, material up to 0.2 m, a 0.1 m plate
// sinking 2 mm per frame, pressure x (1 + k/10) in frame k, 0.01 s apart) and a forces.csv.
#pragma once
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "engine/io/field_store.hpp"
#include "tests/render/synthetic_frames.hpp"

namespace furrow::cli_test {

struct StoredRun {
  static constexpr int kFrames = 4;
  static constexpr double kDx = 0.005, kSurface = 0.2, kPlateX0 = 0.15, kPlateX1 = 0.25;
  static double plate_bottom(int k) { return 0.19 - 0.002 * k; }

  std::vector<std::string> frames;
  explicit StoredRun(const std::filesystem::path& dir) {
    for (int k = 0; k < kFrames; ++k) {
      FieldFrame f = test::hydrostatic_frame(80, 50, kDx, kSurface, 0.01 * k);
      f.step = 100 * k;
      for (float& p : f.scalars["pressure"]) p *= float(1.0 + 0.1 * k);
      f.bodies.push_back(test::box_body("plate", kPlateX0, plate_bottom(k), kPlateX1, plate_bottom(k) + 0.02));
      frames.push_back(frame_path(dir.string(), k));
      write_frame_vdb(frames.back(), f);
    }
    std::ofstream csv(dir / "forces.csv");
    csv << "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m\n";
    for (int k = 0; k <= 30; ++k) csv << 0.001 * k << ",plate,0.2," << 0.2 - 0.0002 * k << ",0," << 40.0 * k << "\n";
  }
};

}  // namespace furrow::cli_test
