// furrow run: scene file -> Scene -> Simulation -> run directory (+ movies rendered from the
// stored frames).
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "app/calibration.hpp"
#include "app/commands.hpp"
#include "app/progress.hpp"
#include "app/run_movies.hpp"
#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

namespace {

volatile sig_atomic_t g_stop_signal = 0;
void request_stop(int sig) { g_stop_signal = sig; }

// Minutes between checkpoints: default 30; 0 turns them off.
double checkpoint_interval_s(const Parsed& p) {
  const std::string text = p.get("--checkpoint-every", "30");
  char* end = nullptr;
  const double minutes = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(minutes >= 0.0) || minutes > 1e6)
    throw UsageError("--checkpoint-every " + text + ": expected minutes of wall time >= 0 (0: no periodic checkpoints)");
  return 60.0 * minutes;
}

}  // namespace

static int run_main(const Parsed& p) {
  Scene scene;
  try {
    scene = load_scene_for_cli(p, p.positional[0]);
  } catch (const SceneError& e) {
    std::cerr << "furrow run: " << e.what() << "\n";
    return 1;
  }
  RunOptions opt;
  opt.out_dir = p.get("--out", (fs::path("out") / scene.name).string());
  opt.force = p.has("--force");
  opt.write_paraview = !p.has("--no-paraview");
  opt.resume = p.has("--resume") || p.has("--resume-any-build");
  opt.resume_any_build = p.has("--resume-any-build");
  opt.checkpoint_interval_s = checkpoint_interval_s(p);
  if (fs::exists(opt.out_dir) && !opt.force) {
    std::cerr << "furrow run: " << opt.out_dir
              << " already exists; pass --out DIR for a new run or --force to replace it\n";
    return 1;
  }
  std::string how;
  const auto calibration = load_calibration();
  const double predicted_s = calibration ? predict_run_wall_s(*calibration, scene, &how) : NAN;
  if (!p.has("--quiet") && std::isfinite(predicted_s))
    std::fprintf(stderr, "%s: predicted %s of solver time (%s)\n", scene.name.c_str(), format_duration(predicted_s).c_str(),
                 how.c_str());
  if (!opt.resume && !p.has("--quiet"))
    for (const std::string& left : checkpoint_dirs(opt.out_dir))
      std::fprintf(stderr, "%s holds a checkpoint of a stopped run; this run starts afresh (--resume continues it)\n",
                   left.c_str());
  // SIGINT/SIGTERM (Ctrl-C, a batch system's time limit): checkpoint after the current step and
  // stop; a second signal kills at once
  struct sigaction sa {};
  sa.sa_handler = request_stop;
  sa.sa_flags = SA_RESETHAND;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  opt.stop_requested = [sigterm_at = sigterm_self_at("FURROW_SIGTERM_AT_STEP"), steps = 0LL]() mutable {
    if (sigterm_at > 0 && ++steps == sigterm_at) std::raise(SIGTERM);  // polled once a step
    return g_stop_signal != 0;
  };
  ProgressPrinter progress(scene.name, p.has("--quiet"));
  opt.progress = [&](const RunProgress& r) { progress(r); };
  RunSummary s;
  try {
    s = run_scene(scene, opt);
  } catch (const std::runtime_error& e) {
    progress.finish();
    std::cerr << "furrow run: " << e.what() << "\n";
    return 1;
  }
  progress.finish();
  if (s.resumed_from_step >= 0 && !p.has("--quiet"))
    std::fprintf(stderr, "%s: resumed from the checkpoint at step %lld\n", scene.name.c_str(),
                 (long long)s.resumed_from_step);
  if (s.stopped) {
    std::fprintf(stderr,
                 "%s: stopped by signal %d at step %lld (t = %.6g s); checkpoint in %s/checkpoint.\n"
                 "Continue with the same command and --resume.\n",
                 scene.name.c_str(), int(g_stop_signal), (long long)s.run_json["steps"].get<int64_t>(),
                 s.run_json["end_time_s"].get<double>(), s.out_dir.c_str());
    return 130;  // as study: stopped by the user
  }

  const auto& j = s.run_json;
  std::printf("%s: %zu particles, %lld steps, dt %.3g..%.3g s, %.1f s wall, %.2f M particle-steps/s", scene.name.c_str(),
              j["particles"].get<size_t>(), (long long)j["steps"].get<int64_t>(), j["dt_min_s"].get<double>(),
              j["dt_max_s"].get<double>(), j["wall_seconds"].get<double>(),
              j["particle_steps_per_second"].get<double>() / 1e6);
  if (std::isfinite(predicted_s))
    std::printf(" (solver %.1f s against %.1f s predicted by the calibration)", j["solver_seconds"].get<double>(),
                predicted_s);
  std::printf("\n");
  for (const auto& b : s.bodies)
    std::printf("  %-12s mean F = (%.4g, %.4g) N/m over the averaging window, peak (%.4g, %.4g) N/m\n",
                b.name.c_str(), b.mean_N_per_m.x(), b.mean_N_per_m.y(), b.peak_N_per_m.x(), b.peak_N_per_m.y());
  if (!p.has("--no-movies")) render_run_movies(s.out_dir, scene, p.has("--quiet"));
  std::printf("outputs in %s\n", s.out_dir.c_str());
  return 0;
}

