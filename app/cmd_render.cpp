// `furrow render` and `furrow demo`: argument handling only; drawing lives in render/.
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "app/commands.hpp"
#include "engine/field_store.hpp"
#include "render/colormap.hpp"
#include "render/field_movie.hpp"
#include "render/force_series.hpp"
#include "render/image_io.hpp"
#include "render/plot.hpp"
#include "render/test_scene.hpp"

namespace fs = std::filesystem;

namespace furrow::cli {

namespace {

// Whole string as a number, else UsageError naming the option.
double parse_number(const std::string& s, const std::string& option) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v))
    throw UsageError(option + ": expected a number, got '" + s + "'");
  return v;
}

long long parse_int(const std::string& s, const std::string& option) {
  char* end = nullptr;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0') throw UsageError(option + ": expected a whole number, got '" + s + "'");
  return v;
}


// "a,b,,c" -> {"a", "b", "", "c"}: every field, empty ones too
std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (size_t c = s.find(sep); ; c = s.find(sep, start)) {
    parts.push_back(s.substr(start, c == std::string::npos ? std::string::npos : c - start));
    if (c == std::string::npos) break;
    start = c + 1;
  }
  return parts;
}

long long frame_number(const std::string& path) {
  const std::string stem = fs::path(path).stem().string();  // frame_00042
  return std::stoll(stem.substr(stem.find('_') + 1));
}

// --frames a:b[:step] on frame numbers, both ends included; "a:" to the end, ":b" from the start,
// "a" alone is one frame.
std::vector<std::string> select_frames(const std::vector<std::string>& all, const std::string& spec) {
  if (spec.empty()) return all;
  const std::vector<std::string> parts = split(spec, ':');
  if (parts.size() > 3) throw UsageError("--frames: expected a:b[:step], got '" + spec + "'");
  long long a = parts[0].empty() ? LLONG_MIN : parse_int(parts[0], "--frames");
  long long b = parts.size() == 1 ? a : (parts[1].empty() ? LLONG_MAX : parse_int(parts[1], "--frames"));
  const long long step = parts.size() == 3 ? parse_int(parts[2], "--frames") : 1;
  if (step < 1) throw UsageError("--frames: step must be >= 1, got '" + spec + "'");
  if (a > b) throw UsageError("--frames: first frame after last in '" + spec + "'");
  std::vector<std::string> out;
  long long taken = 0;
  for (const auto& p : all) {
    const long long n = frame_number(p);
    if (n < a || n > b) continue;
    if (taken++ % step == 0) out.push_back(p);
  }
  if (out.empty()) {
    std::string have = all.empty() ? "none" : std::to_string(frame_number(all.front())) + ".." +
                                                  std::to_string(frame_number(all.back()));
    throw UsageError("--frames " + spec + " selects no frame (stored frames: " + have + ")");
  }
  return out;
}

// Evenly spread subset of at most n frames (first and last kept).
std::vector<std::string> spread(const std::vector<std::string>& v, size_t n) {
  if (v.size() <= n) return v;
  std::vector<std::string> out;
  for (size_t k = 0; k < n; ++k) out.push_back(v[size_t(std::lround(double(k) * double(v.size() - 1) / double(n - 1)))]);
  return out;
}

std::string all_fields() {
  std::string s;
  for (const auto& f : field_registry()) s += (s.empty() ? "" : ", ") + f.name;
  return s;
}

// Default outputs go to the next free name; a path the user gave is refused if taken (unless
// --overwrite).
std::string choose_output(const Parsed& p, const fs::path& default_path, bool* overwrite) {
  *overwrite = p.has("--overwrite");
  if (p.has("--out")) {
    const std::string out = p.get("--out");
    if (fs::exists(out) && !*overwrite)
      throw std::runtime_error(out + " already exists; choose another --out or pass --overwrite");
    return out;
  }
  return *overwrite ? default_path.string() : render::next_free_path(default_path.string());
}

// --range LO:HI on `range` (keeps its log flag); a log range needs LO > 0.
void apply_range_option(const std::string& spec, const std::string& field, render::FieldRange* range) {
  const size_t c = spec.find(':');
  if (c == std::string::npos) throw UsageError("--range: expected LO:HI, got '" + spec + "'");
  range->lo = parse_number(spec.substr(0, c), "--range");
  range->hi = parse_number(spec.substr(c + 1), "--range");
  if (!(range->hi > range->lo)) throw UsageError("--range: LO must be below HI, got '" + spec + "'");
  if (range->log && range->lo <= 0) throw UsageError("--range: " + field + " is drawn on a log scale, LO must be > 0");
}

std::string range_text(const std::string& field, const render::FieldRange& r) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s range %.4g..%.4g %s%s", field.c_str(), r.lo, r.hi, find_field(field)->unit.c_str(),
                r.log ? " (log)" : "");
  return buf;
}

