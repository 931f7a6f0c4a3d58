// furrow validate / new / templates: scene files from the user's side. The engine's scene_io does
// the reading and checking; these commands only print and write.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "app/calibration.hpp"
#include "app/commands.hpp"
#include "app/scene_summary.hpp"
#include "engine/fields.hpp"
#include "engine/io/atomic_file.hpp"
#include "engine/scene/scene_io.hpp"

namespace furrow::cli {

namespace {

namespace fs = std::filesystem;

// A scene name from an output file name: its stem with anything outside [A-Za-z0-9_.-] as '_'.
std::string name_from_path(const std::string& path) {
  std::string stem = fs::path(path).stem().string();
  for (char& ch : stem)
    if (!(std::isalnum((unsigned char)ch) || ch == '_' || ch == '-' || ch == '.')) ch = '_';
  while (!stem.empty() && (stem[0] == '.' || stem[0] == '-')) stem.erase(0, 1);
  return stem.substr(0, 64);
}

std::string template_list() {
  std::string s;
  for (const auto& t : scene_templates()) s += (s.empty() ? "" : ", ") + t.name;
  return s;
}

int validate_main(const Parsed& p) {
  const std::string& path = p.positional[0];
  ValidationOptions options;
  options.allow_large = p.has("--yes");
  const Scene s = load_scene(path, p.all("--set"), options);
  if (!p.has("--brief")) std::cout << format_scene(s) << std::flush;
  std::cerr << scene_summary(s, path);
  return 0;
}

int new_main(const Parsed& p) {
  const std::string& name = p.positional[0];
  const SceneTemplate* t = find_scene_template(name);
  if (!t) throw UsageError("unknown template '" + name + "'; available: " + template_list() + " (see 'furrow templates')");
  if (!p.has("-o")) throw UsageError("missing -o FILE (use -o - for standard output)");
  const std::string out = p.get("-o");
  std::vector<std::string> overrides;
  // the scene is named after its file unless a --set says otherwise
  bool sets_name = false;
  for (const auto& o : p.all("--set")) sets_name |= o.rfind("name=", 0) == 0 || o.rfind("/name=", 0) == 0;
  if (out != "-" && !sets_name && !name_from_path(out).empty()) overrides.push_back("name=\"" + name_from_path(out) + "\"");
  for (const auto& o : p.all("--set")) overrides.push_back(o);
  ValidationOptions options;
  options.allow_large = p.has("--yes");
  const Scene s = parse_scene_text(t->text, "template " + t->name, overrides, options);
  const std::string text = format_scene(s);
  if (out == "-") {
    std::cout << text << std::flush;
    return 0;
  }
  write_text_atomically(out, text, p.has("--force"), "pass --force to replace it");
  std::cerr << "wrote " << out << ": scene \"" << s.name << "\" from template " << t->name << ", ~"
            << estimate_particle_count(s) << " particles, ~" << estimate_step_count(s) << " steps\n";
  return 0;
}

int templates_main(const Parsed&) {
  for (const auto& t : scene_templates()) {
    std::string n = t.name;
    if (n.size() < 16) n.resize(16, ' ');
    std::string d = t.description;
    for (char& ch : d)
      if (ch == '\n' || ch == '\r') ch = ' ';
    std::cout << n << "  " << d << "\n";
  }
  return 0;
}

const char* kSetHelp =
    "--set key.path=value overrides one value before validation: dots separate object keys and array\n"
    "indices (an array element may be named by its \"name\"), e.g. --set domain.dx_m=0.005,\n"
    "--set bodies.plate.friction=0.5, --set 'bodies.0.shape.size_m=[0.05,0.02]'. The value is JSON\n"
    "when it parses as JSON, otherwise a string. Every key is listed in scenes/README.md.";

}  // namespace

Command command_validate() {
  return {"validate", "check a scene without running it; print it resolved, with its cost",
          "furrow validate SCENE.json [--set key.path=value ...] [--yes] [--brief]",
          "Reads SCENE.json, applies the --set overrides and checks every key: unknown or misspelt keys,\n"
          "types, units and physical ranges, bodies and beds inside the domain, and the estimated cost.\n"
          "On success prints the resolved scene (every default filled in) as JSON on standard output and\n"
          "a summary (grid, particles, bodies with their size in cells across their travel and how far\n"
          "a plate that size reads from its converged force, time step, steps, wall time, frames) on\n"
          "standard error, and exits 0. On error prints FILE: /json/pointer: got VALUE, expected ... and\n"
          "exits 1.\n\n" +
              std::string(kSetHelp),
          {{"--set", true, true, "override a scene value", "key.path=value"},
           {"--yes", false, false, "accept scenes estimated above 2e7 particles or 2e6 steps"},
           {"--brief", false, false, "print only the summary, not the resolved JSON"}},
          1, 1, validate_main};
}

Command command_new() {
  return {"new", "write a scene file from a template",
          "furrow new TEMPLATE -o FILE [--set key.path=value ...] [--force] [--yes]",
          "Writes the resolved scene of TEMPLATE (see 'furrow templates'; '-' and '_' are equivalent in\n"
          "the name) to FILE, with the --set overrides applied and every default written out. The scene\n"
          "is named after FILE's stem unless --set name=... is given. An existing FILE is left alone\n"
          "unless --force; the file appears complete or not at all. -o - writes to standard output.\n\n" +
              std::string(kSetHelp),
          {{"-o", true, false, "output scene file ('-' for standard output)", "FILE"},
           {"--set", true, true, "override a template value", "key.path=value"},
           {"--force", false, false, "replace FILE if it exists"},
           {"--yes", false, false, "accept scenes estimated above 2e7 particles or 2e6 steps"}},
          1, 1, new_main};
}

Command command_templates() {
  return {"templates", "list the scene templates for 'furrow new'", "furrow templates",
          "One line per template: its name and description. The templates are the files of scenes/,\n"
          "built into furrow.",
          {}, 0, 0, templates_main};
}

}  // namespace furrow::cli
