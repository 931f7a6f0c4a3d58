// furrow validate / new / templates: scene files from the user's side. The engine's scene_io does
// the reading and checking; these commands only print and write.
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "app/calibration.hpp"
#include "app/commands.hpp"
#include "engine/fields.hpp"
#include "engine/scene_io.hpp"

namespace furrow::cli {

namespace {

namespace fs = std::filesystem;

std::string fmt(const char* f, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

const char* kShapeNames[] = {"circle", "box", "polygon", "union"};
const char* kShapeFunctionNames[] = {"linear", "quadratic", "cubic"};

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

// What a run of this scene will cost and produce, for people (stderr of `furrow validate`).
std::string scene_summary(const Scene& s, const std::string& source) {
  std::ostringstream os;
  const double dx = s.domain.dx_m, dt = estimate_time_step_s(s), t_end = estimate_end_time_s(s);
  const size_t particles = estimate_particle_count(s);
  const int64_t steps = estimate_step_count(s);
  os << "scene \"" << s.name << "\" (" << source << ") is valid\n";
  os << "  grid       " << long(std::ceil(s.domain.width_m / dx - 1e-9)) << " x "
     << long(std::ceil(s.domain.height_m / dx - 1e-9)) << " cells of " << fmt("%g", dx) << " m, "
     << kShapeFunctionNames[int(s.solver.shape_function)] << " B-splines\n";
  os << "  particles  ~" << particles << " (" << s.solver.particles_per_cell_1d << " x "
     << s.solver.particles_per_cell_1d << " per cell)\n";
  for (const auto& m : s.materials)
    os << "  material   " << m.name << ": " << (m.model == MaterialModel::DPM ? "DPM" : "NDPM")
       << ", wave speed " << fmt("%.3g", wave_speed_m_s(m)) << " m/s\n";
  for (const auto& b : s.bodies) {
    const double cells = body_cells_across(s, b), bias = contact_size_bias(s.solver.contact, cells);
    os << "  body       " << b.name << ": " << kShapeNames[int(b.shape.kind)] << ", " << fmt("%.3g", cells)
       << " cells across its travel, max speed " << fmt("%g", motion_max_speed_m_s(b.motion)) << " m/s, "
       << contact_method_name(s.solver.contact) << " contact";
    if (cells < 8.0)
      os << " (under 8 cells across: its force depends strongly on dx and the contact method)";
    else if (std::abs(bias) >= 0.01)
      os << " (a plate this many cells across reads ~" << fmt("%.0f", 100 * std::abs(bias)) << "% "
         << (bias < 0 ? "low" : "high") << ": engine/README.md, \"Body contact\")";
    os << "\n";
  }
  os << "  time step  ~" << fmt("%.3g", dt) << " s (cfl " << fmt("%g", s.solver.cfl) << ")\n";
  os << "  end        t = " << fmt("%.4g", t_end) << " s";
  const int ref = reference_body_index(s);
  if (t_end < s.solver.end_time_s && ref >= 0)
    os << " (body \"" << s.bodies[size_t(ref)].name << "\" travels " << fmt("%g", s.solver.end_displacement_m) << " m)";
  os << "\n  steps      ~" << steps << ", " << fmt("%.3g", estimate_particle_steps(s)) << " particle-steps";
  if (steps > s.solver.max_steps) os << " (to solver.max_steps)";
  os << "\n";
  os << "  wall time  " << predicted_wall_text(s) << "\n";
  if (s.outputs.frame_interval_s > 0.0) {
    os << "  frames     " << long(std::floor(t_end / s.outputs.frame_interval_s + 1e-9)) + 1 << " every "
       << fmt("%g", s.outputs.frame_interval_s) << " s:";
    for (const auto& f : s.outputs.fields) os << " " << f;
    if (!s.outputs.movies.empty()) {
      os << "; movies:";
      for (const auto& f : s.outputs.movies) os << " " << f;
    }
    os << "\n";
  } else {
    os << "  frames     none (outputs.frame_interval_s = 0)\n";
  }
  if (steps > s.solver.max_steps)
    os << "  warning    solver.max_steps = " << s.solver.max_steps << " stops the run before its end\n";
  return os.str();
}

void write_text_atomically(const std::string& path, const std::string& text, bool replace,
                           const std::string& replace_hint) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw std::runtime_error(path + ": directory " + dir.string() + " does not exist");
  if (fs::is_directory(target)) throw std::runtime_error(path + ": is a directory");
  if (!replace && fs::exists(target))
    throw std::runtime_error(path + ": exists; " + replace_hint);
  const fs::path tmp = dir / ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error(path + ": cannot write " + tmp.string());
    }
  }
  // link() fails if the target appeared meanwhile, so without --force nothing is ever clobbered
  const int rc = replace ? std::rename(tmp.c_str(), target.c_str()) : ::link(tmp.c_str(), target.c_str());
  const int err = errno;
  std::error_code ec;
  if (!replace || rc != 0) fs::remove(tmp, ec);
  if (rc != 0)
    throw std::runtime_error(path + ": " + (err == EEXIST ? std::string("exists; " + replace_hint)
                                                          : std::string(std::strerror(err))));
}

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
