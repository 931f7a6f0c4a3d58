#include "app/commands.hpp"
#include <iostream>
namespace furrow::cli {
static int todo(const Parsed& p) { std::cerr << "furrow " << p.command->name << ": not implemented yet\n"; return 1; }
Command command_validate() { return {"validate", "check a scene without running it", "furrow validate SCENE.json", "", {}, 1, 1, todo}; }
Command command_new() { return {"new", "write a scene from a template", "furrow new TEMPLATE -o FILE", "", {{"-o", true, false, "output file", "FILE"}}, 1, 1, todo}; }
Command command_templates() { return {"templates", "list scene templates", "furrow templates", "", {}, 0, 0, todo}; }
}  // namespace furrow::cli
