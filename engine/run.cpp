#include "engine/run.hpp"

#include <dlfcn.h>
#include <signal.h>
#include <sys/resource.h>
#include <tbb/info.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "engine/analysis.hpp"
#include "engine/io/atomic_file.hpp"
#include "engine/io/field_store.hpp"
#include "engine/io/point_store.hpp"
#include "engine/scene/scene_io.hpp"
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
  s.outputs.movies.clear();  // drawn from the stored frames after the run; a sweep skips them
  nlohmann::json j = scene_to_json(s);
  j["outputs"].erase("layout");  // drawn from the stored frames too; scenes keep the hash they had before it
  // the key's absence reads as false: scenes without points keep the hash they had before it
  if (!s.outputs.points) j["outputs"].erase("points");
  return j;
}

bool process_running(long pid) { return pid > 0 && (::kill(pid_t(pid), 0) == 0 || errno == EPERM); }

std::vector<std::string> checkpoint_dirs(const std::string& out_dir) {
  const fs::path final_dir = fs::absolute(out_dir).lexically_normal();
  const std::string prefix = final_dir.filename().string() + ".partial-";
  std::vector<std::string> found;
  if (!fs::is_directory(final_dir.parent_path())) return found;
  for (const auto& e : fs::directory_iterator(final_dir.parent_path())) {
    if (e.path().filename().string().rfind(prefix, 0) != 0) continue;
    // a crash between the two renames of save_checkpoint leaves only checkpoint.old: still whole
    if (!fs::exists(e.path() / "checkpoint") && fs::exists(e.path() / "checkpoint.old" / "run.json"))
      fs::rename(e.path() / "checkpoint.old", e.path() / "checkpoint");
    if (fs::exists(e.path() / "checkpoint" / "run.json")) found.push_back(e.path().string());
  }
  std::sort(found.begin(), found.end());
  return found;
}

namespace {
// FNV-1a 64 of bytes as 16 hex digits
std::string fnv1a_hex(const std::string& bytes) {
  uint64_t h = 14695981039346656037ull;  // FNV-1a 64 offset basis and prime
  for (const unsigned char c : bytes) h = (h ^ c) * 1099511628211ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}
}  // namespace

std::string scene_hash(const Scene& scene) { return fnv1a_hex(result_defining_json(scene).dump()); }

// Defined (from a hash of the engine library) by the CLI and the Python module, which link the same
// engine and so continue each other's checkpoints; absent in other programs (weak: null there).
extern "C" const char* furrow_engine_build_hash() __attribute__((weak));

const std::string& build_id() {
  static const std::string id = [] {
    if (furrow_engine_build_hash) return std::string(FURROW_VERSION) + "-" + furrow_engine_build_hash();
    // the file holding this code: the executable, or the Python module (a shared object) that
    // links the engine, so a checkpoint names that module's build and not the interpreter's
    std::string file = "/proc/self/exe";
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&build_id), &info) && info.dli_fname &&
        std::string(info.dli_fname).find(".so") != std::string::npos)
      file = info.dli_fname;
    std::ifstream in(file, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return std::string(FURROW_VERSION) + "-" + (in ? fnv1a_hex(bytes.str()) : std::string("unknown"));
  }();
  return id;
}

