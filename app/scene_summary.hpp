// `furrow validate`'s summary of a scene: what a run will cost and produce. Shared by the CLI and
// the editor's validate action, which must print the same.
#pragma once

#include <string>

#include "engine/scene/scene.hpp"

namespace furrow::cli {
// First line 'scene "NAME" (SOURCE) is valid'.
std::string scene_summary(const Scene& s, const std::string& source);
}  // namespace furrow::cli
