// furrow sweep: one scene over the cartesian product of --vary values, N runs at a time or over
// the ranks of an MPI job (app/mpi_sweep.cpp), each into its own run directory, then sweep.csv
// (+ sweep.json, sweep.png) over all of them. Running it again finishes what is missing. In the
// app core: the Python module's furrow.sweep runs this same driver (app/drivers.hpp).
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <optional>
#include <thread>

#include "app/commands.hpp"
#include "app/drivers.hpp"
#include "app/mpi_sweep.hpp"
#include "app/progress.hpp"
#include "app/run_dirs.hpp"
#include "app/sweep.hpp"
#include "app/sweep_plot.hpp"
#include "engine/io/atomic_file.hpp"
#include "engine/io/field_store.hpp"
#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"
#include "render/plot.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

namespace {

std::string describe_run(const sweep::SweepRow& r) {
  std::string s;
  for (const auto& b : r.metrics.bodies) {
    if (!b.moving) continue;
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s%s drag %.4g N/m", s.empty() ? "" : ", ", b.name.c_str(), b.mean_drag_N_per_m);
    s += buf;
    if (std::isfinite(b.F0_N_per_m)) {
      std::snprintf(buf, sizeof buf, " (%.3g F0)", b.mean_drag_N_per_m / b.F0_N_per_m);
      s += buf;
    }
  }
  if (r.metrics.collapse) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%sa %.3g: runout (Lf - L0)/L0 %.3g, Hf/H0 %.3g%s", s.empty() ? "" : ", ",
                  r.metrics.aspect_ratio, r.metrics.runout_relative, r.metrics.final_height_relative,
                  r.metrics.settled ? "" : " (still moving)");
    s += buf;
  }
  return s;
}

// The sweep as every rank works it out from the command line alone: runs, their scenes, and
// the combinations whose scene cannot run (a failed row each; the others still run).
struct Plan {
  std::string scene_path;
  Scene base;
  std::vector<sweep::Vary> varies;
  std::vector<std::vector<size_t>> combos;
  std::vector<std::string> names;   // run directory per combination
  std::vector<Scene> scenes;        // per combination; unused where invalid[r] is set
  std::vector<std::string> invalid; // per combination: why its scene cannot run, "" when it can
  std::exception_ptr first_invalid; // the first of those errors
  fs::path out_dir;
};

// Throws UsageError. A scene error that leaves nothing to run is written (when `speak`) or thrown
// (hooks.throw_scene_errors) and gives no plan.
std::optional<Plan> plan_sweep(const Parsed& p, bool speak, const DriverHooks& hooks) {
  std::ostream& err = hooks.err ? *hooks.err : std::cerr;
  Plan plan;
  plan.scene_path = p.positional[0];
  plan.varies = parse_varies(p, "--vary", "nothing to sweep: give at least one --vary KEYS=VALUES");
  if (mpi::launched_rank() >= 0 && p.has("--jobs"))
    throw UsageError("--jobs: under mpirun each rank runs one run at a time; start more ranks instead");
  parse_jobs(p);
  plan.combos = sweep::combinations(plan.varies);
  try {
    plan.base = load_scene_for_cli(p, plan.scene_path);
  } catch (const SceneError& e) {
    if (hooks.throw_scene_errors) throw;
    if (speak) err << "furrow sweep: " << e.what() << "\n";
    return std::nullopt;
  }
  for (const auto& c : plan.combos) {
    plan.scenes.emplace_back();
    plan.invalid.emplace_back();
    try {
      plan.scenes.back() = load_varied_scene(p, plan.scene_path, plan.varies, c, "--vary");
    } catch (const SceneError& e) {
      plan.invalid.back() = e.what();
      if (!plan.first_invalid) plan.first_invalid = std::current_exception();
    }
  }
  if (std::all_of(plan.invalid.begin(), plan.invalid.end(), [](const std::string& w) { return !w.empty(); })) {
    if (hooks.throw_scene_errors) std::rethrow_exception(plan.first_invalid);
    std::vector<std::string> said;  // combinations often fail alike: each message once
    for (const auto& w : plan.invalid)
      if (std::find(said.begin(), said.end(), w) == said.end()) said.push_back(w);
    for (const auto& w : said)
      if (speak) err << "furrow sweep: " << w << "\n";
    return std::nullopt;
  }
  plan.names = sweep::run_dir_names(plan.base.name, plan.varies, plan.combos);
  plan.out_dir =
      fs::absolute(p.get("--out", (fs::path("out") / (plan.base.name + "_sweep")).string())).lexically_normal();
  return plan;
}

