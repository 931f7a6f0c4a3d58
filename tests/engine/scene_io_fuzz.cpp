// Fuzz-style robustness test of the scene reader, built with ASan + UBSan (ctest -L sanitize).
// Random byte flips, inserts and deletes of every template, and random edits of their JSON trees
// (odd values, deleted and added keys), go through parse_scene_text: each must parse cleanly (and
// round-trip) or throw SceneError; nothing else may escape, crash, or take long.
// usage: furrow_scene_fuzz SCENE_DIR [ITERATIONS]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "engine/scene/scene_io.hpp"

namespace fs = std::filesystem;
using furrow::SceneError;

namespace {

// Bytes worth inserting: JSON structure, digits, signs, and a few whole tokens' starts.
const std::string kAlphabet = "{}[]\":,.-+eE0123456789 \n\\tfnu/aszx_\x7f\xff";

std::string mutate(std::string s, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> n_edits(1, 4), op(0, 3);
  const int edits = n_edits(rng);
  for (int e = 0; e < edits; ++e) {
    const size_t pos = s.empty() ? 0 : std::uniform_int_distribution<size_t>(0, s.size() - 1)(rng);
    const char ch = kAlphabet[std::uniform_int_distribution<size_t>(0, kAlphabet.size() - 1)(rng)];
    switch (op(rng)) {
      case 0:  // flip one bit
        if (!s.empty()) s[pos] = char(s[pos] ^ (1 << std::uniform_int_distribution<int>(0, 7)(rng)));
        break;
      case 1: s.insert(s.begin() + long(std::min(pos, s.size())), ch); break;
      case 2:
        if (!s.empty()) s.erase(pos, 1);
        break;
      case 3:  // replace a digit by another: numbers change without breaking syntax
        for (size_t k = pos; k < s.size(); ++k)
          if (std::isdigit((unsigned char)s[k])) {
            s[k] = char('0' + std::uniform_int_distribution<int>(0, 9)(rng));
            break;
          }
        break;
    }
  }
  return s;
}

using json = nlohmann::json;

// Every node of a document, as pointers into it (for picking one at random).
void collect(json& j, std::vector<json*>& out) {
  out.push_back(&j);
  if (j.is_structured())
    for (auto& child : j) collect(child, out);
}

// Values that stress validation: zero, negative, tiny, huge, wrong types, empty containers.
json odd_value(std::mt19937_64& rng) {
  static const std::vector<json> values = {
      0, -1, 1, 2, 0.5, -0.3, 1e-300, 1e300, -1e300, 9, 2.5, 1e-6, 1e6, 4294967297LL, true, false, nullptr,
      "", "nan", "inf", "jaky", "dpm", "ndpm", "box", "circle", "polygon", "union", "path", "friction",
      "open", "phi_d", "velocity", json::array(), json::object(), json::array({0, 0}), json::array({1e9, -1e9}),
      json::array({json::array({0, 0}), json::array({0.01, 0}), json::array({0, 0.01})}),
      json::parse(R"({"type": "union", "parts": [{"type": "circle", "radius_m": 0.01}]})"),
      json::parse(R"({"type": "path", "knots": [{"t_s": 0, "velocity_m_s": [0, -0.1]}, {"t_s": 0.5, "velocity_m_s": [0.2, 0]}]})")};
  return values[std::uniform_int_distribution<size_t>(0, values.size() - 1)(rng)];
}

// Structure-aware mutation: replace, delete or add one node of the parsed template.
std::string mutate_tree(const std::string& text, std::mt19937_64& rng) {
  json j = json::parse(text);
  const int edits = std::uniform_int_distribution<int>(1, 3)(rng);
  for (int e = 0; e < edits; ++e) {
    std::vector<json*> nodes;
    collect(j, nodes);
    json* n = nodes[std::uniform_int_distribution<size_t>(0, nodes.size() - 1)(rng)];
    switch (std::uniform_int_distribution<int>(0, 2)(rng)) {
      case 0: *n = odd_value(rng); break;
      case 1:  // delete a member or element
        if (n->is_object() && !n->empty()) n->erase(n->begin());
        else if (n->is_array() && !n->empty()) n->erase(n->begin() + long(n->size() - 1));
        break;
      case 2:  // add a member or duplicate an element
        if (n->is_object()) (*n)["extra_key"] = odd_value(rng);
        else if (n->is_array() && !n->empty()) n->push_back(n->front());
        break;
    }
  }
  return j.dump(std::uniform_int_distribution<int>(0, 1)(rng) ? 2 : -1);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: furrow_scene_fuzz SCENE_DIR [ITERATIONS]\n";
    return 2;
  }
  const long iterations = argc > 2 ? std::stol(argv[2]) : 2000;
  std::vector<std::pair<std::string, std::string>> seeds;
  for (const auto& entry : fs::directory_iterator(argv[1]))
    if (entry.path().extension() == ".json") {
      std::ifstream in(entry.path(), std::ios::binary);
      std::ostringstream ss;
      ss << in.rdbuf();
      seeds.emplace_back(entry.path().filename().string(), ss.str());
    }
  std::sort(seeds.begin(), seeds.end());
  if (seeds.empty()) {
    std::cerr << "no templates in " << argv[1] << "\n";
    return 1;
  }

  std::mt19937_64 rng(20240611);
  long clean = 0, rejected = 0, failures = 0;
  double slowest_ms = 0.0;
  long slowest_it = -1;
  const auto t0 = std::chrono::steady_clock::now();
  for (long it = 0; it < iterations; ++it) {
    const auto& [name, text] = seeds[size_t(it) % seeds.size()];
    // alternate byte-level (syntax) and tree-level (semantic) mutations
    const std::string input = it % 2 ? mutate(text, rng) : mutate_tree(text, rng);
    const auto start = std::chrono::steady_clock::now();
    try {
      const furrow::Scene s = furrow::parse_scene_text(input, name);
      // a scene that parses must survive its own round trip unchanged
      const auto j = furrow::scene_to_json(s);
      if (furrow::scene_to_json(furrow::parse_scene(j, name)) != j) {
        std::cerr << "iteration " << it << " (" << name << "): round trip changed the scene\n";
        ++failures;
      }
      (void)furrow::format_scene(s);
      ++clean;
    } catch (const SceneError& e) {
      if (std::string(e.what()).find(name) != 0) {
        std::cerr << "iteration " << it << ": error does not start with the file name: " << e.what() << "\n";
        ++failures;
      }
      ++rejected;
    } catch (const std::exception& e) {
      std::cerr << "iteration " << it << " (" << name << "): unexpected exception: " << e.what() << "\n";
      ++failures;
    }
    // reported, not asserted: a wall-clock bound fails on a loaded machine; an input that hangs the
    // reader is caught by the CTest timeout of the whole run (CMakeLists.txt)
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (ms > slowest_ms) slowest_ms = ms, slowest_it = it;
  }
  const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << iterations << " mutations of " << seeds.size() << " templates: " << clean << " parsed, "
            << rejected << " rejected with SceneError, " << failures << " failures; slowest "
            << slowest_ms << " ms (iteration " << slowest_it << "), total " << total_s << " s\n";
  // both outcomes must occur, or the mutations are too weak (or too strong) to test anything
  if (clean == 0 || rejected == 0) {
    std::cerr << "degenerate fuzz run: every input had the same outcome\n";
    return 1;
  }
  return failures == 0 ? 0 : 1;
}
