#include "render/colormap.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <vtkLookupTable.h>

namespace fs = std::filesystem;

namespace furrow::render {

namespace {
fs::path colormap_dir() {
  const char* env = std::getenv("FURROW_ASSET_DIR");
  return fs::path(env && *env ? env : FURROW_ASSET_DIR) / "colormaps";
}

Colormap parse_table(const std::string& name, const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot open colormap table");
  Colormap cm;
  cm.name = name;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "r,g,b") continue;
    std::array<float, 3> c{};
    std::istringstream ls(line);
    char comma1 = 0, comma2 = 0;
    if (!(ls >> c[0] >> comma1 >> c[1] >> comma2 >> c[2]) || comma1 != ',' || comma2 != ',')
      throw std::runtime_error(file.string() + ":" + std::to_string(line_no) + ": expected 'r,g,b', got '" + line + "'");
    for (float v : c)
      if (!(v >= 0.f && v <= 1.f))
        throw std::runtime_error(file.string() + ":" + std::to_string(line_no) + ": colour components must be in [0, 1]");
    cm.rgb.push_back(c);
  }
  if (cm.rgb.size() < 2) throw std::runtime_error(file.string() + ": colormap needs at least 2 entries");
  return cm;
}
}  // namespace

std::array<float, 3> Colormap::at(double t) const {
  if (!(t > 0)) t = 0;  // also NaN
  if (t > 1) t = 1;
  const size_t k = size_t(std::lround(t * double(rgb.size() - 1)));
  return rgb[k];
}

int Colormap::nearest_index(const unsigned char pixel[3], double* distance) const {
  int best = 0;
  double best_d2 = 1e300;
  for (size_t k = 0; k < rgb.size(); ++k) {
    double d2 = 0;
    for (int c = 0; c < 3; ++c) {
      const double d = double(pixel[c]) - 255.0 * rgb[k][c];
      d2 += d * d;
    }
    if (d2 < best_d2) best_d2 = d2, best = int(k);
  }
  if (distance) *distance = std::sqrt(best_d2);
  return best;
}

std::vector<std::string> colormap_names() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(colormap_dir(), ec))
    if (e.path().extension() == ".csv") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

const Colormap& load_colormap(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, Colormap> cache;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = cache.find(name); it != cache.end()) return it->second;
  const fs::path file = colormap_dir() / (name + ".csv");
  if (name.empty() || name.find('/') != std::string::npos || !fs::exists(file)) {
    std::string known;
    for (const auto& n : colormap_names()) known += (known.empty() ? "" : ", ") + n;
    throw std::runtime_error("unknown colormap '" + name + "' (known: " + (known.empty() ? "none found in " + colormap_dir().string() : known) + ")");
  }
  return cache.emplace(name, parse_table(name, file)).first->second;
}

void fill_lookup_table(const Colormap& cmap, vtkLookupTable* lut) {
  lut->SetNumberOfTableValues(vtkIdType(cmap.rgb.size()));
  for (size_t k = 0; k < cmap.rgb.size(); ++k)
    lut->SetTableValue(vtkIdType(k), cmap.rgb[k][0], cmap.rgb[k][1], cmap.rgb[k][2], 1.0);
}

}  // namespace furrow::render
