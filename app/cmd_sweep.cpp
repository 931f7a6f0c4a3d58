// furrow sweep: one scene over the cartesian product of --vary values, N runs at a time, each
// into its own run directory, then sweep.csv (+ sweep.json, sweep.png) over all of them.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <thread>

#include "app/commands.hpp"
#include "app/progress.hpp"
#include "app/run_movies.hpp"
#include "app/sweep.hpp"
#include "app/sweep_plot.hpp"
#include "engine/field_store.hpp"
#include "engine/run.hpp"
#include "engine/scene_io.hpp"
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
  return s;
}

int sweep_main(const Parsed& p) {
  const std::string scene_path = p.positional[0];
  const bool quiet = p.has("--quiet");

  // ---- everything is checked before anything is written ----
  const std::vector<sweep::Vary> varies = parse_varies(p, "--vary", "nothing to sweep: give at least one --vary KEYS=VALUES");
  const int jobs_asked = parse_jobs(p);

  Scene base;
  std::vector<std::vector<size_t>> combos = sweep::combinations(varies);
  std::vector<Scene> scenes;
  try {
    base = load_scene_for_cli(p, scene_path);
    for (const auto& c : combos) scenes.push_back(load_varied_scene(p, scene_path, varies, c, "--vary"));
  } catch (const SceneError& e) {
    std::cerr << "furrow sweep: " << e.what() << "\n";
    return 1;
  }
  const std::vector<std::string> names = sweep::run_dir_names(base.name, varies, combos);

  const fs::path out_dir = fs::absolute(p.get("--out", (fs::path("out") / (base.name + "_sweep")).string())).lexically_normal();
  const bool force = p.has("--force");
  if (fs::exists(out_dir) && !force) {
    std::cerr << "furrow sweep: " << out_dir.string()
              << " already exists; pass --out DIR for a new sweep or --force to replace it\n";
    return 1;
  }

  const int jobs = std::max(1, std::min<int>(jobs_asked, int(scenes.size())));
  const int cores = std::max(1u, std::thread::hardware_concurrency());
  const int threads_each = std::max(1, cores / jobs);
  for (auto& s : scenes) {
    if (s.solver.threads == 0) s.solver.threads = threads_each;  // the scene or --threads decides otherwise
    if (!p.has("--movies")) s.outputs.movies.clear();
  }

  const fs::path tmp_dir = out_dir.string() + ".partial-" + std::to_string(::getpid());
  fs::remove_all(tmp_dir);
  fs::create_directories(tmp_dir);
  if (!quiet)
    std::fprintf(stderr, "furrow sweep: %zu runs of %s, %d at a time (%d thread%s each unless the scene sets threads) -> %s\n",
                 scenes.size(), base.name.c_str(), jobs, threads_each, threads_each == 1 ? "" : "s",
                 out_dir.string().c_str());

  // ---- runs, `jobs` at a time ----
  std::vector<sweep::SweepRow> rows(scenes.size());
  for (size_t r = 0; r < rows.size(); ++r) {
    rows[r].dir = names[r];
    for (size_t k = 0; k < varies.size(); ++k) rows[r].values.push_back(varies[k].values[combos[r][k]]);
  }
  std::atomic<size_t> next{0};
  std::mutex print_mutex, render_mutex;
  size_t done = 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto worker = [&] {
    for (size_t r = next++; r < scenes.size(); r = next++) {
      sweep::SweepRow& row = rows[r];
      const auto w0 = std::chrono::steady_clock::now();
      try {
        RunOptions opt;
        opt.out_dir = (tmp_dir / row.dir).string();
        opt.write_paraview = !p.has("--no-paraview");
        const RunSummary s = run_scene(scenes[r], opt);
        row.metrics = sweep::run_metrics(scenes[r], s, sweep::read_forces_csv(s.out_dir + "/forces.csv", scenes[r]));
        if (p.has("--movies")) {
          std::lock_guard<std::mutex> lock(render_mutex);  // one GL context at a time
          render_run_movies(s.out_dir, scenes[r], true);
        }
        row.ok = true;
      } catch (const std::exception& e) {
        row.error = e.what();
      }
      row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
      std::lock_guard<std::mutex> lock(print_mutex);
      ++done;
      if (quiet) continue;
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double eta = elapsed / double(done) * double(scenes.size() - done);
      std::fprintf(stderr, "[%zu/%zu] %s: %s in %.1f s wall%s%s; elapsed %s, sweep ETA %s\n", done, scenes.size(),
                   row.dir.c_str(), row.ok ? "done" : "FAILED", row.wall_s, row.ok ? ", " : ": ",
                   row.ok ? describe_run(row).c_str() : row.error.c_str(), format_duration(elapsed).c_str(),
                   format_duration(eta).c_str());
    }
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < jobs; ++j) pool.emplace_back(worker);
  for (auto& t : pool) t.join();

  // ---- table, description, figure ----
  write_file_atomic((tmp_dir / "sweep.csv").string(), sweep::sweep_csv(varies, rows));
  nlohmann::json j;
  j["scene"] = scene_path;
  j["scene_name"] = base.name;
  j["sets"] = p.all("--set");
  for (const auto& v : varies) j["vary"].push_back({{"spec", v.spec}, {"keys", v.keys}, {"values", v.values}});
  j["jobs"] = jobs;
  j["threads_per_run"] = threads_each;
  for (const auto& r : rows)
    j["runs"].push_back({{"dir", r.dir}, {"values", r.values}, {"status", r.ok ? "ok" : "failed"}, {"error", r.error},
                         {"wall_s", r.wall_s}});
  for (const auto& [name, meaning] : sweep::sweep_columns(varies, rows)) j["columns"][name] = meaning;
  j["definitions"] = {
      {"drag", "-F.u, u the unit velocity of the body at the start (the force opposing the motion), N/m"},
      {"lift", "F.n, n = u turned +90 degrees (for motion in +x: Fy, up), N/m"},
      {"w", "1 m: forces are per metre out of plane"},
      {"rho_d", "rho_g * packing_fraction of the bed"},
      {"depth", "below the top of the bed under the body at its start; evaluated at the middle of the averaging window"},
      {"z", "depth of a plate's bottom edge at the middle of the averaging window (mean over the moving boxes)"}};
  const sweep::SweepFigure figure = sweep::sweep_figure(base.name, varies, rows);
  j["figure"] = figure.kind;
  write_file_atomic((tmp_dir / "sweep.json").string(), j.dump(2) + "\n");
  bool plotted = false;
  try {
    render::write_figure_png(figure.figure, (tmp_dir / "sweep.png").string(), false);
    plotted = true;
  } catch (const std::exception& e) {
    std::cerr << "furrow sweep: warning: no sweep.png: " << e.what() << "\n";
  }

  if (fs::exists(out_dir)) {
    const fs::path old = out_dir.string() + ".replaced-" + std::to_string(::getpid());
    fs::rename(out_dir, old);
    fs::rename(tmp_dir, out_dir);
    fs::remove_all(old);
  } else {
    fs::create_directories(out_dir.parent_path());
    fs::rename(tmp_dir, out_dir);
  }

  size_t failed = 0;
  for (const auto& r : rows) failed += !r.ok;
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("sweep of %zu runs (%zu failed) in %s: %s/sweep.csv%s%s%s\n", rows.size(), failed,
              format_duration(total).c_str(), out_dir.string().c_str(), plotted ? " and sweep.png (" : "",
              plotted ? figure.kind.c_str() : "", plotted ? ")" : "");
  return failed ? 1 : 0;
}

}  // namespace

Command command_sweep() {
  Command c{"sweep", "run a scene over parameter combinations: sweep.csv and a summary plot",
            "furrow sweep SCENE.json --vary KEYS=VALUES [--vary ...] [--jobs N] [--out DIR] [--set key.path=value ...]",
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
            "--set key path, or several joined by '+' that take the same value. Threads per run are\n"
            "cores / N unless the scene or --threads sets them. Everything is checked before anything\n"
            "runs; an existing DIR is replaced only with --force, once the new sweep is complete.",
            {{"--vary", true, true, "a key path and its values: key.path=a:b:step or key.path=v1,v2", "KEYS=VALUES"},
             {"--jobs", true, false, "runs at a time (default 1)", "N"},
             {"--out", true, false, "sweep directory (default out/<scene name>_sweep)", "DIR"},
             {"--force", false, false, "replace an existing sweep directory once the new sweep completes"},
             {"--movies", false, false, "render each run's movies (off by default in sweeps)"},
             {"--no-paraview", false, false, "skip the ParaView .vti/.pvd files of the runs"}},
            1, 1, sweep_main};
  for (auto& o : scene_run_options()) c.options.push_back(o);
  return c;
}

}  // namespace furrow::cli
