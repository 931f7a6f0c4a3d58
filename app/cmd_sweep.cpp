#include <iostream>

#include "app/commands.hpp"
namespace furrow::cli {
static int todo(const Parsed&) { std::cerr << "furrow sweep: not implemented yet\n"; return 1; }
Command command_sweep() {
  return {"sweep", "run a scene over parameter combinations", "furrow sweep SCENE --vary key.path=a:b:step ...", "", {}, 1, 1, todo};
}
}  // namespace furrow::cli
