#include "engine/run.hpp"

#include <sys/resource.h>
#include <tbb/info.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "engine/analysis.hpp"
#include "engine/field_store.hpp"
#include "engine/scene_io.hpp"
#include "engine/simulation.hpp"

namespace fs = std::filesystem;

namespace furrow {

size_t peak_resident_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return size_t(u.ru_maxrss) * 1024;  // Linux reports KiB
}

nlohmann::json result_defining_json(const Scene& scene) {
  Scene s = scene;
  s.solver.threads = 0;
  return scene_to_json(s);
}

std::string scene_hash(const Scene& scene) {
  uint64_t h = 14695981039346656037ull;  // FNV-1a 64 offset basis and prime
  for (const unsigned char c : result_defining_json(scene).dump()) h = (h ^ c) * 1099511628211ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

namespace {

// Averages forces over output intervals and writes one CSV row per body per interval.
class ForceLog {
 public:
  ForceLog(const std::string& path, const Scene& s) : out_(path), interval_s_(s.outputs.force_interval_s) {
    if (!out_) throw std::runtime_error(path + ": cannot open for writing");
    out_ << "t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m\n";
    sum_.assign(s.bodies.size(), Vec2(0, 0));
    for (const auto& b : s.bodies) names_.push_back(b.name);
  }
  void add(const Simulation& sim) {
    const auto& bodies = sim.bodies();
    if (bodies.empty()) return;
    const double dt = sim.last_dt_s();
    for (size_t b = 0; b < bodies.size(); ++b) sum_[b] += bodies[b].force_N_per_m * dt;
    span_s_ += dt;
    if (span_s_ >= interval_s_ - 1e-15) flush(sim);
  }
  void flush(const Simulation& sim) {
    if (span_s_ <= 0.0) return;
    char line[256];
    for (size_t b = 0; b < sum_.size(); ++b) {
      const Vec2 f = sum_[b] / span_s_;
      const Vec2 x = sim.bodies()[b].position_m;
      std::snprintf(line, sizeof line, "%.9g,%s,%.9g,%.9g,%.9g,%.9g\n", sim.time_s(), names_[b].c_str(),
                    x.x(), x.y(), f.x(), f.y());
      out_ << line;
      sum_[b].setZero();
    }
    span_s_ = 0.0;
  }
  void close() {
    out_.close();
    if (!out_) throw std::runtime_error("forces.csv: write failed");
  }

 private:
  std::ofstream out_;
  double interval_s_ = 0.0, span_s_ = 0.0;
  std::vector<Vec2> sum_;
  std::vector<std::string> names_;
};

// Running per-body statistics for the summary: mean over the averaging window, peaks.
class ForceStats {
 public:
  explicit ForceStats(const Scene& s) : out_(s.outputs) {
    for (const auto& b : s.bodies) {
      BodyForceSummary f;
      f.name = b.name;
      bodies_.push_back(f);
    }
    sums_.assign(s.bodies.size(), Vec2(0, 0));
  }
  void add(const Simulation& sim) {
    const double t = sim.time_s(), d = sim.lead_body_travel_m(), dt = sim.last_dt_s();
    const bool in_window = in_average_window(out_, t, d);
    for (size_t b = 0; b < bodies_.size(); ++b) {
      const Vec2 f = sim.bodies()[b].force_N_per_m;
      auto& s = bodies_[b];
      for (int c = 0; c < 2; ++c)
        if (std::abs(f[c]) > std::abs(s.peak_N_per_m[c])) s.peak_N_per_m[c] = f[c];
      if (in_window) {
        sums_[b] += f * dt;
        ++s.window_samples;
      }
    }
    if (in_window) window_s_ += dt;
  }
  std::vector<BodyForceSummary> finish() {
    for (size_t b = 0; b < bodies_.size(); ++b)
      bodies_[b].mean_N_per_m = window_s_ > 0.0 ? Vec2(sums_[b] / window_s_)
                                                : Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
    return bodies_;
  }

 private:
  const Outputs& out_;
  std::vector<BodyForceSummary> bodies_;
  std::vector<Vec2> sums_;
  double window_s_ = 0.0;
};

nlohmann::json vec_json(const Vec2& v) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  return nlohmann::json::array({num(v.x()), num(v.y())});
}

}  // namespace