namespace {

// Averages forces over output intervals and writes one CSV row per body per interval.
class ForceLog {
 public:
  // state: a checkpoint's, to append after the rows it had written; null for a new file
  ForceLog(const std::string& path, const Scene& s, const nlohmann::json& state)
      : path_(path), interval_s_(s.outputs.force_interval_s) {
    sum_.assign(s.bodies.size(), Vec2(0, 0));
    torque_sum_.assign(s.bodies.size(), 0.0);
    for (const auto& b : s.bodies) names_.push_back(b.name);
    if (state.is_null()) {
      out_.open(path, std::ios::trunc);
      out_ << kForcesHeader << "\n";
    } else {
      fs::resize_file(path, state.at("bytes").get<uintmax_t>());
      out_.open(path, std::ios::app);
      span_s_ = state.at("span_s").get<double>();
      for (size_t b = 0; b < sum_.size(); ++b) sum_[b] = Vec2(state.at("sum")[b][0], state.at("sum")[b][1]);
      if (state.contains("torque_sum"))
        for (size_t b = 0; b < sum_.size(); ++b) torque_sum_[b] = state.at("torque_sum")[b].get<double>();
    }
    if (!out_) throw std::runtime_error(path + ": cannot open for writing");
  }
  void add(const Simulation& sim) {
    const auto& bodies = sim.bodies();
    if (bodies.empty()) return;
    const double dt = sim.last_dt_s();
    for (size_t b = 0; b < bodies.size(); ++b) {
      sum_[b] += bodies[b].force_N_per_m * dt;
      torque_sum_[b] += bodies[b].torque_N * dt;
    }
    span_s_ += dt;
    if (span_s_ >= interval_s_ - 1e-15) flush(sim);
  }
  void flush(const Simulation& sim) {
    if (span_s_ <= 0.0) return;
    char line[512];
    for (size_t b = 0; b < sum_.size(); ++b) {
      const Vec2 f = sum_[b] / span_s_;
      const BodyState& body = sim.bodies()[b];
      const Vec2 x = body.position_m, v = body.velocity_m_s;
      std::snprintf(line, sizeof line, "%.9g,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", sim.time_s(),
                    names_[b].c_str(), x.x(), x.y(), f.x(), f.y(), torque_sum_[b] / span_s_,
                    body.angle_rad * 180.0 / M_PI, v.x(), v.y(), body.omega_rad_s);
      out_ << line;
      sum_[b].setZero();
      torque_sum_[b] = 0.0;
    }
    span_s_ = 0.0;
  }
  nlohmann::json state() {
    out_.flush();
    if (!out_) throw std::runtime_error(path_ + ": write failed");
    nlohmann::json sum = nlohmann::json::array();
    for (const Vec2& v : sum_) sum.push_back({v.x(), v.y()});
    return {{"bytes", fs::file_size(path_)}, {"span_s", span_s_}, {"sum", sum}, {"torque_sum", torque_sum_}};
  }
  void close() {
    out_.close();
    if (!out_) throw std::runtime_error("forces.csv: write failed");
  }

 private:
  std::string path_;
  std::ofstream out_;
  double interval_s_ = 0.0, span_s_ = 0.0;
  std::vector<Vec2> sum_;
  std::vector<double> torque_sum_;
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
    torque_sums_.assign(s.bodies.size(), 0.0);
  }
  void add(const Simulation& sim) {
    const double t = sim.time_s(), d = sim.lead_body_travel_m(), dt = sim.last_dt_s();
    const bool in_window = in_average_window(out_, t, d);
    for (size_t b = 0; b < bodies_.size(); ++b) {
      const Vec2 f = sim.bodies()[b].force_N_per_m;
      auto& s = bodies_[b];
      for (int c = 0; c < 2; ++c)
        if (std::abs(f[c]) > std::abs(s.peak_N_per_m[c])) s.peak_N_per_m[c] = f[c];
      const double torque = sim.bodies()[b].torque_N;
      if (std::abs(torque) > std::abs(s.peak_torque_N)) s.peak_torque_N = torque;
      if (in_window) {
        sums_[b] += f * dt;
        torque_sums_[b] += torque * dt;
        ++s.window_samples;
      }
    }
    if (in_window) window_s_ += dt;
  }
  nlohmann::json state() const {
    nlohmann::json b = nlohmann::json::array();
    for (size_t k = 0; k < bodies_.size(); ++k)
      b.push_back({{"peak", {bodies_[k].peak_N_per_m.x(), bodies_[k].peak_N_per_m.y()}},
                   {"sum", {sums_[k].x(), sums_[k].y()}},
                   {"peak_torque", bodies_[k].peak_torque_N},
                   {"torque_sum", torque_sums_[k]},
                   {"samples", bodies_[k].window_samples}});
    return {{"bodies", b}, {"window_s", window_s_}};
  }
  void restore(const nlohmann::json& j) {
    window_s_ = j.at("window_s").get<double>();
    for (size_t k = 0; k < bodies_.size(); ++k) {
      const auto& b = j.at("bodies").at(k);
      bodies_[k].peak_N_per_m = Vec2(b.at("peak")[0], b.at("peak")[1]);
      sums_[k] = Vec2(b.at("sum")[0], b.at("sum")[1]);
      bodies_[k].peak_torque_N = b.value("peak_torque", 0.0);
      torque_sums_[k] = b.value("torque_sum", 0.0);
      bodies_[k].window_samples = b.at("samples").get<int64_t>();
    }
  }
  std::vector<BodyForceSummary> finish() {
    for (size_t b = 0; b < bodies_.size(); ++b) {
      const double nan = std::numeric_limits<double>::quiet_NaN();
      bodies_[b].mean_N_per_m = window_s_ > 0.0 ? Vec2(sums_[b] / window_s_) : Vec2::Constant(nan);
      bodies_[b].mean_torque_N = window_s_ > 0.0 ? torque_sums_[b] / window_s_ : nan;
    }
    return bodies_;
  }

