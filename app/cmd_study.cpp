// furrow study: one scene over a ladder of settings, each rung a child `furrow run` (so its peak
// memory is its own and a crash or Ctrl-C loses only that rung), cheapest first, with the wall time
// of each rung predicted from the finished ones; the table is rewritten after every rung. In the app
// core: the Python module's furrow.study runs this same driver (app/drivers.hpp), its rungs runs of
// the furrow CLI.
#include <signal.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>

#include "app/calibration.hpp"
#include "app/commands.hpp"
#include "app/drivers.hpp"
#include "app/progress.hpp"
#include "app/run_dirs.hpp"
#include "app/study.hpp"
#include "app/sweep.hpp"
#include "engine/io/atomic_file.hpp"
#include "engine/io/field_store.hpp"
#include "engine/scene/scene_io.hpp"
#include "render/plot.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace furrow::cli {

namespace {

volatile sig_atomic_t g_stop = 0;
void on_stop(int) { g_stop = 1; }

bool is_dx_ladder(const sweep::Vary& v) {
  return v.keys.size() == 1 && (v.keys[0] == "domain.dx_m" || v.keys[0] == "/domain/dx_m");
}

struct Job {
  size_t rung;
  std::chrono::steady_clock::time_point start;
};

}  // namespace

int study_main(const Parsed& p, const DriverHooks& hooks) {
  std::ostream& err = hooks.err ? *hooks.err : std::cerr;
  const std::string scene_path = p.positional[0];
  const bool quiet = p.has("--quiet");

  // ---- everything is checked before anything runs or is written ----
  const std::vector<sweep::Vary> ladders = parse_varies(
      p, "--ladder", "nothing to study: give at least one --ladder KEY=VALUES, e.g. --ladder domain.dx_m=0.01,0.005,0.0025");
  study::Quantity q;
  try {
    q = study::parse_quantity(p.get("--quantity", "drag_mean"));
  } catch (const study::StudyError& e) {
    throw UsageError(e.what());
  }
  const std::string body = p.get("--body", "");
  const int jobs_asked = parse_jobs(p);

  const auto combos = sweep::combinations(ladders);
  std::vector<Scene> scenes;
  Scene base;
  try {
    base = load_scene_for_cli(p, scene_path);
    for (const auto& c : combos) scenes.push_back(load_varied_scene(p, scene_path, ladders, c, "--ladder"));
  } catch (const SceneError& e) {
    if (hooks.throw_scene_errors) throw;
    err << "furrow study: " << e.what() << "\n";
    return 1;
  }
  for (size_t r = 0; r < scenes.size(); ++r) {
    const std::string why = study::cannot_produce(scenes[r], q, body);
    if (!why.empty()) {
      err << "furrow study: --quantity " << study::quantity_name(q) << ": " << scene_path << " cannot produce it"
                << (scenes.size() > 1 && r > 0 ? " (rung " + std::to_string(r + 1) + ")" : "") << ": " << why << "\n";
      return 1;
    }
  }
  const auto names = sweep::run_dir_names(base.name, ladders, combos);
  const int jobs = std::max(1, std::min<int>(jobs_asked, int(scenes.size())));
  const int cores = std::max(1u, std::thread::hardware_concurrency());
  const int threads_each = std::max(1, cores / jobs);

  std::vector<study::Rung> rungs(scenes.size());
  for (size_t r = 0; r < rungs.size(); ++r) {
    auto& g = rungs[r];
    if (scenes[r].solver.threads == 0) scenes[r].solver.threads = threads_each;
    scenes[r].outputs.movies.clear();
    g.dir = names[r];
    for (size_t k = 0; k < ladders.size(); ++k) {
      g.values.push_back(ladders[k].values[combos[r][k]]);
      if (!is_dx_ladder(ladders[k])) g.group += (g.group.empty() ? "" : ", ") + ladders[k].column + "=" + g.values.back();
    }
    g.dx_m = scenes[r].domain.dx_m;
    g.estimated_particle_steps = estimate_particle_steps(scenes[r]);
    g.predicted_wall_s = g.value = NAN;
    g.threads = scenes[r].solver.threads;
  }

  const fs::path out_dir =
      fs::absolute(p.get("--out", (fs::path("out") / (base.name + "_study")).string())).lexically_normal();
  // a rung whose directory holds something else is not overwritten: say so before running anything
  std::vector<std::string> conflicts;
  for (size_t r = 0; r < rungs.size(); ++r) {
    const RunDirMatch m = match_run_dir(out_dir / rungs[r].dir, scenes[r]);
    if (m.state == RunDirState::same_scene) rungs[r].reused = true;
    else if (m.state == RunDirState::other_scene) conflicts.push_back((out_dir / rungs[r].dir).string() + ": " + m.why);
    else if (m.state == RunDirState::incomplete)
      fs::remove_all(out_dir / rungs[r].dir);  // an incomplete rung directory holds no finished result
  }
  if (!conflicts.empty()) {
    err << "furrow study: " << out_dir.string() << " holds runs that are not this study's rungs:\n";
    for (const auto& c : conflicts) err << "  " << c << "\n";
    err << "pass --out DIR for a new study\n";
    return 1;
  }

  fs::create_directories(out_dir / "scenes");
  fs::create_directories(out_dir / "logs");
  remove_stale_partials(out_dir);
  // predictions made by an earlier invocation stay with the rungs it finished
  if (fs::exists(out_dir / "study.json")) {
    try {
      const auto old = nlohmann::json::parse(read_text(out_dir / "study.json"));
      for (const auto& e : old.value("rungs", nlohmann::json::array()))
        for (auto& g : rungs)
          if (g.reused && e.value("dir", "") == g.dir && e.contains("predicted_wall_s") && e["predicted_wall_s"].is_number())
            g.predicted_wall_s = e["predicted_wall_s"].get<double>(), g.predicted_from = e.value("predicted_from", "");
    } catch (const std::exception&) {
      // an unreadable old table only loses old predictions
    }
  }

  auto collect = [&](size_t r) {
    auto& g = rungs[r];
    const auto [j, metrics] = read_finished_run(out_dir / g.dir, scenes[r]);
    std::string why;
    g.value = study::extract(q, metrics, j, body, &why);
    g.error = std::isfinite(g.value) ? "" : why;
    g.wall_s = j.value("wall_seconds", 0.0);
    g.particles = j.value("particles", 0.0);
    g.steps = j.value("steps", 0.0);
    g.particle_steps = g.particles * g.steps;
    g.peak_resident_bytes = j.value("peak_resident_bytes", 0.0);
    g.state_bytes = j.value("state_bytes_per_particle", 0.0) * g.particles;
    g.threads = j.value("threads", g.threads);
    g.ok = true;
  };
  size_t reused = 0;
  for (size_t r = 0; r < rungs.size(); ++r)
    if (rungs[r].reused) {
      try {
        collect(r);
        ++reused;
      } catch (const std::exception& e) {
        err << "furrow study: " << (out_dir / rungs[r].dir).string() << ": cannot read its results: " << e.what()
                  << "\npass --out DIR for a new study\n";
        return 1;
      }
    }

  bool plotted = false;
  // writes the tables (and at the end the figure) from an analysed copy of the rungs, returned
  auto write_outputs = [&](bool final_figure) {
    auto copy = rungs;
    const study::Summary s = study::analyse(copy);
    write_file_atomic((out_dir / "study.csv").string(), study::study_csv(ladders, q, copy));
    write_file_atomic((out_dir / "study.md").string(), study::study_markdown(base.name, ladders, q, body, copy, s));
    nlohmann::json j;
    j["scene"] = scene_path;
    j["scene_name"] = base.name;
    j["sets"] = p.all("--set");
    j["quantity"] = study::quantity_name(q);
    j["quantity_definition"] = study::quantity_meaning(q);
    j["body"] = body;
    for (const auto& l : ladders) j["ladders"].push_back({{"spec", l.spec}, {"keys", l.keys}, {"values", l.values}});
    j["reference"] = std::isfinite(s.reference) ? nlohmann::json(s.reference) : nlohmann::json(nullptr);
    j["reference_from"] = s.reference_from;
    auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    for (const auto& g : copy)
      j["rungs"].push_back({{"dir", g.dir},
                            {"values", g.values},
                            {"status", g.ok ? (g.reused ? "reused" : "ok") : (g.error.empty() ? "pending" : "failed")},
                            {"error", g.error},
                            {"value", num(g.value)},
                            {"predicted_wall_s", num(g.predicted_wall_s)},
                            {"predicted_from", g.predicted_from},
                            {"wall_s", g.ok ? num(g.wall_s) : nlohmann::json(nullptr)},
                            {"estimated_particle_steps", g.estimated_particle_steps}});
    write_file_atomic((out_dir / "study.json").string(), j.dump(2) + "\n");
    if (final_figure && hooks.write_figure_png) try {
        hooks.write_figure_png(study::study_figure(base.name, q, copy, s), (out_dir / "study.png").string());
        plotted = true;
      } catch (const std::exception& e) {
        err << "furrow study: warning: no study.png: " << e.what() << "\n";
      }
    return std::make_pair(copy, s);
  };

  // ---- rungs, cheapest first, `jobs` at a time, each a child `furrow run` ----
  std::vector<size_t> order;
  for (size_t r = 0; r < rungs.size(); ++r)
    if (!rungs[r].reused) order.push_back(r);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return rungs[a].estimated_particle_steps < rungs[b].estimated_particle_steps;
  });
  if (!quiet) {
    // the threads the rungs run on: --threads / solver.threads where set, else cores / jobs
    const int threads = scenes.front().solver.threads;
    const bool same = std::all_of(scenes.begin(), scenes.end(), [&](const Scene& x) { return x.solver.threads == threads; });
    const std::string each = same ? std::to_string(threads) + (threads == 1 ? " thread" : " threads") : "the rungs' own threads";
    std::fprintf(stderr, "furrow study: %zu rungs of %s (%zu already done), %d at a time, %s each -> %s\n",
                 rungs.size(), base.name.c_str(), reused, jobs, each.c_str(), out_dir.string().c_str());
  }
  write_outputs(false);

  const std::string exe = hooks.furrow_exe.empty() ? fs::read_symlink("/proc/self/exe").string() : hooks.furrow_exe;
  g_stop = 0;
  if (!hooks.stop_requested) {  // the CLI: a signal stops the study; the module polls Python instead
    struct sigaction sa {};
    sa.sa_handler = on_stop;
    sigaction(SIGTERM, &sa, nullptr);
    sigaction(SIGINT, &sa, nullptr);
  }
  auto stop = [&] { return g_stop || (hooks.stop_requested && hooks.stop_requested() && (g_stop = 1)); };
  const auto calibration = load_calibration();  // predicts the first rung, when there is one
  std::map<pid_t, Job> running;
  size_t next = 0, finished = reused, failed = 0;
  const long long sigterm_after = sigterm_self_at("FURROW_SIGTERM_AFTER_RUNGS");
  long long finished_here = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while ((next < order.size() || !running.empty()) && !stop()) {
    while (next < order.size() && int(running.size()) < jobs && !stop()) {
      const size_t r = order[next++];
      auto& g = rungs[r];
      g.predicted_wall_s = study::predict_wall_s(rungs, g, &g.predicted_from);
      if (!std::isfinite(g.predicted_wall_s) && calibration) {
        std::string how;
        g.predicted_wall_s = predict_run_wall_s(*calibration, scenes[r], &how);
        g.predicted_from = "furrow bench calibration, " + how;
      }
      const fs::path scene_file = out_dir / "scenes" / (g.dir + ".json");
      write_file_atomic(scene_file.string(), format_scene(scenes[r]));
      if (!quiet)
        std::fprintf(stderr, "[%zu/%zu] %s: %.3g particle-steps, predicted %s (%s)\n", finished + running.size() + 1,
                     rungs.size(), g.dir.c_str(), g.estimated_particle_steps,
                     std::isfinite(g.predicted_wall_s) ? study::wall_text(g.predicted_wall_s).c_str() : "unknown",
                     g.predicted_from.c_str());
      std::vector<std::string> args = {exe, "run", scene_file.string(), "--out", (out_dir / g.dir).string(),
                                       "--no-movies", "--no-paraview"};
      if (p.has("--yes")) args.push_back("--yes");
      // one rung at a time on a terminal: its own progress bar shows; otherwise rungs run quietly
      const bool show = jobs == 1 && !quiet;
      if (!show) args.push_back("--quiet");
      posix_spawn_file_actions_t fa;
      posix_spawn_file_actions_init(&fa);
      const std::string log = (out_dir / "logs" / (g.dir + ".log")).string();
      posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (!show) posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      pid_t pid = 0;
      const int rc = posix_spawn(&pid, exe.c_str(), &fa, nullptr, argv.data(), environ);
      posix_spawn_file_actions_destroy(&fa);
      if (rc != 0) {
        g.error = std::string("could not start ") + exe + ": " + std::strerror(rc);
        ++finished, ++failed;
        continue;
      }
      running[pid] = {r, std::chrono::steady_clock::now()};
      if (hooks.on_event)
        hooks.on_event({{"event", "rung_start"}, {"dir", g.dir}, {"values", g.values},
                        {"predicted_wall_s", std::isfinite(g.predicted_wall_s) ? nlohmann::json(g.predicted_wall_s)
                                                                               : nlohmann::json(nullptr)},
                        {"started", finished + running.size()}, {"rungs", rungs.size()}});
      // FURROW_SIGTERM_AFTER_RUNGS (tests of the stop): the signal arrives with a rung running
      if (sigterm_after > 0 && finished_here == sigterm_after) std::raise(SIGTERM);
    }
    // a stop that came while rungs were being started must not wait for them to finish
    if (running.empty() || stop()) break;
    // polls its own children only (a Python process may have others), checking for a stop between
    int status = 0;
    pid_t pid = 0;
    for (const auto& [child, job] : running) {
      const pid_t w = ::waitpid(child, &status, WNOHANG);
      if (w == child || (w < 0 && errno != EINTR)) {
        if (w < 0) status = 255 << 8;  // cannot be waited for (not expected): a failed rung
        pid = child;
        break;
      }
    }
    if (pid == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      continue;
    }
    const auto it = running.find(pid);
    const size_t r = it->second.rung;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second.start).count();
    running.erase(it);
    auto& g = rungs[r];
    ++finished;
    ++finished_here;
    const bool exited_ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (exited_ok) {
      try {
        collect(r);
      } catch (const std::exception& e) {
        g.ok = false;
        g.error = std::string("cannot read its results: ") + e.what();
      }
    } else {
      // the last line of the child's log says why
      std::string last, line;
      std::istringstream in(read_text(out_dir / "logs" / (g.dir + ".log")));
      while (std::getline(in, line))
        if (!line.empty()) last = line;
      g.error = (WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                     : "exit status " + std::to_string(WEXITSTATUS(status))) +
                (last.empty() ? "" : ": " + last);
    }
    failed += g.ok ? 0 : 1;
    write_outputs(false);
    if (hooks.on_event)
      hooks.on_event({{"event", "rung_done"}, {"dir", g.dir}, {"values", g.values}, {"ok", g.ok}, {"error", g.error},
                      {"value", g.ok && std::isfinite(g.value) ? nlohmann::json(g.value) : nlohmann::json(nullptr)},
                      {"wall_s", g.ok ? g.wall_s : wall}, {"finished", finished}, {"rungs", rungs.size()}});
    if (!quiet) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      char value[96] = "";
      if (g.ok && std::isfinite(g.value))
        std::snprintf(value, sizeof value, "%s %.5g %s", study::quantity_name(q).c_str(), g.value,
                      study::quantity_unit(q).c_str());
      std::fprintf(stderr, "[%zu/%zu] %s: %s in %s (predicted %s); %s; study elapsed %s\n", finished, rungs.size(),
                   g.dir.c_str(), g.ok ? "done" : "FAILED", study::wall_text(g.ok ? g.wall_s : wall).c_str(),
                   std::isfinite(g.predicted_wall_s) ? study::wall_text(g.predicted_wall_s).c_str() : "-",
                   g.ok && std::isfinite(g.value) ? value : g.error.c_str(), format_duration(elapsed).c_str());
    }
  }
  if (g_stop) {
    for (const auto& [pid, job] : running) ::kill(pid, SIGTERM);
    for (const auto& [pid, job] : running) ::waitpid(pid, nullptr, 0);
    remove_stale_partials(out_dir);
    write_outputs(true);
    std::fprintf(stderr, "furrow study: stopped; %zu of %zu rungs are done and in %s/study.csv. Run the same command "
                 "again to finish the rest.\n", finished, rungs.size(), out_dir.string().c_str());
    return 130;
  }
  const auto [copy, s] = write_outputs(true);
  size_t no_value = 0;
  for (const auto& g : copy) no_value += g.ok && !std::isfinite(g.value);
  std::printf("study of %zu rungs (%zu reused, %zu failed, %zu without a value): %s/study.md, study.csv%s\n",
              rungs.size(), reused, failed, no_value, out_dir.string().c_str(), plotted ? ", study.png" : "");
  if (std::isfinite(s.reference))
    std::printf("reference %s = %.6g %s (%s)\n", study::quantity_name(q).c_str(), s.reference,
                study::quantity_unit(q).c_str(), s.reference_from.c_str());
  for (const auto& g : copy)
    if (g.ok && std::isfinite(g.value))
      std::printf("  %-56s %10.5g %s  error %6.2f%%  wall %s\n", g.dir.c_str(), g.value, study::quantity_unit(q).c_str(),
                  100.0 * g.error_relative, study::wall_text(g.wall_s).c_str());
  return failed ? 1 : 0;
}