int render_main(const Parsed& p) {
  const std::string run_dir = p.positional[0];
  if (!fs::is_directory(run_dir)) {
    std::cerr << "furrow render: run directory '" << run_dir << "' does not exist\n";
    return 1;
  }
  if (!p.has("--field")) throw UsageError("--field NAME[,NAME...] is required (fields: " + all_fields() + ")");
  const std::vector<std::string> fields = split(p.get("--field"), ',');
  for (size_t k = 0; k < fields.size(); ++k) {
    if (!find_field(fields[k])) {
      std::cerr << "furrow render: unknown field '" << fields[k] << "' in --field " << p.get("--field")
                << " (valid fields: " << all_fields() << ")\n";
      return 2;
    }
    for (size_t j = 0; j < k; ++j)
      if (fields[j] == fields[k]) throw UsageError("--field: '" + fields[k] + "' is listed twice");
  }
  const bool several = fields.size() > 1;
  if (several && (p.has("--range") || p.has("--colormap")))
    throw UsageError("--range and --colormap apply to a single --field");
  if (p.has("--png") && p.has("--contact-sheet")) throw UsageError("--png and --contact-sheet exclude each other");
  const bool sheet = p.has("--contact-sheet");

  render::FrameStyle style;
  style.field = fields.front();
  style.smooth = p.has("--smooth");
  if (p.has("--colormap")) {
    style.colormap = p.get("--colormap");
    render::load_colormap(style.colormap);  // unknown name: error listing the known ones
  }
  const double fps = p.has("--fps") ? parse_number(p.get("--fps"), "--fps") : 10.0;
  if (!(fps > 0)) throw UsageError("--fps must be > 0");

  const fs::path frames_dir = fs::path(run_dir) / "frames";
  if (!fs::is_directory(frames_dir)) {
    std::cerr << "furrow render: " << run_dir << " has no frames/ folder (is it a run directory from 'furrow run'?)\n";
    return 1;
  }
  std::vector<std::string> frames = select_frames(list_frames(run_dir), p.get("--frames"));
  if (frames.empty()) {
    std::cerr << "furrow render: no frame_*.vdb files in " << frames_dir.string() << "\n";
    return 1;
  }
  if (sheet && !p.has("--frames")) frames = spread(frames, 12);

  // one fixed range per field over the frames drawn
  const std::vector<render::FrameScan> scans = render::scan_frames(frames, fields);
  render::PanelsStyle panels_style;
  std::string ranges;
  for (size_t k = 0; k < fields.size(); ++k) {
    render::FrameStyle s = style;
    s.field = fields[k];
    s.range = scans[k].range;
    s.time_decimals = scans[k].time_decimals;
    if (p.has("--range")) apply_range_option(p.get("--range"), fields[k], &s.range);
    panels_style.fields.push_back(s);
    ranges += (ranges.empty() ? "" : "; ") + range_text(fields[k], s.range);
  }
  style = panels_style.fields.front();
  const fs::path forces = fs::path(run_dir) / "forces.csv";
  if (!p.has("--no-panel") && !sheet && fs::exists(forces)) {
    render::ForcePanel panel = render::read_force_panel(forces.string());
    if (!panel.series.empty()) style.panel = panels_style.forces = panel;
  }
  // default sizes: 1280x720; a sheet 1920 wide; several fields 640x480 per panel (the force plot
  // is one more panel), on a sheet 1280x720 per field
  const int panels = int(fields.size()) + (panels_style.forces ? 1 : 0);
  if (several) style.width = sheet ? 1280 * int(fields.size()) : 640 * panels, style.height = sheet ? 720 : 480;
  else if (sheet) style.width = 1920, style.height = 1080;
  if (p.has("--size")) parse_size(p.get("--size"), &style.width, &style.height);
  panels_style.width = style.width, panels_style.height = style.height;

  std::string name;  // default output name: the fields joined by '-'
  for (const auto& f : fields) name += (name.empty() ? "" : "-") + f;
  bool overwrite = false;
  if (p.has("--png")) {
    const std::string dir = choose_output(p, fs::path(run_dir) / "renders" / name, &overwrite);
    const auto written = several ? render::render_pngs(frames, panels_style, dir, overwrite)
                                 : render::render_pngs(frames, style, dir, overwrite);
    std::cout << dir << "  (" << written.size() << " PNG, " << style.width << "x" << style.height << ", " << ranges
              << ")\n";
  } else if (sheet) {
    const std::string out = choose_output(p, fs::path(run_dir) / "renders" / (name + "_contact_sheet.png"), &overwrite);
    if (fs::path(out).has_parent_path()) fs::create_directories(fs::path(out).parent_path());
    const int columns = p.has("--columns") ? int(parse_int(p.get("--columns"), "--columns")) : 0;
    if (columns < 0) throw UsageError("--columns must be >= 1");
    const render::RgbImage img = several ? render::render_contact_sheet(frames, panels_style, columns)
                                         : render::render_contact_sheet(frames, style, columns);
    render::write_png(img, out, overwrite);
    std::cout << out << "  (" << frames.size() << " frames, " << img.width << "x" << img.height << ", " << ranges
              << ")\n";
  } else {
    if (style.width % 2 || style.height % 2)
      throw UsageError("--size: movies need even width and height (H.264, yuv420p), got " +
                       std::to_string(style.width) + "x" + std::to_string(style.height));
    const std::string out = choose_output(p, fs::path(run_dir) / "movies" / (name + ".mp4"), &overwrite);
    if (fs::path(out).has_parent_path()) fs::create_directories(fs::path(out).parent_path());
    if (several) render::render_movie(frames, panels_style, out, fps, overwrite);
    else render::render_movie(frames, style, out, fps, overwrite);
    std::cout << out << "  (" << frames.size() << " frames at " << fps << " fps, " << style.width << "x"
              << style.height << ", " << ranges << ")\n";
  }
  return 0;
}