 private:
  const Outputs& out_;
  std::vector<BodyForceSummary> bodies_;
  std::vector<Vec2> sums_;
  std::vector<double> torque_sums_;
  double window_s_ = 0.0;
};

nlohmann::json num_json(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
nlohmann::json vec_json(const Vec2& v) { return nlohmann::json::array({num_json(v.x()), num_json(v.y())}); }

// The DIR.partial-* holding a checkpoint of this scene (the furthest along), or an empty path.
fs::path find_checkpoint(const fs::path& final_dir, const Scene& scene, bool any_build) {
  const std::string prefix = final_dir.filename().string() + ".partial-", hash = scene_hash(scene);
  fs::path best;
  int64_t best_steps = -1;
  for (const std::string& d : checkpoint_dirs(final_dir.string())) {
    const fs::path dir(d);
    const fs::path state = dir / "checkpoint" / "run.json";
    const long pid = std::strtol(dir.filename().string().c_str() + prefix.size(), nullptr, 10);
    if (pid != long(getpid()) && process_running(pid))
      throw std::runtime_error(dir.string() + " is still being written by process " + std::to_string(pid) +
                               ": stop it first or choose another --out");
    std::ifstream in(state);
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(in);
    } catch (const std::exception& x) {
      throw std::runtime_error(state.string() + ": cannot be read (" + x.what() + "); remove " + dir.string() +
                               " to start afresh");
    }
    if (j.value("scene_hash", std::string()) != hash)
      throw std::runtime_error(dir.string() + " holds a checkpoint of a different scene (scene_hash " +
                               j.value("scene_hash", std::string("?")) + ", this scene " + hash +
                               "): remove it or choose another --out");
    // checkpoints from before builds were recorded carry none: taken as this build's
    const std::string build = j.value("build", build_id());
    if (build != build_id() && !any_build)
      throw std::runtime_error(dir.string() + " holds a checkpoint written by build " + build + ", this program is " +
                               build_id() + ": resumed by it, the run would not be bit-identical to an uninterrupted "
                               "one. Continue it with that build, or pass --resume-any-build");
    if (j.value("steps", int64_t(-1)) > best_steps) best = dir, best_steps = j.value("steps", int64_t(-1));
  }
  return best;
}

