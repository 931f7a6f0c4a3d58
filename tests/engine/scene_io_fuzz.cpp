// Fuzz-style robustness test of the scene reader, built with ASan + UBSan (ctest -L sanitize).
// Random byte flips, inserts and deletes of every template go through parse_scene_text: each must
// parse cleanly or throw SceneError; nothing else may escape, crash, or take long.
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

#include "engine/scene_io.hpp"

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
  const auto t0 = std::chrono::steady_clock::now();
  for (long it = 0; it < iterations; ++it) {
    const auto& [name, text] = seeds[size_t(it) % seeds.size()];
    const std::string input = mutate(text, rng);
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
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    slowest_ms = std::max(slowest_ms, ms);
    if (ms > 2000.0) {
      std::cerr << "iteration " << it << " (" << name << ") took " << ms << " ms\n";
      ++failures;
    }
  }
  const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << iterations << " mutations of " << seeds.size() << " templates: " << clean << " parsed, "
            << rejected << " rejected with SceneError, " << failures << " failures; slowest "
            << slowest_ms << " ms, total " << total_s << " s\n";
  // both outcomes must occur, or the mutations are too weak (or too strong) to test anything
  if (clean == 0 || rejected == 0) {
    std::cerr << "degenerate fuzz run: every input had the same outcome\n";
    return 1;
  }
  return failures == 0 ? 0 : 1;
}