Command command_study() {
  Command c{"study", "what accuracy costs: a scene over a ladder of dx / shape functions / particles per cell",
            "furrow study SCENE.json --ladder KEY=VALUES [--ladder ...] [--quantity Q] [--body NAME] [--jobs N] [--out DIR]",
            "Runs the scene at every rung (every combination of the --ladder values), cheapest first, each\n"
            "as a child `furrow run` into DIR/<scene>_<key>=<value>_..., and reads one quantity from each:\n"
            "  drag_mean    mean drag over the scene's averaging window (N/m; default)\n"
            "  lift_mean    mean lift over the averaging window (N/m)\n"
            "  peak_force   initial peak of the drag (N/m; the drag must give 5% after it)\n"
            "  wedge_angle  apex angle of the rigid wedge under a descending plate (deg; needs the velocity\n"
            "               field stored in frames)\n"
            "  fluctuation  the lead body's drag: RMS about a line in travel over its mean (paper case 3)\n"
            "Before each rung it prints the wall time predicted from the finished rungs (a line in\n"
            "particle-steps through the rungs of the same settings); after each it rewrites in DIR:\n"
            "  study.csv   per rung: the quantity, its difference from the finest rung of the same settings\n"
            "              and from their Richardson extrapolation in dx (three rungs, any ratio), the\n"
            "              observed order, the error against the reference, predicted and measured wall\n"
            "              time, particles, steps, peak memory (units in the column names)\n"
            "  study.md    the same as a table, the reference, and the cheapest rung within 10/5/2/1%\n"
            "  study.json  settings and per-rung status; study.png: error vs wall time (log-log, rungs\n"
            "              labelled by dx) and the quantity vs dx\n"
            "The reference is the Richardson value of the settings that hold the most expensive rung, or\n"
            "that rung's value. Ctrl-C or a failed rung keeps the finished rungs and their table; running the\n"
            "same command again reuses every rung whose directory holds a complete run of the same scene\n"
            "(threads, movies aside) and runs the rest. A directory holding a different run is an error (nothing\n"
            "runs). Threads per rung: cores / N unless the scene or --threads sets them; for timings that\n"
            "compare, keep --jobs 1. Rungs write no movies and no ParaView files; each rung's scene is in\n"
            "DIR/scenes and its output in DIR/logs. FURROW_SIGTERM_AFTER_RUNGS=N in the environment makes\n"
            "the study send itself SIGTERM as it starts a rung after N have finished (for tests of the stop).",
            {{"--ladder", true, true, "a key path and its rungs: key.path=v1,v2,v3 or key.path=a:b:step", "KEY=VALUES"},
             {"--quantity", true, false, "drag_mean (default), lift_mean, peak_force, wedge_angle or fluctuation", "Q"},
             {"--body", true, false, "the body whose force is read (default: the first moving body)", "NAME"},
             {"--jobs", true, false, "rungs at a time (default 1)", "N"},
             {"--out", true, false, "study directory (default out/<scene name>_study); an existing one is resumed",
              "DIR"}},
            1, 1, [](const Parsed& p) { return study_main(p, cli_driver_hooks()); }};
  for (auto& o : scene_run_options()) c.options.push_back(o);
  return c;
}

}  // namespace furrow::cli