// run_scene's stages, in order: prepare_run_dir (as the run is built), set_up, step_loop, finish.
// Its locals are members under the same names, so each stage reads as the one function did.
struct SceneRun {
  using clock = std::chrono::steady_clock;
  const Scene& scene;
  const RunOptions& opt;
  fs::path final_dir, tmp_dir, checkpoint_dir;  // set by prepare_run_dir
  nlohmann::json resumed = prepare_run_dir();  // the checkpoint's run state; null for a new run
  const clock::time_point wall0 = clock::now();
  Simulation sim{scene};
  // the checkpoint's state, before the force log trims forces.csv to the checkpoint's rows
  const bool state_loaded = load_state();
  ForceLog forces{(tmp_dir / "forces.csv").string(), scene, resumed.is_null() ? resumed : resumed.at("forces")};
  ForceStats stats{scene};
  RunAnalysis analysis{scene};  // run.json "analysis": drag statistics, wedge per frame
  CollapseAnalysis collapse{scene};  // run.json "collapse": runout and height of a released column

  const Outputs& out = scene.outputs;
  std::vector<std::string> fields;
  bool frames_on = false;
  RasterSpec raster;
  std::vector<PvdEntry> pvd;
  int64_t frame_index = 0;
  double next_frame_s = 0.0;

  // progress: the end is whichever criterion comes first
  const double end_t = scene.solver.end_time_s, end_d = scene.solver.end_displacement_m;
  double dt_min = std::numeric_limits<double>::max(), dt_max = 0.0;
  double wall_before_s = 0.0, solver_before_s = 0.0;  // earlier segments of a resumed run
  double checkpoint_s = 0.0;  // writing checkpoints, all segments: not solver time
  int segments = 1;
  clock::time_point loop0;  // the solver loop's start in this segment
  int64_t steps0 = 0;       // and the step it started from
  double fraction0 = 0.0;   // and how far the run was then
  clock::time_point last_report = clock::now();
  int64_t contact_sweeps = 0, contact_unconverged = 0, contact_points_max = 0;
  int contact_sweeps_max = 0;
  double contact_residual_max = 0.0;
  RunSummary summary;
  nlohmann::json builds = nlohmann::json::array();  // every build that ran a segment, in order
  double segment_checkpoint_s = 0.0;

  SceneRun(const Scene& s, const RunOptions& o) : scene(s), opt(o) {}
  nlohmann::json prepare_run_dir();
  bool load_state();
  void set_up();
  std::optional<RunSummary> step_loop();  // a summary when stopped at a checkpoint
  RunSummary finish();

