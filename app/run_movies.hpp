// Renders movies/<field>.mp4 for the fields a scene lists under outputs.movies, from the run
// directory's stored frames (the renderer never sees the solver).
#pragma once
#include <string>

#include "engine/scene/scene.hpp"

namespace furrow::cli {
void render_run_movies(const std::string& run_dir, const Scene& scene, bool quiet);
}
