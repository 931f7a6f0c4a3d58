#include "app/commands.hpp"
#include <iostream>
namespace furrow::cli {
static int todo(const Parsed& p) { std::cerr << "furrow " << p.command->name << ": not implemented yet\n"; return 1; }
Command command_render() { return {"render", "re-render stored frames to PNG or MP4", "furrow render RUN_DIR [options]", "", {}, 1, 1, todo}; }
Command command_demo() { return {"demo", "run the default scene and render its movie", "furrow demo [--out DIR]", "", {{"--out", true, false, "output root", "DIR"}}, 0, 0, todo}; }
}  // namespace furrow::cli
