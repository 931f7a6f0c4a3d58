// `furrow render` and `furrow demo`: argument handling only; drawing lives in render/.
#include <filesystem>
#include <iostream>

#include "app/commands.hpp"
#include "render/image_io.hpp"
#include "render/test_scene.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

static int todo(const Parsed& p) {
  std::cerr << "furrow " << p.command->name << ": not implemented yet\n";
  return 1;
}

Command command_render() {
  return {"render", "re-render stored frames to PNG or MP4", "furrow render RUN_DIR [options]", "", {}, 1, 1, todo};
}

static int demo_main(const Parsed& p) {
  const fs::path dir = fs::path(p.get("--out", "out")) / "demo";
  fs::create_directories(dir);
  // Keep earlier results: pick test_scene_2.png, _3, ... when the name is taken.
  const std::string path = render::next_free_path((dir / "test_scene.png").string());
  render::write_png(render::render_test_scene(1280, 720), path);
  std::cout << path << "\n";
  return 0;
}

Command command_demo() {
  return {"demo",
          "render the built-in check scene off-screen to DIR/demo/",
          "furrow demo [--out DIR]",
          "Renders the built-in check scene off-screen (no display needed) to DIR/demo/test_scene.png\n"
          "and prints the path written. An existing file is never replaced: the new image goes to\n"
          "the next free name (test_scene_2.png, test_scene_3.png, ...).",
          {{"--out", true, false, "output root (default: out)", "DIR"}},
          0,
          0,
          demo_main};
}

}  // namespace furrow::cli
