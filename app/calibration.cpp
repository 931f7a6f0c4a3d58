#include "app/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "app/progress.hpp"
#include "engine/io/atomic_file.hpp"
#include "engine/io/field_store.hpp"
#include "engine/scene/scene_io.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

namespace {

const char* kShapeFunctionNames[] = {"linear", "quadratic", "cubic"};

std::string model_of(const Scene& s) {
  bool dpm = false;
  for (const auto& m : s.materials) dpm = dpm || m.model == MaterialModel::DPM;
  return dpm && s.effects.dilatancy ? "dpm" : "ndpm";
}

}  // namespace

std::string calibration_path() {
  if (const char* p = std::getenv("FURROW_CALIBRATION"); p && *p) return p;
  if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return (fs::path(x) / "furrow" / "calibration.json").string();
  const char* home = std::getenv("HOME");
  return (fs::path(home && *home ? home : ".") / ".config" / "furrow" / "calibration.json").string();
}

std::optional<Calibration> load_calibration(std::string* why) {
  const std::string path = calibration_path();
  if (!fs::exists(path)) {
    if (why) *why = "no calibration at " + path;
    return std::nullopt;
  }
  try {
    std::ifstream in(path);
    const auto j = nlohmann::json::parse(in);
    Calibration c;
    c.path = path;
    c.host = j.value("host", "");
    c.cpu = j.value("cpu", "");
    c.date = j.value("date", "");
    c.particles = j.value("particles", size_t(0));
    c.size_exponent = j.value("size_exponent", 0.0);
    c.large_particles = j.value("large_particles", size_t(0));
    c.large_particle_steps_per_s = j.value("large_particle_steps_per_s", 0.0);
    for (const auto& e : j.at("entries"))
      c.entries.push_back({e.at("shape_function").get<std::string>(), e.at("model").get<std::string>(),
                           e.at("threads").get<int>(), e.at("particle_steps_per_s").get<double>()});
    return c;
  } catch (const std::exception& e) {
    if (why) *why = path + " cannot be read (" + e.what() + "); run `furrow bench` to remake it";
    return std::nullopt;
  }
}

void save_calibration(const Calibration& c) {
  nlohmann::json j;
  j["host"] = c.host;
  j["cpu"] = c.cpu;
  j["date"] = c.date;
  j["particles"] = c.particles;
  j["size_exponent"] = c.size_exponent;
  j["large_particles"] = c.large_particles;
  j["large_particle_steps_per_s"] = c.large_particle_steps_per_s;
  j["units"] = "particle_steps_per_s: particles times solver steps per wall second";
  j["entries"] = nlohmann::json::array();
  for (const auto& e : c.entries)
    j["entries"].push_back({{"shape_function", e.shape_function},
                            {"model", e.model},
                            {"threads", e.threads},
                            {"particle_steps_per_s", e.particle_steps_per_s}});
  fs::create_directories(fs::path(c.path).parent_path());
  write_file_atomic(c.path, j.dump(2) + "\n");
}

int run_threads(const Scene& scene) {
  return scene.solver.threads > 0 ? scene.solver.threads : int(std::max(1u, std::thread::hardware_concurrency()));
}

double predict_run_wall_s(const Calibration& c, const Scene& scene, std::string* how) {
  const std::string shape = kShapeFunctionNames[int(scene.solver.shape_function)], model = model_of(scene);
  const int threads = run_threads(scene);
  // the measured thread counts for this shape function and model, by threads
  std::vector<std::pair<int, double>> rates;
  for (const auto& e : c.entries)
    if (e.shape_function == shape && e.model == model && e.particle_steps_per_s > 0.0)
      rates.emplace_back(e.threads, e.particle_steps_per_s);
  if (rates.empty()) {
    if (how) *how = "the calibration has no figure for " + shape + " " + model;
    return std::numeric_limits<double>::quiet_NaN();
  }
  std::sort(rates.begin(), rates.end());
  double rate = rates.back().second;
  if (threads <= rates.front().first) {
    rate = rates.front().second;
  } else {
    for (size_t i = 1; i < rates.size(); ++i)
      if (threads <= rates[i].first) {
        const double a = double(threads - rates[i - 1].first) / double(rates[i].first - rates[i - 1].first);
        rate = (1.0 - a) * rates[i - 1].second + a * rates[i].second;
        break;
      }
  }
  const double psteps = estimate_particle_steps(scene);
  // smaller beds are not scaled up: below the bench size threading overheads, not caches, decide
  const double particles = double(estimate_particle_count(scene));
  if (c.particles > 0 && particles > double(c.particles))
    rate *= std::pow(particles / double(c.particles), std::clamp(c.size_exponent, -0.5, 0.0));
  if (how) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%d thread%s, %s %s at %.3g M particle-steps/s", threads, threads == 1 ? "" : "s",
                  shape.c_str(), model.c_str(), rate / 1e6);
    *how = buf;
    if (c.particles > 0 && particles > double(c.particles) && c.size_exponent < 0.0)
      *how += " for this bed's size";
  }
  return psteps / rate;
}

std::string predicted_wall_text(const Scene& scene) {
  std::string why;
  const auto c = load_calibration(&why);
  if (!c) return "unknown: " + why + "; `furrow bench` measures this machine in under a minute";
  std::string how;
  const double s = predict_run_wall_s(*c, scene, &how);
  if (!std::isfinite(s)) return "unknown: " + how + "; rerun `furrow bench`";
  std::string when = s < 60.0 ? std::to_string(int(std::ceil(s))) + " s" : "";
  if (s >= 60.0) {
    const long m = std::lround(s / 60.0);
    when = m >= 60 ? std::to_string(m / 60) + " h " + std::to_string(m % 60) + " min" : std::to_string(m) + " min";
  }
  return "~" + when + " of solver time on this machine (" + how + "; calibrated " + c->date + ")";
}

}  // namespace furrow::cli
