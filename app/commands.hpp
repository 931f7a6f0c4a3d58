// One function per subcommand, each defined in its own app/cmd_*.cpp.
#pragma once
#include "app/cli.hpp"
#include "app/sweep.hpp"
#include "engine/scene/scene.hpp"

namespace furrow::cli {
Command command_run();        // app/cmd_run.cpp
Command command_validate();   // app/cmd_scene.cpp
Command command_new();        // app/cmd_scene.cpp
Command command_templates();  // app/cmd_scene.cpp
Command command_render();     // app/cmd_render.cpp
Command command_demo();       // app/cmd_render.cpp
Command command_compare();    // app/cmd_render.cpp
Command command_inspect();    // app/cmd_inspect.cpp
Command command_edit();       // app/cmd_edit.cpp
Command command_sweep();      // app/cmd_sweep.cpp
Command command_study();      // app/cmd_study.cpp
Command command_bench();      // app/cmd_bench.cpp

// Shared by run and sweep (app/cmd_run.cpp): the scene from PATH with --set/--threads/--yes
// applied, and the option specs for those flags. Throws SceneError.
Scene load_scene_for_cli(const Parsed& p, const std::string& path);
std::vector<OptionSpec> scene_run_options();
// load_scene_for_cli plus one combination of sweep/study values (`option` is "--vary" or
// "--ladder"): an error in a value the option wrote names the option instead of a --set.
Scene load_varied_scene(const Parsed& p, const std::string& path, const std::vector<sweep::Vary>& varies,
                        const std::vector<size_t>& combo, const std::string& option);
// The --vary / --ladder specs (each KEYS=VALUES, no key twice); throws UsageError naming `option`,
// with `if_none` when there are none.
std::vector<sweep::Vary> parse_varies(const Parsed& p, const std::string& option, const std::string& if_none);
// --size WxH (16..8192 each); throws UsageError (app/cmd_render.cpp).
void parse_size(const std::string& s, int* w, int* h);
// The CLI's worker count option (--jobs N, 1..1024, default 1); throws UsageError.
int parse_jobs(const Parsed& p);
// For tests that stop a run or a study by a signal at a known point rather than at a wall-clock
// moment: the count in environment variable `name` (FURROW_SIGTERM_AT_STEP for run,
// FURROW_SIGTERM_AFTER_RUNGS for study), after which the command sends itself SIGTERM; 0 when
// unset or not a positive whole number (app/cmd_run.cpp).
long long sigterm_self_at(const char* name);
// The view options of inspect and edit (--headless, --script, --exit-after-script, --size WxH):
// throws UsageError for a bad combination; returns 2, after saying why on stderr, when a window is
// wanted but none can open here, else 0 (app/cmd_inspect.cpp).
struct ViewOptions {
  bool headless = false;
  int width = 1280, height = 720;
};
int view_options(const Parsed& p, const std::string& command, ViewOptions* o);
}  // namespace furrow::cli