  void write_frame() {
    const ParticleView view = sim.particle_view();
    FieldFrame f = rasterize(view, raster, fields);
    f.scene_name = scene.name;
    f.step = sim.step_count();
    f.time_s = sim.time_s();
    f.dt_s = sim.last_dt_s();
    f.bodies = sim.body_outlines();
    if (analysis.wants_frames())
      analysis.add_frame(f, sim.lead_body_travel_m(), sim.bodies()[size_t(analysis.lead_index())].velocity_m_s);
    if (out.points) {
      // before the frame file: once frame k exists, so do its points
      PointFrameInfo info;
      info.scene_name = f.scene_name;
      info.step = f.step;
      info.time_s = f.time_s;
      info.dt_s = f.dt_s;
      info.dx_m = raster.dx_m;
      info.bodies = f.bodies;
      write_points_vdb(points_path(tmp_dir.string(), frame_index), info, view);
    }
    write_frame_vdb(frame_path(tmp_dir.string(), frame_index), f);
    if (opt.frame_written) opt.frame_written(frame_index, frame_path(tmp_dir.string(), frame_index));
    if (opt.write_paraview) {
      write_vti(frame_path(tmp_dir.string(), frame_index, "vti"), f);
      pvd.push_back({f.time_s, fs::relative(frame_path(tmp_dir.string(), frame_index, "vti"), tmp_dir).string()});
    }
    ++frame_index;
    next_frame_s += out.frame_interval_s;
  }
  double fraction() const {
    double f = end_t > 0.0 ? sim.time_s() / end_t : 0.0;
    if (end_d > 0.0) f = std::max(f, sim.lead_body_travel_m() / end_d);
    return std::min(f, 1.0);
  }
  void report(bool force_report) {
    if (!opt.progress) return;
    const auto now = clock::now();
    if (!force_report && std::chrono::duration<double>(now - last_report).count() < opt.progress_interval_s) return;
    last_report = now;
    RunProgress p;
    p.fraction = fraction();
    p.time_s = sim.time_s();
    p.steps = sim.step_count();
    const double segment_s = std::chrono::duration<double>(now - wall0).count();
    p.wall_s = wall_before_s + segment_s;
    // from the loop's own pace (set-up and a checkpoint's loading left out), once it has run a few
    // seconds: a resumed paper-size run used to wait for 1% of the run (minutes) before showing one
    const double loop_s = std::chrono::duration<double>(now - loop0).count();
    const double done = p.fraction - fraction0;
    p.eta_s = loop_s >= 5.0 && done > 0.0 ? loop_s * (1.0 - p.fraction) / done : -1.0;
    p.particles = sim.particles().size();
    p.dt_s = sim.last_dt_s();
    p.particle_steps_per_s = loop_s > 0.0 ? double(p.particles) * double(p.steps - steps0) / loop_s : 0.0;
    opt.progress(p);
  }
  // The run's state after a step, written beside the old checkpoint and swapped in by two renames
  // (find_checkpoint takes checkpoint.old if a crash falls between them).
  void save_checkpoint() {
    const auto t0 = clock::now();
    const fs::path fresh = tmp_dir / "checkpoint.new", old = tmp_dir / "checkpoint.old";
    fs::remove_all(fresh);
    fs::create_directories(fresh);
    {
      std::ofstream f(fresh / "simulation.bin", std::ios::binary);
      sim.save_state(f);
      f.close();
      if (!f) throw std::runtime_error((fresh / "simulation.bin").string() + ": write failed");
    }
    nlohmann::json pvd_json = nlohmann::json::array();
    for (const auto& e : pvd) pvd_json.push_back({e.time_s, e.file});
    // the state file is the checkpoint's cost; its small run.json is left out
    const double writing_s = std::chrono::duration<double>(clock::now() - t0).count();
    const nlohmann::json j = {
        {"scene_hash", scene_hash(scene)}, {"build", build_id()}, {"builds", builds},
        {"steps", sim.step_count()}, {"time_s", sim.time_s()},
        {"frame_index", frame_index}, {"next_frame_s", next_frame_s}, {"pvd", pvd_json},
        {"dt_min_s", dt_min}, {"dt_max_s", dt_max},
        {"contact", {contact_sweeps, contact_unconverged, contact_points_max, contact_sweeps_max, contact_residual_max}},
        {"wall_seconds", wall_before_s + std::chrono::duration<double>(clock::now() - wall0).count()},
        {"solver_seconds",
         solver_before_s + std::chrono::duration<double>(t0 - loop0).count() - segment_checkpoint_s},
        {"segments", segments}, {"checkpoint_seconds", checkpoint_s + writing_s}, {"forces", forces.state()},
        {"stats", stats.state()},
        {"analysis", analysis.state()}, {"collapse", collapse.state()}};
    write_file_atomic((fresh / "run.json").string(), j.dump() + "\n");
    fs::remove_all(old);
    if (fs::exists(checkpoint_dir)) fs::rename(checkpoint_dir, old);
    fs::rename(fresh, checkpoint_dir);
    fs::remove_all(old);
    const double took = std::chrono::duration<double>(clock::now() - t0).count();
    segment_checkpoint_s += took;
    checkpoint_s += took;
  }
};

// The run directory: a fresh DIR.partial-PID, or the checkpoint's moved there.
nlohmann::json SceneRun::prepare_run_dir() {
  if (opt.out_dir.empty()) throw std::invalid_argument("run_scene: no output directory given");
  final_dir = fs::absolute(opt.out_dir).lexically_normal();
  if (fs::exists(final_dir) && !opt.force)
    throw std::runtime_error(final_dir.string() + " already exists: choose another --out or pass --force to replace it");
  tmp_dir = final_dir.string() + ".partial-" + std::to_string(getpid());
  checkpoint_dir = tmp_dir / "checkpoint";
  nlohmann::json resumed;  // the checkpoint's run state; null for a new run
  if (opt.resume) {
    const fs::path from = find_checkpoint(final_dir, scene, opt.resume_any_build);
    if (!from.empty()) {
      if (from != tmp_dir) {
        fs::remove_all(tmp_dir);
        fs::rename(from, tmp_dir);
      }
      std::ifstream in(checkpoint_dir / "run.json");
      resumed = nlohmann::json::parse(in);
    }
  }
  if (resumed.is_null()) {
    fs::remove_all(tmp_dir);
    fs::create_directories(tmp_dir / "frames");
    write_file_atomic((tmp_dir / "scene.json").string(), format_scene(scene));
  }
  return resumed;
}