// Overlays one body's force-vs-displacement trace from several runs (e.g. two contact methods or
// two resolutions of one scene) in one chart.
int compare_main(const Parsed& p) {
  std::vector<std::string> labels;
  if (p.has("--labels")) {
    labels = split(p.get("--labels"), ',');
    if (labels.size() != p.positional.size())
      throw UsageError("--labels: " + std::to_string(labels.size()) + " labels for " +
                       std::to_string(p.positional.size()) + " runs");
  }
  const std::string body = p.get("--body");
  const double lo = p.has("--from") ? parse_number(p.get("--from"), "--from") : -INFINITY;
  const double hi = p.has("--to") ? parse_number(p.get("--to"), "--to") : INFINITY;
  if (!(hi > lo)) throw UsageError("--to must be above --from");
  render::PlotPanel panel;
  panel.x_label = "displacement (mm)";
  panel.y_label = "resisting force (N/m)";
  for (size_t r = 0; r < p.positional.size(); ++r) {
    const fs::path forces = fs::path(p.positional[r]) / "forces.csv";
    if (!fs::exists(forces)) {
      std::cerr << "furrow compare: " << forces.string() << " does not exist (is " << p.positional[r]
                << " a run directory from 'furrow run'?)\n";
      return 1;
    }
    const render::ForcePanel f = render::read_force_panel(forces.string());
    const render::ForceSeries* s = nullptr;
    for (const auto& c : f.series)
      if (body.empty() || c.label == body) {
        s = &c;
        break;
      }
    if (!s) {
      std::string have;
      for (const auto& c : f.series) have += (have.empty() ? "" : ", ") + c.label;
      std::cerr << "furrow compare: " << forces.string() << " has no body '" << body << "' (bodies: " << have << ")\n";
      return 1;
    }
    render::PlotSeries ps;
    ps.label = labels.empty() ? fs::path(p.positional[r]).filename().string() + " (" + s->label + ")" : labels[r];
    ps.markers = false;
    for (size_t k = 0; k < s->x.size(); ++k)
      if (s->x[k] >= lo && s->x[k] <= hi) {
        ps.x.push_back(s->x[k]);
        ps.y.push_back(s->y[k]);
      }
    panel.series.push_back(ps);
  }
  render::PlotFigure fig;
  fig.title = p.get("--title");
  fig.panels.push_back(panel);
  if (p.has("--size")) parse_size(p.get("--size"), &fig.width, &fig.height);
  bool overwrite = false;
  const std::string out = choose_output(p, fs::path("force_comparison.png"), &overwrite);
  render::write_figure_png(fig, out, overwrite);
  std::cout << out << "\n";
  return 0;
}

int demo_main(const Parsed& p) {
  const fs::path dir = fs::path(p.get("--out", "out")) / "demo";
  fs::create_directories(dir);
  // Keep earlier results: pick test_scene_2.png, _3, ... when the name is taken.
  const std::string path = render::next_free_path((dir / "test_scene.png").string());
  render::write_png(render::render_test_scene(1280, 720), path);
  std::cout << path << "\n";
  return 0;
}

}  // namespace

void parse_size(const std::string& s, int* w, int* h) {
  const size_t x = s.find('x');
  if (x == std::string::npos) throw UsageError("--size: expected WxH, e.g. 1280x720, got '" + s + "'");
  const long long ww = parse_int(s.substr(0, x), "--size"), hh = parse_int(s.substr(x + 1), "--size");
  if (ww < 16 || hh < 16 || ww > 8192 || hh > 8192)
    throw UsageError("--size: width and height must be in 16..8192, got '" + s + "'");
  *w = int(ww), *h = int(hh);
}

