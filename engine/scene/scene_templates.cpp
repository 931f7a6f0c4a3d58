// Scene templates: scenes/*.json, embedded into the binary by cmake/embed_scenes.cmake.
#include <algorithm>

#include "engine/scene/scene_io.hpp"

namespace furrow {
namespace embedded {
struct EmbeddedScene {
  const char* name;
  const unsigned char* data;
  size_t size;
};
extern const EmbeddedScene kScenes[];
extern const size_t kSceneCount;
}  // namespace embedded

const std::vector<SceneTemplate>& scene_templates() {
  static const std::vector<SceneTemplate> all = [] {
    std::vector<SceneTemplate> out;
    for (size_t i = 0; i < embedded::kSceneCount; ++i) {
      const auto& e = embedded::kScenes[i];
      SceneTemplate t;
      t.name = e.name;
      t.text.assign(reinterpret_cast<const char*>(e.data), e.size);
      // the description is read leniently here; `furrow new` validates the whole template
      const auto j = nlohmann::json::parse(t.text, nullptr, false);
      if (j.is_object() && j.contains("description") && j["description"].is_string())
        t.description = j["description"].get<std::string>();
      out.push_back(std::move(t));
    }
    return out;
  }();
  return all;
}

const SceneTemplate* find_scene_template(const std::string& name) {
  std::string key = name;
  std::replace(key.begin(), key.end(), '-', '_');
  for (const auto& t : scene_templates())
    if (t.name == name || t.name == key) return &t;
  return nullptr;
}

}  // namespace furrow