Command command_run() {
  Command c{"run", "run a scene: forces.csv, OpenVDB frames, movies into a run directory",
            "furrow run SCENE.json [--out DIR] [--set key.path=value ...] [--force]",
            "Runs the scene and writes DIR (default out/<scene name>):\n"
            "  scene.json   the scene as run, every default filled in\n"
            "  forces.csv   t_s,body,x_m,y_m,Fx_N_per_m,Fy_N_per_m,torque_N_m_per_m,angle_deg,vx_m_s,vy_m_s,\n"
            "               omega_rad_s (force and torque of the media on each body,\n"
            "               per metre out of plane; averaged over outputs.force_interval_s)\n"
            "  frames/      frame_NNNNN.vdb (OpenVDB) and .vti, with frames.pvd for ParaView; with\n"
            "               outputs.points, points_NNNNN.vdb: the material points (OpenVDB point data)\n"
            "  movies/      <field>.mp4 for each field in outputs.movies and <name>.mp4 for outputs.layout\n"
            "               (the paper's layout), each with its last frame as a poster PNG\n"
            "  run.json     particles, steps, dt range, wall time, particle-steps/s, peak memory, force summary\n"
            "The run is built under DIR.partial-PID and renamed into place when complete; an existing DIR\n"
            "is never overwritten unless --force is given. A scene with errors writes nothing.\n"
            "Checkpoints: every --checkpoint-every minutes, and on SIGINT or SIGTERM (Ctrl-C, a batch\n"
            "system's time limit), the run's whole state goes to DIR.partial-PID/checkpoint; a signal then\n"
            "stops the run with exit status 130. The same command with --resume continues from there with\n"
            "results identical to an uninterrupted run (any thread count); run.json's wall and solver\n"
            "seconds are summed over the segments. A checkpoint is resumed only by the build that wrote\n"
            "it (run.json \"build\": version and a hash of the engine library, the same for this CLI and\n"
            "the Python module built with it) unless --resume-any-build is given.\n"
            "FURROW_SIGTERM_AT_STEP=N in the environment makes the run send itself SIGTERM after step N\n"
            "(N counted from this segment's start; for tests of the stop).",
            {{"--out", true, false, "run directory (default out/<scene name>)", "DIR"},
             {"--force", false, false, "replace an existing run directory once the new run completes"},
             {"--no-movies", false, false, "skip rendering movies"},
             {"--no-paraview", false, false, "skip the ParaView .vti/.pvd files"},
             {"--resume", false, false, "continue a stopped run of this scene from its checkpoint (none: start afresh)"},
             {"--resume-any-build", false, false,
              "--resume, also from a checkpoint another build wrote (run.json then lists the builds)"},
             {"--checkpoint-every", true, false, "minutes of wall time between checkpoints (default 30; 0: only on a signal)",
              "MIN"}},
            1, 1, run_main};
  for (auto& o : scene_run_options()) c.options.push_back(o);
  return c;
}

}  // namespace furrow::cli