RunSummary run_scene(const Scene& scene, const RunOptions& opt) {
  using clock = std::chrono::steady_clock;
  if (opt.out_dir.empty()) throw std::invalid_argument("run_scene: no output directory given");
  const fs::path final_dir = fs::absolute(opt.out_dir).lexically_normal();
  if (fs::exists(final_dir) && !opt.force)
    throw std::runtime_error(final_dir.string() + " already exists: choose another --out or pass --force to replace it");
  const fs::path tmp_dir = final_dir.string() + ".partial-" + std::to_string(getpid());
  fs::remove_all(tmp_dir);
  fs::create_directories(tmp_dir / "frames");

  write_file_atomic((tmp_dir / "scene.json").string(), format_scene(scene));

  const auto wall0 = clock::now();
  Simulation sim(scene);
  ForceLog forces((tmp_dir / "forces.csv").string(), scene);
  ForceStats stats(scene);
  RunAnalysis analysis(scene);  // run.json "analysis": drag statistics, wedge per frame
  CollapseAnalysis collapse(scene);  // run.json "collapse": runout and height of a released column

  const auto& out = scene.outputs;
  std::vector<std::string> fields;
  for (const auto& f : out.fields) fields.push_back(f);
  const bool frames_on = out.frame_interval_s > 0.0 && !fields.empty();
  RasterSpec raster;
  raster.nx = sim.grid().nx;
  raster.ny = sim.grid().ny;
  raster.dx_m = scene.domain.dx_m;
  std::vector<PvdEntry> pvd;
  int64_t frame_index = 0;
  double next_frame_s = 0.0;
  auto write_frame = [&] {
    FieldFrame f = rasterize(sim.particle_view(), raster, fields);
    f.scene_name = scene.name;
    f.step = sim.step_count();
    f.time_s = sim.time_s();
    f.dt_s = sim.last_dt_s();
    f.bodies = sim.body_outlines();
    if (analysis.wants_frames())
      analysis.add_frame(f, sim.lead_body_travel_m(), sim.bodies()[size_t(analysis.lead_index())].velocity_m_s);
    write_frame_vdb(frame_path(tmp_dir.string(), frame_index), f);
    if (opt.frame_written) opt.frame_written(frame_index, frame_path(tmp_dir.string(), frame_index));
    if (opt.write_paraview) {
      write_vti(frame_path(tmp_dir.string(), frame_index, "vti"), f);
      pvd.push_back({f.time_s, fs::relative(frame_path(tmp_dir.string(), frame_index, "vti"), tmp_dir).string()});
    }
    ++frame_index;
    next_frame_s += out.frame_interval_s;
  };

  // progress: the end is whichever criterion comes first
  const double end_t = scene.solver.end_time_s, end_d = scene.solver.end_displacement_m;
  auto fraction = [&] {
    double f = end_t > 0.0 ? sim.time_s() / end_t : 0.0;
    if (end_d > 0.0) f = std::max(f, sim.lead_body_travel_m() / end_d);
    return std::min(f, 1.0);
  };
  double dt_min = std::numeric_limits<double>::max(), dt_max = 0.0;
  auto last_report = clock::now();
  auto report = [&](bool force_report) {
    if (!opt.progress) return;
    const auto now = clock::now();
    if (!force_report && std::chrono::duration<double>(now - last_report).count() < opt.progress_interval_s) return;
    last_report = now;
    RunProgress p;
    p.fraction = fraction();
    p.time_s = sim.time_s();
    p.steps = sim.step_count();
    p.wall_s = std::chrono::duration<double>(now - wall0).count();
    p.eta_s = p.fraction > 0.01 ? p.wall_s * (1.0 - p.fraction) / p.fraction : -1.0;
    p.particles = sim.particles().size();
    p.dt_s = sim.last_dt_s();
    opt.progress(p);
  };

  if (frames_on) write_frame();
  if (collapse.active()) collapse.add_step(0.0, sim.particle_view());
  const auto loop0 = clock::now();
  int64_t contact_sweeps = 0, contact_unconverged = 0, contact_points_max = 0;
  int contact_sweeps_max = 0;
  double contact_residual_max = 0.0;
  while (!sim.finished()) {
    sim.step();
    const StepStats& st = sim.stats();
    contact_sweeps += st.contact_sweeps;
    contact_sweeps_max = std::max(contact_sweeps_max, st.contact_sweeps);
    contact_points_max = std::max(contact_points_max, st.contact_points);
    contact_unconverged += st.contact_converged ? 0 : 1;
    contact_residual_max = std::max(contact_residual_max, st.contact_residual_m_s);
    dt_min = std::min(dt_min, sim.last_dt_s());
    dt_max = std::max(dt_max, sim.last_dt_s());
    forces.add(sim);
    stats.add(sim);
    if (analysis.active()) {
      const BodyState& lead = sim.bodies()[size_t(analysis.lead_index())];
      analysis.add_step(sim.time_s(), sim.lead_body_travel_m(), lead.force_N_per_m, lead.velocity_m_s);
    }
    if (frames_on && sim.time_s() >= next_frame_s - 1e-12) write_frame();
    if (collapse.active()) collapse.add_step(sim.time_s(), sim.particle_view());
    report(false);
  }
  const double loop_s = std::chrono::duration<double>(clock::now() - loop0).count();
  if (collapse.active()) collapse.add_step(sim.time_s(), sim.particle_view(), true);
  forces.flush(sim);
  forces.close();
  report(true);
  if (opt.write_paraview && !pvd.empty()) write_pvd((tmp_dir / "frames.pvd").string(), pvd);

  RunSummary summary;
  summary.bodies = stats.finish();
  const double wall_s = std::chrono::duration<double>(clock::now() - wall0).count();
  const double psteps = double(sim.particles().size()) * double(sim.step_count());
  auto& j = summary.run_json;
  j["scene"] = scene.name;
  j["scene_hash"] = scene_hash(scene);
  j["particles"] = sim.particles().size();
  j["grid_nodes"] = sim.grid().node.size();
  j["steps"] = sim.step_count();
  j["end_time_s"] = sim.time_s();
  j["dt_min_s"] = sim.step_count() ? dt_min : 0.0;
  j["dt_max_s"] = dt_max;
  j["wave_speed_m_s"] = sim.wave_speed_m_s();
  j["wall_seconds"] = wall_s;
  j["solver_seconds"] = loop_s;
  j["particle_steps_per_second"] = loop_s > 0.0 ? psteps / loop_s : 0.0;
  j["threads"] = scene.solver.threads > 0 ? scene.solver.threads : tbb::info::default_concurrency();
  j["peak_resident_bytes"] = peak_resident_bytes();
  const PhaseSeconds& ph = sim.phase_seconds();
  j["phase_seconds"] = {{"sort", ph.sort}, {"p2g", ph.p2g}, {"grid", ph.grid}, {"contact", ph.contact},
                        {"g2p", ph.g2p}, {"constitutive", ph.constitutive},
                        {"g2p_constitutive", ph.g2p_constitutive}, {"reorder", ph.reorder}};
  j["state_bytes_per_particle"] = sim.particles().size() ? double(sim.state_bytes()) / sim.particles().size() : 0.0;
  j["state_precision"] = FURROW_FLOAT_STATE ? "float stress, pressure, mass, affine matrix, strain rate" : "double";
  j["frames"] = frame_index;
  j["lead_body_travel_m"] = sim.lead_body_travel_m();
  j["units"] = {{"force", "N/m (per metre out of plane)"}, {"time", "s"}, {"length", "m"}};
  for (const auto& b : summary.bodies)
    j["bodies"].push_back({{"name", b.name},
                           {"mean_force_N_per_m", vec_json(b.mean_N_per_m)},
                           {"peak_force_N_per_m", vec_json(b.peak_N_per_m)},
                           {"window_steps", b.window_samples}});
  if (analysis.active()) j["analysis"] = analysis.to_json();
  if (collapse.active()) j["collapse"] = collapse.to_json();
  if (!scene.bodies.empty() && scene.solver.contact == ContactMethod::Particle)
    j["contact"] = {{"method", "particle"},
                    {"points_max", contact_points_max},
                    {"sweeps_mean", sim.step_count() ? double(contact_sweeps) / double(sim.step_count()) : 0.0},
                    {"sweeps_max", contact_sweeps_max},
                    {"steps_not_converged", contact_unconverged},
                    {"last_sweep_change_max_m_s", contact_residual_max}};
  write_file_atomic((tmp_dir / "run.json").string(), j.dump(2) + "\n");

  // move into place; an existing run (only with --force) is replaced after the new one is whole
  if (fs::exists(final_dir)) {
    const fs::path old = final_dir.string() + ".replaced-" + std::to_string(getpid());
    fs::rename(final_dir, old);
    fs::rename(tmp_dir, final_dir);
    fs::remove_all(old);
  } else {
    fs::create_directories(final_dir.parent_path());
    fs::rename(tmp_dir, final_dir);
  }
  summary.out_dir = final_dir.string();
  return summary;
}

}  // namespace furrow
