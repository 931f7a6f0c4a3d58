// One function per subcommand, each defined in its own app/cmd_*.cpp.
#pragma once
#include "app/cli.hpp"
#include "engine/scene.hpp"

namespace furrow::cli {
Command command_run();        // app/cmd_run.cpp
Command command_validate();   // app/cmd_scene.cpp
Command command_new();        // app/cmd_scene.cpp
Command command_templates();  // app/cmd_scene.cpp
Command command_render();     // app/cmd_render.cpp
Command command_demo();       // app/cmd_render.cpp
Command command_compare();    // app/cmd_render.cpp
Command command_sweep();      // app/cmd_sweep.cpp

// Shared by run and sweep (app/cmd_run.cpp): the scene from PATH with --set/--threads/--yes
// applied, and the option specs for those flags. Throws SceneError.
Scene load_scene_for_cli(const Parsed& p, const std::string& path);
std::vector<OptionSpec> scene_run_options();
}  // namespace furrow::cli
