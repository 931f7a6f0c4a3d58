// `furrow render` and `furrow demo`: argument handling only; drawing lives in render/.
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include "app/commands.hpp"
#include "engine/io/field_store.hpp"
#include "engine/scene/scene_io.hpp"
#include "render/colormap.hpp"
#include "render/field_movie.hpp"
#include "render/force_series.hpp"
#include "render/image_io.hpp"
#include "render/layouts.hpp"
#include "render/point_splat.hpp"
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

std::string all_fields() { return render::display_field_names(); }

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
  std::snprintf(buf, sizeof buf, "%s range %.4g..%.4g %s%s", field.c_str(), r.lo, r.hi, render::find_display_field(field)->unit.c_str(),
                r.log ? " (log)" : "");
  return buf;
}

int render_main(const Parsed& p) {
  const std::vector<std::string>& runs = p.positional;
  for (const auto& run_dir : runs)
    if (!fs::is_directory(run_dir)) {
      std::cerr << "furrow render: run directory '" << run_dir << "' does not exist\n";
      return 1;
    }
  // --layout: the fields, frame and scales the first run's scene names (outputs.layout); options
  // given as well take precedence
  MovieLayout layout;
  if (p.has("--layout")) {
    const fs::path scene_path = fs::path(runs.front()) / "scene.json";
    if (!fs::exists(scene_path))
      throw std::runtime_error("--layout: " + scene_path.string() + " does not exist (it names the layout)");
    layout = load_scene(scene_path.string()).outputs.layout;
    if (layout.name.empty())
      throw std::runtime_error("--layout: " + scene_path.string() +
                               " names no outputs.layout (give --field, --frame-of, --normalize instead)");
  }
  std::string field_list = p.get("--field");
  if (field_list.empty())
    for (const auto& f : layout.fields) field_list += (field_list.empty() ? "" : ",") + f;
  if (field_list.empty())
    throw UsageError("--field NAME[,NAME...] is required (fields: " + all_fields() + ")");
  const std::string frame_of = p.get("--frame-of", layout.frame_of);
  const bool normalize = p.has("--normalize") || layout.normalize;
  const std::vector<std::string> fields = split(field_list, ',');
  for (size_t k = 0; k < fields.size(); ++k) {
    if (!render::find_display_field(fields[k])) {
      std::cerr << "furrow render: unknown field '" << fields[k] << "' in --field " << field_list
                << " (valid fields: " << all_fields() << ")\n";
      return 2;
    }
    for (size_t j = 0; j < k; ++j)
      if (fields[j] == fields[k]) throw UsageError("--field: '" + fields[k] + "' is listed twice");
  }
  const bool several_runs = runs.size() > 1;
  if (several_runs && fields.size() > 1)
    throw UsageError("several runs side by side take one --field (got " + field_list + ")");
  const bool several = fields.size() > 1 || several_runs;
  if (fields.size() > 1 && (p.has("--range") || p.has("--colormap")))
    throw UsageError("--range and --colormap apply to a single --field");
  if (p.has("--png") && p.has("--contact-sheet")) throw UsageError("--png and --contact-sheet exclude each other");
  const bool sheet = p.has("--contact-sheet");
  if (sheet && several_runs) throw UsageError("--contact-sheet takes one run");
  if (sheet && (!frame_of.empty() || normalize))
    throw UsageError("--frame-of and --normalize apply to movies and --png");
  std::vector<std::string> labels;
  if (p.has("--labels")) {
    labels = split(p.get("--labels"), ',');
    if (labels.size() != runs.size())
      throw UsageError("--labels: " + std::to_string(labels.size()) + " labels for " + std::to_string(runs.size()) +
                       " runs");
  }
  const double zoom = p.has("--zoom") ? parse_number(p.get("--zoom"), "--zoom") : layout.zoom;
  if (!(zoom >= 1.0 && zoom <= 50.0)) throw UsageError("--zoom must be in 1..50, got " + p.get("--zoom"));
  if (zoom != 1.0 && frame_of.empty()) throw UsageError("--zoom goes with --frame-of BODY");

  render::FrameStyle style;
  style.field = fields.front();
  style.smooth = !p.has("--cells");
  style.follow_body = frame_of;
  style.zoom = zoom;
  if (p.has("--colormap")) {
    style.colormap = p.get("--colormap");
    render::load_colormap(style.colormap);  // unknown name: error listing the known ones
  }

  // every run's frames, selected alike and paired by time
  std::vector<std::vector<std::string>> run_frames;
  for (const auto& run_dir : runs) {
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
    run_frames.push_back(frames);
  }
  const std::vector<std::string>& frames = run_frames.front();
  if (several_runs) {
    size_t n = frames.size();
    for (const auto& r : run_frames) n = std::min(n, r.size());
    const FieldFrame first = read_frame(frames.front());
    for (size_t r = 1; r < runs.size(); ++r) {
      const FieldFrame other = read_frame(run_frames[r].front());
      const double w0 = first.nx * first.dx_m, h0 = first.ny * first.dx_m;
      const double w1 = other.nx * other.dx_m, h1 = other.ny * other.dx_m;
      if (std::abs(w1 - w0) > 0.01 * w0 || std::abs(h1 - h0) > 0.01 * h0) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "the domains differ: %s is %.4g x %.4g m, %s is %.4g x %.4g m", runs[0].c_str(), w0,
                      h0, runs[r].c_str(), w1, h1);
        std::cerr << "furrow render: " << buf << "; side by side needs the same domain (dx may differ)\n";
        return 1;
      }
      run_frames[r].resize(n);
    }
    run_frames.front().resize(n);
    // frames pair by index; their times must agree (same frame interval and start)
    double t_before = 0.0;  // run 0's previous frame time: each file is read once
    for (size_t k = 0; k < n; ++k) {
      const double t0 = read_frame(run_frames[0][k]).time_s;
      const double gap = k > 0 ? t0 - t_before : t0;
      t_before = t0;
      for (size_t r = 1; r < runs.size(); ++r) {
        const double t = read_frame(run_frames[r][k]).time_s;
        if (std::abs(t - t0) > 1e-9 + 0.25 * std::abs(gap)) {
          std::cerr << "furrow render: frames do not pair by time: " << run_frames[0][k] << " is at t = " << t0
                    << " s, " << run_frames[r][k] << " at t = " << t << " s (store frames at the same interval)\n";
          return 1;
        }
      }
    }
  }
  // a body to follow must be in every run's frames before anything is written
  if (!style.follow_body.empty())
    for (const auto& r : run_frames) {
      const FieldFrame f = read_frame(r.front());
      std::string names;
      bool found = false;
      for (const auto& b : f.bodies) found |= b.name == style.follow_body, names += (names.empty() ? "" : ", ") + b.name;
      if (!found) {
        std::cerr << "furrow render: --frame-of: no body '" << style.follow_body << "' in " << r.front()
                  << " (bodies: " << (names.empty() ? "none" : names) << ")\n";
        return 1;
      }
    }
  const std::vector<std::vector<std::string>> grid_frames = run_frames;
  if (p.has("--points")) {
    if (sheet) throw UsageError("--points draws movies and --png, not contact sheets");
    style.smooth = false;  // the discs, not a blend of them
    for (size_t r = 0; r < runs.size(); ++r) {  // the frame files stay the grid and the checks' source
      for (auto& f : run_frames[r]) f = render::points_path_for(f);
      if (!fs::exists(run_frames[r].front())) {
        std::cerr << "furrow render: --points: " << run_frames[r].front()
                  << " does not exist (run the scene with outputs.points true to store the points)\n";
        return 1;
      }
    }
  }
  const double fps = p.has("--fps") ? parse_number(p.get("--fps"), "--fps") : render::movie_fps(frames.size());
  if (!(fps > 0)) throw UsageError("--fps must be > 0");

  // one fixed range per panel over the frames drawn: several runs share one (same colours, same values)
  render::PanelsStyle panels_style;
  std::string ranges;
  std::optional<render::FieldRange> shared;
  std::string normalized;  // the scales drawn with, printed
  if (several_runs) {
    std::vector<std::string> all;
    for (const auto& r : run_frames) all.insert(all.end(), r.begin(), r.end());
    shared = render::scan_frames(all, fields.front()).range;
  }
  const std::vector<render::FrameScan> scans = render::scan_frames(frames, fields);
  for (size_t k = 0; k < std::max(fields.size(), runs.size()); ++k) {
    render::FrameStyle s = style;
    s.field = fields[several_runs ? 0 : k];
    s.range = shared ? *shared : scans[k].range;
    s.time_decimals = scans[several_runs ? 0 : k].time_decimals;
    if (p.has("--range")) apply_range_option(p.get("--range"), s.field, &s.range);
    if (several_runs) s.title = labels.empty() ? fs::path(runs[k]).filename().string() : labels[k];
    if (k == 0 || !several_runs) ranges += (ranges.empty() ? "" : "; ") + range_text(s.field, s.range);
    if (normalize) {
      const fs::path scene_path = fs::path(runs[several_runs ? k : 0]) / "scene.json";
      if (!fs::exists(scene_path))
        throw std::runtime_error("--normalize: " + scene_path.string() + " does not exist (it names the body's speed and size)");
      const Scene run_scene = load_scene(scene_path.string());
      if (!p.has("--normalize") && reference_body_index(run_scene) < 0) {
        // the layout asks for it, but no body moves in this run: drawn in units
        if (k == 0) std::cerr << "furrow render: " << scene_path.string() << ": no body moves; drawn in units\n";
        panels_style.fields.push_back(s);
        continue;
      }
      const render::BodyScales sc = render::body_scales(run_scene, scene_path.string());
      render::normalize_style(sc, &s);
      if (k == 0) normalized = render::scales_text(sc);
    }
    panels_style.fields.push_back(s);
  }
  style = panels_style.fields.front();
  // a run's force panel: each body's raw trace, or with --force-mean its average over one cell of
  // travel drawn over it
  auto panel_of = [&](size_t r) {
    const render::ForcePanel raw = render::read_force_panel((fs::path(runs[r]) / "forces.csv").string());
    if (!p.has("--force-mean")) return raw;
    const double dx_mm = 1000.0 * read_frame(grid_frames[r].front()).dx_m;
    char text[64];
    std::snprintf(text, sizeof text, "1 cell = %.3g mm", dx_mm);
    return render::with_running_mean(raw, dx_mm, text);
  };
  const fs::path forces = fs::path(runs.front()) / "forces.csv";
  if (!p.has("--no-panel") && !sheet && fs::exists(forces)) {
    render::ForcePanel panel = panel_of(0);
    if (several_runs)  // each trace labelled like its run's panel
      for (auto& row : panel.rows)
        for (auto& s : row.series) s.label = panels_style.fields[0].title + ": " + s.label;
    // several runs: one trace per run, labelled like its panel
    for (size_t r = 1; r < runs.size() && !panel.series.empty(); ++r) {
      const fs::path f = fs::path(runs[r]) / "forces.csv";
      if (!fs::exists(f)) continue;
      const render::ForcePanel other = panel_of(r);
      for (auto s : other.series) {
        s.label = panels_style.fields[r].title + ": " + s.label;
        panel.series.push_back(s);
      }
      // torque, depth, ...: the same rows, in their order (torque, depth, speed, angle)
      for (const auto& row : other.rows) {
        auto mine = std::find_if(panel.rows.begin(), panel.rows.end(), [&](const auto& m) { return m.key == row.key; });
        if (mine == panel.rows.end()) mine = panel.rows.insert(panel.rows.end(), render::MotionRow{row.key, row.y_label, row.movie, {}});
        for (auto s : row.series) {
          s.label = panels_style.fields[r].title + ": " + s.label;
          mine->series.push_back(s);
        }
      }
      const std::vector<std::string>& order = render::motion_row_keys();
      std::stable_sort(panel.rows.begin(), panel.rows.end(), [&](const auto& a, const auto& b) {
        return std::find(order.begin(), order.end(), a.key) < std::find(order.begin(), order.end(), b.key);
      });
    }
    if (several_runs)
      for (size_t k = 0; k < panel.series.size() && panel.series[k].label.find(": ") == std::string::npos; ++k)
        panel.series[k].label = panels_style.fields[0].title + ": " + panel.series[k].label;
    if (!panel.series.empty()) style.panel = panels_style.forces = panel;
  }
  // default sizes: 1280x720; a sheet 1920 wide; several panels 640x480 each (the force plot is one
  // more panel), on a sheet 1280x720 per field
  const int panels = int(panels_style.fields.size()) + (panels_style.forces ? 1 : 0);
  if (several) style.width = sheet ? 1280 * int(fields.size()) : 640 * panels, style.height = sheet ? 720 : 480;
  else if (sheet) style.width = 1920, style.height = 1080;
  if (p.has("--size")) parse_size(p.get("--size"), &style.width, &style.height);
  panels_style.width = style.width, panels_style.height = style.height;

  // default output name: the layout's, else the fields (several runs: and the labels) joined by '-'
  std::string name = layout.name;
  if (name.empty())
    for (const auto& f : fields) name += (name.empty() ? "" : "-") + f;
  if (several_runs)
    for (const auto& s : panels_style.fields) name += "-" + s.title;
  bool overwrite = false;
  if (p.has("--png")) {
    const std::string dir = choose_output(p, fs::path(runs.front()) / "renders" / name, &overwrite);
    const auto written = several_runs ? render::render_pngs(run_frames, panels_style, dir, overwrite)
                         : several    ? render::render_pngs(frames, panels_style, dir, overwrite)
                                      : render::render_pngs(frames, style, dir, overwrite);
    std::cout << dir << "  (" << written.size() << " PNG, " << style.width << "x" << style.height << ", " << ranges
              << (normalized.empty() ? "" : "; normalized by " + normalized) << ")\n";
  } else if (sheet) {
    const std::string out = choose_output(p, fs::path(runs.front()) / "renders" / (name + "_contact_sheet.png"), &overwrite);
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
    const std::string out = choose_output(p, fs::path(runs.front()) / "movies" / (name + ".mp4"), &overwrite);
    if (fs::path(out).has_parent_path()) fs::create_directories(fs::path(out).parent_path());
    if (several_runs) render::render_movie(run_frames, panels_style, out, fps, overwrite);
    else if (several) render::render_movie(frames, panels_style, out, fps, overwrite);
    else render::render_movie(frames, style, out, fps, overwrite);
    std::cout << out << "  (" << frames.size() << " frames at " << fps << " fps, " << style.width << "x"
              << style.height << ", " << ranges << (normalized.empty() ? "" : "; normalized by " + normalized) << "; poster " << fs::path(out).replace_extension(".png").string()
              << ")\n";
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
          "furrow render RUN_DIR [RUN_DIR...] --field NAME[,NAME...] [--frames a:b[:step]] [--size WxH] [--png | --contact-sheet] [--out PATH]",
          "Draws fields of the frames stored in RUN_DIR/frames/*.vdb, off-screen (no display needed).\n"
          "Several fields (--field strain_rate,pressure,packing_fraction) are drawn side by side, each\n"
          "with its own colour range and colorbar (default size 640x480 per panel, the force plot being\n"
          "one more panel; a contact sheet puts one sheet per field side by side, 1280x720 each).\n"
          "The colour range is fixed over all selected frames (min..max over cells with material; strain\n"
          "rate on a log scale from max/10^4 up to its max) unless --range is given. Cells without material\n"
          "are grey, bodies are outlined in cyan, and each image carries a colorbar with the field's unit and\n"
          "the time stamp. The field is drawn at about the image's resolution, blended between cell centres\n"
          "within the material (its edge within half a cell of the cells with material); --cells draws\n"
          "each cell as one flat colour instead. Movies and PNGs show a side panel from RUN_DIR/forces.csv when it exists:\n"
          "for each body, the resisting force -F.d (d = unit direction of its travel from first to last\n"
          "position; Fy for a plate pushed down) against its displacement from its first position,\n"
          "every step as recorded (--force-mean: its running mean over one cell of travel over the faint\n"
          "raw trace).\n"
          "\n"
          "Several runs (furrow render RUN_A RUN_B --field strain_rate --labels loose,dense) are drawn\n"
          "side by side, one field, one colour range over all of them, each panel titled by its label and\n"
          "the force panel carrying one trace per run; their frames pair by index and must agree in time\n"
          "and domain (dx may differ). The paper's movie layouts:\n"
          "  --frame-of BODY  centre every frame on BODY: it stays still and the bed moves past it\n"
          "                   (--zoom F enlarges the view about it)\n"
          "  --normalize      velocity over the moving body's speed v, strain rate over v/L (L its size\n"
          "                   across its travel), time as t v/L; v and L come from RUN_DIR/scene.json and\n"
          "                   are printed in the title\n"
          "\n"
          "--layout takes all of that from RUN_DIR/scene.json's outputs.layout (each paper template\n"
          "names its movie's layout), writing movies/<layout name>.mp4.\n"
          "--points draws the material points of frames/points_NNNNN.vdb (scenes with outputs.points)\n"
          "as discs of their own area coloured by their own value, as the paper's figures do.\n"
          "\n"
          "Outputs (default: a movie):\n"
          "  movie            RUN_DIR/movies/<field>.mp4 (H.264, yuv420p, faststart: plays in browsers;\n"
          "                   even sizes; ~10 s long unless --fps), its last frame as <field>.png beside it\n"
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
           {"--fps", true, false, "movie frames per second (default: the frames over 10 s, 2..60)", "N"},
           {"--labels", true, false, "panel titles of several runs, comma-separated (default: folder names)", "LIST"},
           {"--frame-of", true, false, "follow this body: it stays still in the image", "BODY"},
           {"--zoom", true, false, "with --frame-of: enlarge the view about the body (1..50, default 1)", "F"},
           {"--normalize", false, false, "dimensionless velocity (/v), strain rate (/(v/L)) and time (t v/L)"},
           {"--no-panel", false, false, "leave out the force panel"},
           {"--force-mean", false, false, "force panel: one cell's running mean over the faint raw trace (default: raw)"},
           {"--layout", false, false, "the paper's layout the run's scene names (outputs.layout): fields, frame, scales"},
           {"--points", false, false, "draw the stored material points (outputs.points) as discs coloured by their own value"},
           {"--cells", false, false, "draw each cell as one flat colour (default: blended within the material)"},
           {"--smooth", false, false, "blend values within the material: the default, kept for old scripts"}},
          1,
          8,
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