// What rank 0 decided about the sweep directory, for every rank.
struct Decision {
  int exit_status = 0;      // non-zero: nothing runs
  fs::path work_dir;        // the sweep directory, or with --force a new one that replaces it at the end
  std::vector<size_t> todo; // runs to do, longest predicted first
  std::vector<bool> reused; // per run: a finished run of its scene is already there
};

nlohmann::json decision_json(const Decision& d) {
  return {{"exit_status", d.exit_status}, {"work_dir", d.work_dir.string()}, {"todo", d.todo}, {"reused", d.reused}};
}

Decision decision_from(const nlohmann::json& j) {
  return {j.at("exit_status").get<int>(), j.at("work_dir").get<std::string>(), j.at("todo").get<std::vector<size_t>>(),
          j.at("reused").get<std::vector<bool>>()};
}

// An existing directory is resumed only when it holds this sweep (the same runs, by sweep.json).
bool holds_this_sweep(const fs::path& dir, const Plan& plan) {
  try {
    const auto j = nlohmann::json::parse(read_text(dir / "sweep.json"));
    std::vector<std::string> dirs;
    for (const auto& r : j.at("runs")) dirs.push_back(r.at("dir").get<std::string>());
    return dirs == plan.names;
  } catch (const std::exception&) {
    return false;
  }
}

// Rank 0: new, resumed or (--force) replacing directory; which runs are done; errors printed.
Decision decide(const Parsed& p, const Plan& plan, std::ostream& err) {
  Decision d;
  d.work_dir = plan.out_dir;
  d.reused.assign(plan.names.size(), false);
  if (fs::exists(plan.out_dir) && p.has("--force")) {
    d.work_dir = plan.out_dir.string() + ".partial-" + std::to_string(::getpid());
    fs::remove_all(d.work_dir);
  } else if (fs::exists(plan.out_dir)) {
    if (!holds_this_sweep(plan.out_dir, plan)) {
      err << "furrow sweep: " << plan.out_dir.string() << " already exists and is not this sweep (its "
                << "sweep.json does not list these runs); pass --out DIR for a new sweep or --force to replace it\n";
      return {1, {}, {}, {}};
    }
    std::vector<std::string> conflicts;
    for (size_t r = 0; r < plan.names.size(); ++r) {
      if (!plan.invalid[r].empty()) continue;
      const fs::path dir = plan.out_dir / plan.names[r];
      const RunDirMatch m = match_run_dir(dir, plan.scenes[r]);
      d.reused[r] = m.state == RunDirState::same_scene;
      if (m.state == RunDirState::other_scene) conflicts.push_back(dir.string() + ": " + m.why);
      if (m.state == RunDirState::incomplete) fs::remove_all(dir);  // holds no finished result
    }
    if (!conflicts.empty()) {
      err << "furrow sweep: " << plan.out_dir.string()
                << " holds runs of another version of this sweep's scene; they would not belong in one table:\n";
      for (const auto& c : conflicts) err << "  " << c << "\n";
      err << "pass --out DIR for a new sweep or --force to replace it\n";
      return {1, {}, {}, {}};
    }
    remove_stale_partials(plan.out_dir);
  }
  fs::create_directories(d.work_dir);
  std::vector<double> particle_steps(plan.names.size(), 0.0);
  for (size_t r = 0; r < plan.names.size(); ++r) {
    if (!plan.invalid[r].empty() || d.reused[r]) continue;
    d.todo.push_back(r);
    particle_steps[r] = estimate_particle_steps(plan.scenes[r]);
  }
  // longest first, so that no long run starts last while the other ranks sit idle
  std::stable_sort(d.todo.begin(), d.todo.end(), [&](size_t a, size_t b) { return particle_steps[a] > particle_steps[b]; });
  return d;
}