bool SceneRun::load_state() {
  if (!resumed.is_null()) {
    const std::string path = (checkpoint_dir / "simulation.bin").string();
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path + ": cannot open");
    sim.load_state(in, path);
  }
  return !resumed.is_null();
}

// What a frame stores, and the run's counters from the checkpoint or the first frame.
void SceneRun::set_up() {
  for (const auto& f : out.fields) fields.push_back(f);
  frames_on = out.frame_interval_s > 0.0 && !fields.empty();
  raster.nx = sim.grid().nx;
  raster.ny = sim.grid().ny;
  raster.dx_m = scene.domain.dx_m;
  if (!resumed.is_null()) builds = resumed.value("builds", nlohmann::json::array({resumed.value("build", build_id())}));
  if (builds.empty() || builds.back() != build_id()) builds.push_back(build_id());
  if (!resumed.is_null()) {
    summary.resumed_from_step = sim.step_count();
    const auto& r = resumed;
    frame_index = r.at("frame_index").get<int64_t>();
    next_frame_s = r.at("next_frame_s").get<double>();
    for (const auto& e : r.at("pvd")) pvd.push_back({e.at(0).get<double>(), e.at(1).get<std::string>()});
    dt_min = r.at("dt_min_s").get<double>(), dt_max = r.at("dt_max_s").get<double>();
    const auto& c = r.at("contact");
    contact_sweeps = c.at(0), contact_unconverged = c.at(1), contact_points_max = c.at(2);
    contact_sweeps_max = c.at(3), contact_residual_max = c.at(4);
    wall_before_s = r.at("wall_seconds").get<double>();
    solver_before_s = r.at("solver_seconds").get<double>();
    checkpoint_s = r.value("checkpoint_seconds", 0.0);
    segments = r.at("segments").get<int>() + 1;
    stats.restore(r.at("stats"));
    analysis.restore(r.at("analysis"));
    collapse.restore(r.at("collapse"));
  } else {
    if (frames_on) write_frame();
    if (collapse.active()) collapse.add_step(0.0, sim.particle_view());
  }
}

std::optional<RunSummary> SceneRun::step_loop() {
  loop0 = clock::now();
  steps0 = sim.step_count();
  fraction0 = fraction();
  auto last_checkpoint = clock::now();
  while (!sim.finished()) {
    sim.step();
    if (opt.after_step) opt.after_step(sim);
    // A non-finite state stops the run before anything of it is recorded: the rows and frames
    // written so far stay in the partial directory. Velocities suffice (G2P moves positions by
    // them; a bad stress or volume reaches them through the next P2G) and cost ~1% of a step.
    {
      const Particles& p = sim.particles();
      bool finite = true;
      for (size_t i = 0; i < p.size(); ++i) finite &= std::isfinite(p.vx[i] + p.vy[i]);
      if (!finite) {
        std::string field;
        size_t bad = 0;
        p.for_each_array([&](const char* name, const auto& a) {
          for (size_t i = 0; i < a.size() && field.empty(); ++i)
            if (!std::isfinite(double(a[i]))) field = name, bad = i;
        });
        forces.close();
        std::ostringstream msg;
        msg << "non-finite state at step " << sim.step_count() << " (t = " << sim.time_s() << " s): " << field
            << " of point " << bad << " at (" << p.x[bad] << ", " << p.y[bad] << ") m; the run stopped, what it wrote is in "
            << tmp_dir.string();
        throw std::runtime_error(msg.str());
      }
    }
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
    const bool stop = opt.stop_requested && opt.stop_requested();
    if (stop || (opt.checkpoint_interval_s > 0.0 &&
                 std::chrono::duration<double>(clock::now() - last_checkpoint).count() >= opt.checkpoint_interval_s)) {
      save_checkpoint();
      last_checkpoint = clock::now();
    }
    if (stop && !sim.finished()) {
      report(true);
      summary.stopped = true;
      summary.out_dir = tmp_dir.string();
      summary.run_json = {{"steps", sim.step_count()}, {"end_time_s", sim.time_s()}};
      return summary;
    }
  }
  return std::nullopt;
}

