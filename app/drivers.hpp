// `furrow sweep` and `furrow study` as the CLI and the Python module both run them: one driver
// each (app/cmd_sweep.cpp, app/cmd_study.cpp), given the parsed command line and what the program
// around them provides. The module links no renderer, so it passes no figure writer (no sweep.png
// or study.png) and polls Python for Ctrl-C instead of catching signals.
#pragma once
#include <functional>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "app/cli.hpp"
#include "engine/run.hpp"
#include "engine/scene/scene.hpp"
#include "render/plot.hpp"

namespace furrow::cli {

struct DriverHooks {
  // draws sweep.png / study.png (overwriting); empty: no figure
  std::function<void(const render::PlotFigure&, const std::string& path)> write_figure_png;
  // a run's movies (sweep --movies); empty: --movies is a usage error
  std::function<void(const std::string& run_dir, const Scene&)> render_movies;
  // polled between runs and after every step (from the runs' threads): true stops the sweep (runs
  // end with a checkpoint) or the study (rungs get SIGTERM). Empty: a study stops on SIGINT/SIGTERM,
  // a sweep never (a killed sweep is finished by running it again).
  std::function<bool()> stop_requested;
  // what happens, one event at a time: {"event": "run_done" | "rung_start" | "rung_done", ...}
  std::function<void(const nlohmann::json&)> on_event;
  // a sweep's runs' progress (dir name, progress), every run_progress_interval_s of wall time
  std::function<void(const std::string&, const RunProgress&)> on_run_progress;
  double run_progress_interval_s = 0.5;
  // where errors are written (default std::cerr)
  std::ostream* err = nullptr;
  // a scene error that leaves nothing to run is thrown (SceneError) instead of written to err
  bool throw_scene_errors = false;
  // the furrow CLI that runs a study's rungs (empty: this executable)
  std::string furrow_exe;
};

// The hooks `furrow sweep` and `furrow study` run with; the CLI's main() gives them its renderer.
DriverHooks& cli_driver_hooks();

// Exit status as the CLI's: 0 done, 1 failed runs or an error (written to hooks.err), 130 stopped.
// Throw UsageError for a bad command line.
int sweep_main(const Parsed& p, const DriverHooks& hooks);
int study_main(const Parsed& p, const DriverHooks& hooks);

}  // namespace furrow::cli
