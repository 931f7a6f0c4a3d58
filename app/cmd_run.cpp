#include "app/commands.hpp"
#include <iostream>
namespace furrow::cli {
static int run_main(const Parsed&) { std::cerr << "furrow run: not implemented yet\n"; return 1; }
Command command_run() {
  return {"run", "run a scene: forces.csv, frames, movies under out/", "furrow run SCENE.json [options]", "",
          {{"--out", true, false, "run directory (default out/<scene name>)", "DIR"},
           {"--set", true, true, "override a scene value", "key.path=value"},
           {"--force", false, false, "replace an existing run directory"}},
          1, 1, run_main};
}
}  // namespace furrow::cli