// sweep.json: the settings and each run's status; once the table exists, its columns and figure.
nlohmann::json sweep_json(const Parsed& p, const Plan& plan, const std::vector<sweep::SweepRow>& rows,
                          const std::vector<std::string>& status, const std::vector<int>& ran_on, int ranks, int jobs,
                          int threads_each) {
  nlohmann::json j;
  j["scene"] = plan.scene_path;
  j["scene_name"] = plan.base.name;
  j["sets"] = p.all("--set");
  for (const auto& v : plan.varies) j["vary"].push_back({{"spec", v.spec}, {"keys", v.keys}, {"values", v.values}});
  j["ranks"] = ranks;
  j["jobs"] = jobs;
  j["threads_per_run"] = threads_each;
  for (size_t r = 0; r < rows.size(); ++r)
    j["runs"].push_back({{"dir", rows[r].dir}, {"values", rows[r].values}, {"status", status[r]},
                         {"error", rows[r].error}, {"wall_s", rows[r].wall_s},
                         {"rank", ran_on[r] >= 0 ? nlohmann::json(ran_on[r]) : nlohmann::json(nullptr)}});
  return j;
}

int run_sweep(const Parsed& p, const Plan& plan, mpi::Job& job, const DriverHooks& hooks) {
  const bool quiet = p.has("--quiet");
  const bool root = job.rank() == 0;
  std::ostream& err = hooks.err ? *hooks.err : std::cerr;
  if (p.has("--movies") && !hooks.render_movies)
    throw UsageError("--movies: no renderer here (the Python module): render the runs' movies with `furrow render RUN`");
  Decision d;
  if (root) d = decide(p, plan, err);
  d = decision_from(nlohmann::json::parse(job.broadcast(decision_json(d).dump())));
  if (d.exit_status != 0) return root ? d.exit_status : 0;

  // a lone process runs --jobs runs at a time; under MPI each rank runs one, on its node's share
  // of the cores
  const int jobs = job.size() > 1 ? 1 : std::max(1, std::min<int>(parse_jobs(p), int(std::max<size_t>(1, d.todo.size()))));
  const int sharing = job.size() > 1 ? job.ranks_on_node() : jobs;
  const int cores = std::max(1u, std::thread::hardware_concurrency());
  const int threads_each = std::max(1, cores / sharing);
  std::vector<Scene> scenes = plan.scenes;
  for (auto& s : scenes) {
    if (s.solver.threads == 0) s.solver.threads = threads_each;  // the scene or --threads decides otherwise
    if (!p.has("--movies")) s.outputs.movies.clear();
  }

  std::mutex render_mutex;
  // a stop (hooks.stop_requested) ends the running runs with a checkpoint and starts no more
  std::atomic<bool> stopping{false};
  std::vector<char> stopped(plan.names.size(), 0);  // per run, written by its own thread
  auto stop_now = [&] { return stopping || (hooks.stop_requested && hooks.stop_requested() && (stopping = true)); };
  auto run = [&](size_t r) {
    mpi::Outcome o;
    o.index = r;
    o.rank = job.rank();
    const auto w0 = std::chrono::steady_clock::now();
    if (stop_now()) {
      stopped[r] = 1;
      o.error = "stopped before it started";
      return o;
    }
    try {
      RunOptions opt;
      opt.out_dir = (d.work_dir / plan.names[r]).string();
      opt.write_paraview = !p.has("--no-paraview");
      opt.resume = true;  // a run a stop left with a checkpoint continues from it (bit-identically)
      if (hooks.stop_requested) opt.stop_requested = stop_now;
      opt.progress_interval_s = hooks.run_progress_interval_s;
      if (hooks.on_run_progress) opt.progress = [&, r](const RunProgress& pr) { hooks.on_run_progress(plan.names[r], pr); };
      const RunSummary s = run_scene(scenes[r], opt);
      if (s.stopped) {
        stopped[r] = 1;
        o.error = "stopped at step " + std::to_string(s.run_json.value("steps", int64_t(0))) + " (checkpoint in " +
                  s.out_dir + ")";
        o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
        return o;
      }
      if (p.has("--movies")) {
        std::lock_guard<std::mutex> lock(render_mutex);  // one GL context at a time
        hooks.render_movies(s.out_dir, scenes[r]);
      }
      o.ok = true;
    } catch (const std::exception& e) {
      o.error = e.what();
    }
    o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    return o;
  };

  std::vector<sweep::SweepRow> rows(plan.names.size());
  std::vector<std::string> status(rows.size(), "pending");
  std::vector<int> ran_on(rows.size(), -1);  // rank that ran it in this invocation
  std::vector<bool> collected(rows.size(), false);
  // the results of a finished run, read back from its directory (wherever its rank wrote it)
  auto collect = [&](size_t r) {
    try {
      const FinishedRun f = read_finished_run(d.work_dir / plan.names[r], plan.scenes[r]);
      rows[r].metrics = f.metrics;
      if (d.reused[r]) rows[r].wall_s = f.run_json.value("wall_seconds", 0.0);
      collected[r] = true;
    } catch (const std::exception& e) {
      rows[r].error = std::string("cannot read its results: ") + e.what();
    }
  };
  if (root) {
    for (size_t r = 0; r < rows.size(); ++r) {
      rows[r].dir = plan.names[r];
      for (size_t k = 0; k < plan.varies.size(); ++k) rows[r].values.push_back(plan.varies[k].values[plan.combos[r][k]]);
      rows[r].error = plan.invalid[r];
      if (!plan.invalid[r].empty()) status[r] = "failed";
      if (d.reused[r]) {
        status[r] = "reused";
        rows[r].ok = true;
        collect(r);
      }
    }
    // written first, so that a sweep stopped part-way is recognised and resumed
    write_file_atomic((d.work_dir / "sweep.json").string(),
                      sweep_json(p, plan, rows, status, ran_on, job.size(), jobs, threads_each).dump(2) + "\n");
    if (!quiet) {
      std::fprintf(stderr, "furrow sweep: %zu runs of %s (%zu already done), %s%d thread%s each unless the scene sets "
                   "threads -> %s\n", rows.size(), plan.base.name.c_str(),
                   size_t(std::count(d.reused.begin(), d.reused.end(), true)),
                   (job.size() > 1 ? "over " + std::to_string(job.size()) + " MPI ranks, "
                                   : std::to_string(jobs) + " at a time, ").c_str(),
                   threads_each, threads_each == 1 ? "" : "s", plan.out_dir.string().c_str());
      for (size_t r = 0; r < rows.size(); ++r)
        if (!plan.invalid[r].empty()) std::fprintf(stderr, "furrow sweep: %s cannot run: %s\n", rows[r].dir.c_str(),
                                                   plan.invalid[r].c_str());
    }
  }

  size_t done = 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto on_done = [&](const mpi::Outcome& o) {
    sweep::SweepRow& row = rows[o.index];
    row.ok = o.ok;
    row.error = o.error;
    row.wall_s = o.wall_s;
    status[o.index] = o.ok ? "ok" : stopped[o.index] ? "stopped" : "failed";
    ran_on[o.index] = o.rank;
    if (o.ok) collect(o.index);
    ++done;
    if (hooks.on_event)
      hooks.on_event({{"event", "run_done"}, {"dir", row.dir}, {"values", row.values}, {"status", status[o.index]},
                      {"error", row.error}, {"wall_s", row.wall_s}, {"done", done}, {"todo", d.todo.size()}});
    if (quiet) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double eta = elapsed / double(done) * double(d.todo.size() - done);
    const std::string what = row.ok ? describe_run(row) : row.error;
    std::fprintf(stderr, "[%zu/%zu] %s: %s in %.1f s wall%s%s; elapsed %s, sweep ETA %s\n", done, d.todo.size(),
                 row.dir.c_str(), row.ok ? "done" : "FAILED", row.wall_s, what.empty() ? "" : row.ok ? ", " : ": ",
                 what.c_str(), format_duration(elapsed).c_str(), format_duration(eta).c_str());
  };
  job.distribute(d.todo, jobs, run, on_done);
  if (!root) return 0;
  if (stopping) {  // the table waits for the runs the next invocation finishes
    write_file_atomic((d.work_dir / "sweep.json").string(),
                      sweep_json(p, plan, rows, status, ran_on, job.size(), jobs, threads_each).dump(2) + "\n");
    const size_t finished = size_t(std::count(status.begin(), status.end(), "ok")) +
                            size_t(std::count(status.begin(), status.end(), "reused"));
    if (!quiet)
      std::fprintf(stderr, "furrow sweep: stopped; %zu of %zu runs are done in %s. Run the same sweep again to finish "
                   "the rest.\n", finished, rows.size(), d.work_dir.string().c_str());
    return 130;
  }

  // ---- table, description, figure ----
  for (size_t r = 0; r < rows.size(); ++r)
    if (rows[r].ok && !collected[r]) {
      collect(r);  // a run another node wrote may show up here late (network file systems)
      rows[r].ok = collected[r];
      if (!rows[r].ok) status[r] = "failed";
    }
  write_file_atomic((d.work_dir / "sweep.csv").string(), sweep::sweep_csv(plan.varies, rows));
  nlohmann::json j = sweep_json(p, plan, rows, status, ran_on, job.size(), jobs, threads_each);
  for (const auto& [name, meaning] : sweep::sweep_columns(plan.varies, rows)) j["columns"][name] = meaning;
  j["definitions"] = {
      {"drag", "-F.u, u the unit velocity of the body at the start (the force opposing the motion), N/m"},
      {"lift", "F.n, n = u turned +90 degrees (for motion in +x: Fy, up), N/m"},
      {"w", "1 m: forces are per metre out of plane"},
      {"rho_d", "rho_g * packing_fraction of the bed"},
      {"depth", "below the top of the bed under the body at its start; evaluated at the middle of the averaging window"},
      {"z", "depth of a plate's bottom edge at the middle of the averaging window (mean over the moving boxes)"}};
  const sweep::SweepFigure figure = sweep::sweep_figure(plan.base.name, plan.varies, rows);
  j["figure"] = figure.kind;
  write_file_atomic((d.work_dir / "sweep.json").string(), j.dump(2) + "\n");
  bool plotted = false;
  if (hooks.write_figure_png) try {
      // the directory holds this sweep (decide() checked): its figure follows the table just written
      hooks.write_figure_png(figure.figure, (d.work_dir / "sweep.png").string());
      plotted = true;
    } catch (const std::exception& e) {
      err << "furrow sweep: warning: no sweep.png: " << e.what() << "\n";
    }

  if (d.work_dir != plan.out_dir) {  // --force: the new sweep is complete, the old one goes
    const fs::path old = plan.out_dir.string() + ".replaced-" + std::to_string(::getpid());
    fs::rename(plan.out_dir, old);
    fs::rename(d.work_dir, plan.out_dir);
    fs::remove_all(old);
  }

  size_t failed = 0, reused = 0;
  for (size_t r = 0; r < rows.size(); ++r) failed += !rows[r].ok, reused += d.reused[r];
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("sweep of %zu runs (%zu reused, %zu failed) in %s: %s/sweep.csv%s%s%s\n", rows.size(), reused, failed,
              format_duration(total).c_str(), plan.out_dir.string().c_str(), plotted ? " and sweep.png (" : "",
              plotted ? figure.kind.c_str() : "", plotted ? ")" : "");
  if (failed) {
    std::fprintf(stderr, "furrow sweep: %zu of %zu runs failed (status and error in sweep.csv):\n", failed, rows.size());
    for (const auto& r : rows)
      if (!r.ok) std::fprintf(stderr, "  %s: %s\n", r.dir.c_str(), r.error.c_str());
  }
  return failed ? 1 : 0;
}

}  // namespace

