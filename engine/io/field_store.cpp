// Rasterization of particles onto cells and frame file naming.
#include "engine/io/field_store.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace fs = std::filesystem;

namespace furrow {

namespace {

// Fields that are plain mass-weighted particle averages, and the particle array each one comes
// from. velocity, packing_fraction and density have their own rules in rasterize().
struct AveragedField {
  const char* name;
  ScalarArray ParticleView::*array;
};
const AveragedField kAveraged[] = {
    {"pressure", &ParticleView::pressure_Pa},
    {"strain_rate", &ParticleView::strain_rate_1_s},
    {"plastic_strain", &ParticleView::plastic_strain},
    {"phi_d", &ParticleView::phi_d},
};
constexpr int kMaxAveraged = int(std::size(kAveraged));
constexpr double kFillFraction = 0.4;

std::string known_field_names() {
  std::string s;
  for (const auto& f : field_registry()) s += (s.empty() ? "" : ", ") + f.name;
  return s;
}

void require_array(const ScalarArray& a, const std::string& field, const char* array) {
  if (!a)
    throw std::invalid_argument("rasterize: field '" + field + "' requested but the particle array '" +
                                array + "' is not provided");
}

}  // namespace

FieldFrame rasterize(const ParticleView& p, const RasterSpec& spec,
                     const std::vector<std::string>& fields) {
  if (spec.nx <= 0 || spec.ny <= 0 || !(spec.dx_m > 0.0) || !std::isfinite(spec.dx_m) ||
      !spec.origin_m.allFinite())
    throw std::invalid_argument("rasterize: RasterSpec needs nx, ny > 0 and a finite dx_m > 0");
  const int64_t ncell64 = int64_t(spec.nx) * spec.ny;
  if (ncell64 >= std::numeric_limits<int32_t>::max())
    throw std::invalid_argument("rasterize: grid of " + std::to_string(ncell64) + " cells is too large");
  if (p.count >= size_t(std::numeric_limits<uint32_t>::max()))
    throw std::invalid_argument("rasterize: too many particles");
  if (p.count > 0 && (!p.x_m || !p.y_m || !p.mass_kg || !p.volume_m2))
    throw std::invalid_argument("rasterize: particle positions, mass and volume are required");

  // resolve the request against the registry
  bool want_velocity = false, want_packing = false, want_density = false;
  std::vector<std::pair<std::string, ScalarArray>> averaged;
  for (const auto& name : fields) {
    if (!find_field(name))
      throw std::invalid_argument("rasterize: unknown field '" + name + "' (known: " +
                                  known_field_names() + ")");
    if (name == "velocity") {
      require_array(p.vx_m_s, name, "vx_m_s");
      require_array(p.vy_m_s, name, "vy_m_s");
      want_velocity = true;
    } else if (name == "packing_fraction") {
      require_array(p.grain_density_kg_m3, name, "grain_density_kg_m3");
      want_packing = true;
    } else if (name == "density") {
      want_density = true;
    } else {
      const AveragedField* rule = nullptr;
      for (const auto& a : kAveraged)
        if (name == a.name) rule = &a;
      if (!rule) throw std::logic_error("rasterize: registry field '" + name + "' has no rule");
      require_array(p.*(rule->array), name, name.c_str());
      bool dup = false;
      for (const auto& a : averaged) dup |= a.first == name;
      if (!dup) averaged.emplace_back(name, p.*(rule->array));
    }
  }

  FieldFrame f;
  f.nx = spec.nx;
  f.ny = spec.ny;
  f.dx_m = spec.dx_m;
  f.origin_m = spec.origin_m;
  const size_t ncell = size_t(ncell64);
  f.active.assign(ncell, 0);

  // counting sort of particles by cell keeps each cell's sum in particle order (deterministic)
  const size_t n = p.count;
  std::vector<int32_t> cell(n);
  const double inv_dx = 1.0 / spec.dx_m;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const double fx = (p.x_m[k] - spec.origin_m.x()) * inv_dx;
      const double fy = (p.y_m[k] - spec.origin_m.y()) * inv_dx;
      // written so that NaN lands outside
      if (!(fx >= 0.0 && fx < spec.nx && fy >= 0.0 && fy < spec.ny)) {
        cell[k] = -1;
        continue;
      }
      cell[k] = int32_t(std::min(int(fy), spec.ny - 1)) * spec.nx + std::min(int(fx), spec.nx - 1);
    }
  });
  std::vector<uint32_t> start(ncell + 1, 0);
  for (size_t k = 0; k < n; ++k)
    if (cell[k] >= 0) ++start[size_t(cell[k]) + 1];
  for (size_t c = 0; c < ncell; ++c) start[c + 1] += start[c];
  std::vector<uint32_t> order(start[ncell]);
  {
    std::vector<uint32_t> next(start.begin(), start.end() - 1);
    for (size_t k = 0; k < n; ++k)
      if (cell[k] >= 0) order[next[size_t(cell[k])]++] = uint32_t(k);
  }

  // outputs (map nodes do not move, so raw pointers stay valid)
  auto output = [&](const std::string& name) {
    auto& v = f.scalars[name];
    v.assign(ncell, 0.0f);
    return v.data();
  };
  float* out_packing = want_packing ? output("packing_fraction") : nullptr;
  float* out_density = want_density ? output("density") : nullptr;
  float* out_avg[kMaxAveraged] = {};
  const int navg = int(averaged.size());
  for (int a = 0; a < navg; ++a) out_avg[a] = output(averaged[a].first);
  if (want_velocity) {
    f.velocity_x.assign(ncell, 0.0f);
    f.velocity_y.assign(ncell, 0.0f);
  }

  // quadratic B-spline of an offset in cells (support 1.5 cells each side)
  auto bspline = [](double d) {
    d = std::fabs(d);
    return d < 0.5 ? 0.75 - d * d : d < 1.5 ? 0.5 * (1.5 - d) * (1.5 - d) : 0.0;
  };
  const bool smooth = spec.transfer == RasterTransfer::quadratic_bspline;
  const int reach = smooth ? 1 : 0;  // neighbour cells whose points can weigh on a cell
  tbb::parallel_for(tbb::blocked_range<size_t>(0, ncell, 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t c = r.begin(); c != r.end(); ++c) {
      const bool holds_points = start[c] != start[c + 1];
      if (!holds_points && !smooth) continue;  // inactive
      const int ci = int(c % size_t(spec.nx)), cj = int(c / size_t(spec.nx));
      const double xc = spec.origin_m.x() + (ci + 0.5) * spec.dx_m, yc = spec.origin_m.y() + (cj + 0.5) * spec.dx_m;
      double m = 0, vol = 0, grain_vol = 0, mvx = 0, mvy = 0, mq[kMaxAveraged] = {};
      for (int nj = std::max(cj - reach, 0); nj <= std::min(cj + reach, spec.ny - 1); ++nj)
        for (int ni = std::max(ci - reach, 0); ni <= std::min(ci + reach, spec.nx - 1); ++ni) {
          const size_t nc = size_t(nj) * size_t(spec.nx) + size_t(ni);
          for (uint32_t s = start[nc]; s < start[nc + 1]; ++s) {
            const uint32_t k = order[s];
            const double w = smooth ? bspline((p.x_m[k] - xc) * inv_dx) * bspline((p.y_m[k] - yc) * inv_dx) : 1.0;
            const double mk = w * p.mass_kg[k];
            m += mk;
            vol += w * p.volume_m2[k];
            if (want_packing) grain_vol += w * p.grain_density_kg_m3[k] * p.volume_m2[k];
            if (want_velocity) {
              mvx += mk * p.vx_m_s[k];
              mvy += mk * p.vy_m_s[k];
            }
            for (int a = 0; a < navg; ++a) mq[a] += mk * averaged[a].second[k];
          }
        }
      if (!(m > 0.0)) continue;  // massless points only: inactive
      // an empty cell inside the material (points pulled apart behind a body's corner) is filled
      // when the kernel finds more than kFillFraction of a cell's volume around it: an empty cell
      // ringed by full ones finds 0.53, one above a flat surface 0.16, a one-cell notch 0.37
      if (!holds_points && !(vol >= kFillFraction * spec.dx_m * spec.dx_m)) continue;
      f.active[c] = 1;
      if (out_packing) out_packing[c] = grain_vol > 0.0 ? float(m / grain_vol) : 0.0f;
      if (out_density) out_density[c] = vol > 0.0 ? float(m / vol) : 0.0f;
      if (want_velocity) {
        f.velocity_x[c] = float(mvx / m);
        f.velocity_y[c] = float(mvy / m);
      }
      for (int a = 0; a < navg; ++a) out_avg[a][c] = float(mq[a] / m);
    }
  });
  return f;
}

std::string frame_path(const std::string& run_dir, int64_t index, const std::string& ext) {
  if (index < 0) throw std::invalid_argument("frame_path: negative frame index");
  char name[48];
  std::snprintf(name, sizeof name, "frame_%05lld.", static_cast<long long>(index));
  return (fs::path(run_dir) / "frames" / (name + ext)).string();
}

std::vector<std::string> list_frames(const std::string& run_dir) {
  const fs::path dir = fs::path(run_dir) / "frames";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw std::runtime_error("list_frames: no frames folder " + dir.string());
  std::vector<std::pair<long long, std::string>> found;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    const std::string pre = "frame_", suf = ".vdb";
    if (name.size() <= pre.size() + suf.size() || name.compare(0, pre.size(), pre) != 0 ||
        name.compare(name.size() - suf.size(), suf.size(), suf) != 0)
      continue;
    const std::string digits = name.substr(pre.size(), name.size() - pre.size() - suf.size());
    if (digits.size() > 18 || !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) continue;
    found.emplace_back(std::stoll(digits), e.path().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> paths;
  for (auto& f : found) paths.push_back(std::move(f.second));
  return paths;
}

}  // namespace furrow