// run.json, and the run directory moved into place.
RunSummary SceneRun::finish() {
  const double loop_s =
      solver_before_s + std::chrono::duration<double>(clock::now() - loop0).count() - segment_checkpoint_s;
  if (collapse.active()) collapse.add_step(sim.time_s(), sim.particle_view(), true);
  forces.flush(sim);
  forces.close();
  report(true);
  if (opt.write_paraview && !pvd.empty()) write_pvd((tmp_dir / "frames.pvd").string(), pvd);

  fs::remove_all(checkpoint_dir);  // a finished run keeps no checkpoint
  summary.bodies = stats.finish();
  const double wall_s = wall_before_s + std::chrono::duration<double>(clock::now() - wall0).count();
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
  j["segments"] = segments;  // > 1: resumed from checkpoints; the seconds are summed over them
  j["checkpoint_seconds"] = checkpoint_s;  // in wall_seconds, not in solver_seconds
  j["build"] = build_id();
  if (builds.size() > 1) j["resumed_across_builds"] = builds;  // --resume-any-build: not bit-identical
  j["particle_steps_per_second"] = loop_s > 0.0 ? psteps / loop_s : 0.0;
  j["threads"] = scene.solver.threads > 0 ? scene.solver.threads : tbb::info::default_concurrency();
  j["peak_resident_bytes"] = peak_resident_bytes();
  const PhaseSeconds& ph = sim.phase_seconds();
  j["phase_seconds"] = {{"p2g", ph.p2g}, {"grid", ph.grid}, {"contact", ph.contact},
                        {"g2p", ph.g2p}, {"constitutive", ph.constitutive},
                        {"g2p_constitutive", ph.g2p_constitutive}, {"reorder", ph.reorder}};
  j["reorders"] = {{"scheduled", sim.reorders().scheduled}, {"strayed", sim.reorders().strayed},
                   {"every_steps", Simulation::kReorderSteps}};
  j["state_bytes_per_particle"] = sim.particles().size() ? double(sim.state_bytes()) / sim.particles().size() : 0.0;
  j["state_precision"] = FURROW_FLOAT_STATE ? "float stress, pressure, mass, affine matrix, strain rate" : "double";
  j["instruction_set"] = instruction_set();
  j["frames"] = frame_index;
  j["lead_body_travel_m"] = sim.lead_body_travel_m();
  j["units"] = {{"force", "N/m (per metre out of plane)"}, {"torque", "N m/m, counter-clockwise, about the body's origin"}, {"time", "s"}, {"length", "m"}};
  for (const auto& b : summary.bodies)
    j["bodies"].push_back({{"name", b.name},
                           {"mean_force_N_per_m", vec_json(b.mean_N_per_m)},
                           {"peak_force_N_per_m", vec_json(b.peak_N_per_m)},
                           {"mean_torque_N_m_per_m", num_json(b.mean_torque_N)},
                           {"peak_torque_N_m_per_m", b.peak_torque_N},
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

}  // namespace

RunSummary run_scene(const Scene& scene, const RunOptions& opt) {
  SceneRun run(scene, opt);
  run.set_up();
  if (std::optional<RunSummary> stopped = run.step_loop()) return *stopped;
  return run.finish();
}

}  // namespace furrow