DriverHooks& cli_driver_hooks() {
  static DriverHooks hooks;
  return hooks;
}

int sweep_main(const Parsed& p, const DriverHooks& hooks) {
  std::ostream& err = hooks.err ? *hooks.err : std::cerr;
  const int launched = mpi::launched_rank();
  if (launched >= 0 && !mpi::built_with_mpi()) {
    if (launched == 0)
      err << "furrow sweep: started by an MPI launcher, but this furrow was built without MPI (furrow "
                   "--version): run the sweep without mpirun/srun, or rebuild with -DFURROW_MPI=ON\n";
    return 1;
  }
  // every rank checks the same command line; only rank 0 (or a lone process) says what is wrong
  const bool speak = launched <= 0;
  std::optional<Plan> plan;
  try {
    plan = plan_sweep(p, speak, hooks);
  } catch (const UsageError&) {
    if (!speak) return 2;
    throw;
  }
  if (!plan) return 1;

  mpi::Job job;  // MPI_Init only under an MPI launcher
  try {
    return run_sweep(p, *plan, job, hooks);
  } catch (const UsageError&) {
    throw;
  } catch (const std::exception& e) {
    err << "furrow sweep: error" << (job.size() > 1 ? " on rank " + std::to_string(job.rank()) : "") << ": "
              << e.what() << "\n";
    job.abort(1);  // the other ranks may be waiting on this one
    return 1;
  }
}

