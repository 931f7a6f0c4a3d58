#include "app/run_movies.hpp"

#include <iostream>

namespace furrow::cli {

void render_run_movies(const std::string& run_dir, const Scene& scene, bool quiet) {
  if (scene.outputs.movies.empty()) return;
  if (!quiet) std::cerr << "movies: not yet wired to the renderer\n";
}

}  // namespace furrow::cli
