// One function per subcommand, each defined in its own app/cmd_*.cpp.
#pragma once
#include "app/cli.hpp"

namespace furrow::cli {
Command command_run();        // app/cmd_run.cpp
Command command_validate();   // app/cmd_scene.cpp
Command command_new();        // app/cmd_scene.cpp
Command command_templates();  // app/cmd_scene.cpp
Command command_render();     // app/cmd_render.cpp
Command command_demo();       // app/cmd_render.cpp
}  // namespace furrow::cli