Command command_sweep() {
  Command c{"sweep", "run a scene over parameter combinations: sweep.csv and a summary plot",
            "furrow sweep SCENE.json --vary KEYS=VALUES [--vary ...] [--jobs N] [--out DIR] [--set key.path=value ...]\n"
            "       mpirun -np N furrow sweep SCENE.json --vary ... [--out DIR]",
            "Runs every combination (cartesian product) of the --vary values, N at a time (--jobs), each run\n"
            "into DIR/<scene>_<key>=<value>_... (as `furrow run` writes it; movies only with --movies), then\n"
            "writes into DIR (default out/<scene>_sweep):\n"
            "  sweep.csv   one row per run: the swept values (column = key path), wall time, and per body\n"
            "              the mean drag and lift over the scene's averaging window, the initial peak drag\n"
            "              (empty when the drag never gives), for plates the drag at the start of\n"
            "              penetration (F(z -> 0) of a line fitted over z in [dx, L/2]), and their\n"
            "              normalized forms: a circle by pi (D/2)^2 rho_d g w, moving boxes by\n"
            "              rho_d g z L_avg w (z: depth of the plate bottom below the bed surface at the\n"
            "              middle of the window; L_avg: mean width of the moving boxes); rho_d = rho_g phi\n"
            "              of the bed, g = |gravity|, w = 1 m. Units are in the column names.\n"
            "  sweep.json  the sweep's settings, each run's status, and every column's definition\n"
            "  sweep.png   the paper's figure for what was swept (drag/lift vs depth, force vs plate width\n"
            "              with power-law exponents, pair drag vs separation) or mean forces vs the first key\n"
            "VALUES is a:b:step (b included) or a list v1,v2,... (JSON values, e.g. [0.05,0.02]); KEYS is a\n"
            "--set key path, or several joined by '+' that take the same value, or one each when a list\n"
            "value gives one per key separated by ';' (a pair's separation:\n"
            "--vary 'bodies.0.start_m.0+bodies.1.start_m.0=0.55;0.65,0.54;0.66,0.35;0.85').\n"
            "Threads per run are cores / N unless the scene or --threads sets them.\n"
            "Under mpirun or srun the runs spread over the ranks, longest predicted (particle-steps)\n"
            "first, each rank taking the next when it finishes, on its node's cores / ranks there; rank 0\n"
            "writes the table. A combination whose scene is invalid, or a run that fails, is a row with\n"
            "status failed and its error; the others run, and the sweep exits 1 saying how many failed.\n"
            "Running the same sweep again into DIR (stopped, killed or with failures) reuses every run\n"
            "whose directory holds a finished run of the same scene (threads, movies aside) and runs the rest; a\n"
            "run of a different scene there is an error naming it and the keys that differ. A DIR\n"
            "holding another sweep is replaced only with --force, once the new sweep is complete.",
            {{"--vary", true, true, "a key path and its values: key.path=a:b:step or key.path=v1,v2", "KEYS=VALUES"},
             {"--jobs", true, false, "runs at a time (default 1; not under mpirun: one per rank)", "N"},
             {"--out", true, false, "sweep directory (default out/<scene name>_sweep); the same sweep there is resumed", "DIR"},
             {"--force", false, false, "rerun every run; replace DIR once the new sweep completes"},
             {"--movies", false, false, "render each run's movies (off by default in sweeps)"},
             {"--no-paraview", false, false, "skip the ParaView .vti/.pvd files of the runs"}},
            1, 1, [](const Parsed& p) { return sweep_main(p, cli_driver_hooks()); }};
  for (auto& o : scene_run_options()) c.options.push_back(o);
  return c;
}

}  // namespace furrow::cli