Command command_render() {
  return {"render",
          "re-render stored frames to an MP4, PNGs or a contact sheet",
          "furrow render RUN_DIR --field NAME[,NAME...] [--frames a:b[:step]] [--size WxH] [--png | --contact-sheet] [--out PATH]",
          "Draws fields of the frames stored in RUN_DIR/frames/*.vdb, off-screen (no display needed).\n"
          "Several fields (--field strain_rate,pressure,packing_fraction) are drawn side by side, each\n"
          "with its own colour range and colorbar (default size 640x480 per panel, the force plot being\n"
          "one more panel; a contact sheet puts one sheet per field side by side, 1280x720 each).\n"
          "The colour range is fixed over all selected frames (min..max over cells with material; strain\n"
          "rate on a log scale from max/10^4 up to its max) unless --range is given. Cells without material\n"
          "are grey, bodies are outlined in cyan, and each image carries a colorbar with the field's unit and\n"
          "the time stamp. Each cell is one flat colour unless --smooth blends the values between cell\n"
          "centres within the material (cells without material stay grey, so the free surface stays sharp). Movies and PNGs show a side panel from RUN_DIR/forces.csv when it exists:\n"
          "for each body, the resisting force -F.d (d = unit direction of its travel from first to last\n"
          "position; Fy for a plate pushed down) against its displacement from its first position.\n"
          "\n"
          "Outputs (default: a movie):\n"
          "  movie            RUN_DIR/movies/<field>.mp4 (H.264, yuv420p; even sizes)\n"
          "  --png            RUN_DIR/renders/<field>/frame_NNNNN.png, one per frame\n"
          "  --contact-sheet  RUN_DIR/renders/<field>_contact_sheet.png: up to 12 frames spread over the run\n"
          "                  (<field> is the fields joined by '-' when there are several)\n"
          "                  (or exactly those picked by --frames), each tile labelled with its time (1920 wide)\n"
          "Nothing is overwritten: a default name that is taken becomes <name>_2, _3, ...; a taken --out\n"
          "PATH is an error unless --overwrite is given. Prints the path written.\n"
          "\n"
          "--frames selects by frame number (frame_00042.vdb is 42), both ends included: '10:50',\n"
          "'10:50:5' (every 5th), '20:' (to the end), ':30', or '42' (one frame).",
          {{"--field", true, false, "field(s) to draw, comma-separated: " + all_fields(), "NAME[,NAME...]"},
           {"--frames", true, false, "frame numbers a:b[:step], both ends included (default: all)", "SPEC"},
           {"--size", true, false, "image size (default 1280x720; contact sheet: sheet width 1920, tiles WxH-shaped)", "WxH"},
           {"--png", false, false, "write one PNG per frame instead of a movie"},
           {"--contact-sheet", false, false, "write one PNG with the frames as a grid of tiles"},
           {"--columns", true, false, "contact-sheet columns (default: about square)", "N"},
           {"--out", true, false, "output file (movie, sheet) or folder (--png)", "PATH"},
           {"--overwrite", false, false, "replace an existing output"},
           {"--range", true, false, "fixed colour range instead of the frames' min..max (one field only)", "LO:HI"},
           {"--colormap", true, false, "viridis, magma or coolwarm (default: by field; one field only)", "NAME"},
           {"--fps", true, false, "movie frames per second (default 10)", "N"},
           {"--no-panel", false, false, "leave out the force panel"},
           {"--smooth", false, false, "blend values between cell centres within the material (display only)"}},
          1,
          1,
          render_main};
}

Command command_compare() {
  return {"compare",
          "overlay the force traces of several runs in one chart (PNG)",
          "furrow compare RUN_DIR RUN_DIR... [--body NAME] [--from MM] [--to MM] [--labels a,b,...] [--out FILE.png]",
          "Reads RUN_DIR/forces.csv of each run and draws one body's resisting force -F.d (N/m, d the\n"
          "unit direction of its travel) against its displacement (mm), all runs in one chart: two\n"
          "contact methods, two resolutions or two materials of one scene side by side. The body is\n"
          "the first one in each file unless --body names it. Writes force_comparison.png in the\n"
          "current folder (or the next free name) unless --out is given; a taken --out is an error\n"
          "unless --overwrite. Prints the path written.",
          {{"--body", true, false, "body name (default: the first body of each run)", "NAME"},
           {"--from", true, false, "first displacement to draw (mm)", "MM"},
           {"--to", true, false, "last displacement to draw (mm)", "MM"},
           {"--labels", true, false, "legend entries, one per run, comma-separated (default: folder names)", "LIST"},
           {"--title", true, false, "chart title", "TEXT"},
           {"--size", true, false, "image size (default 1280x720)", "WxH"},
           {"--out", true, false, "output PNG", "FILE"},
           {"--overwrite", false, false, "replace an existing output"}},
          1,
          16,
          compare_main};
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
