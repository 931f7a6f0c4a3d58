#include "app/study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "app/progress.hpp"
#include "engine/analysis.hpp"
#include "engine/scene/scene_io.hpp"

namespace furrow::study {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const std::vector<std::pair<Quantity, std::string>> kQuantities = {{Quantity::DragMean, "drag_mean"},
                                                                   {Quantity::LiftMean, "lift_mean"},
                                                                   {Quantity::PeakForce, "peak_force"},
                                                                   {Quantity::WedgeAngle, "wedge_angle"},
                                                                   {Quantity::Fluctuation, "fluctuation"}};

std::string fmt(const char* f, double v) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}


// Finished rungs with a value, by group, coarse to fine (largest dx first, then fewest particle-steps).
std::map<std::string, std::vector<Rung*>> by_group(std::vector<Rung>& rungs) {
  std::map<std::string, std::vector<Rung*>> g;
  for (auto& r : rungs)
    if (r.ok && std::isfinite(r.value)) g[r.group].push_back(&r);
  for (auto& [k, v] : g)
    std::stable_sort(v.begin(), v.end(), [](const Rung* a, const Rung* b) {
      if (a->dx_m != b->dx_m) return a->dx_m > b->dx_m;
      return a->estimated_particle_steps < b->estimated_particle_steps;
    });
  return g;
}

}  // namespace

std::string wall_text(double s) {
  if (!std::isfinite(s)) return "";
  return s < 60.0 ? fmt(s < 10.0 ? "%.2f s" : "%.1f s", s) : cli::format_duration(s);
}

Quantity parse_quantity(const std::string& name) {
  for (const auto& [q, n] : kQuantities)
    if (n == name) return q;
  throw StudyError("--quantity " + name + ": expected one of drag_mean, lift_mean, peak_force, wedge_angle, fluctuation");
}

std::string quantity_name(Quantity q) {
  for (const auto& [k, n] : kQuantities)
    if (k == q) return n;
  return "?";
}

std::string quantity_unit(Quantity q) {
  return q == Quantity::WedgeAngle ? "deg" : q == Quantity::Fluctuation ? "of the mean" : "N/m";
}

// the unit part of the quantity's columns in study.csv
static std::string column_suffix(Quantity q) {
  return q == Quantity::WedgeAngle ? "_deg" : q == Quantity::Fluctuation ? "_relative" : "_N_per_m";
}

std::string quantity_column(Quantity q) { return quantity_name(q) + column_suffix(q); }

std::string quantity_meaning(Quantity q) {
  switch (q) {
    case Quantity::DragMean:
      return "mean drag (force against the body's motion) over the scene's averaging window, N/m";
    case Quantity::LiftMean:
      return "mean lift (force across the body's motion, +90 degrees from it) over the averaging window, N/m";
    case Quantity::PeakForce:
      return "initial peak of the drag (smoothed over 2 dx of travel, the largest drag before it first "
             "falls 5% below it), N/m";
    case Quantity::WedgeAngle:
      return "apex angle of the rigid wedge under the plate, median over the frames of the second half of "
             "the travel (run.json analysis.wedge), deg";
    case Quantity::Fluctuation:
      return "relative fluctuation of the lead body's drag: RMS about a line in travel over its mean, bins of "
             "one dx of travel (run.json analysis.drag; paper case 3)";
  }
  return "";
}

std::string cannot_produce(const Scene& scene, Quantity q, const std::string& body) {
  const int lead = reference_body_index(scene);
  if (lead < 0) return "the scene has no moving body, so no drag, lift or wedge";
  if (!body.empty()) {
    const auto it = std::find_if(scene.bodies.begin(), scene.bodies.end(), [&](const Body& b) { return b.name == body; });
    if (it == scene.bodies.end()) {
      std::string names;
      for (const auto& b : scene.bodies) names += (names.empty() ? "" : ", ") + b.name;
      return "--body " + body + ": the scene has no such body (it has: " + names + ")";
    }
    if (motion_max_speed_m_s(it->motion) <= 0.0) return "--body " + body + ": the body does not move, so it has no drag";
  }
  if (q == Quantity::Fluctuation && !body.empty() && body != scene.bodies[size_t(lead)].name)
    return "fluctuation is measured on the lead body " + scene.bodies[size_t(lead)].name + " only";
  if (q == Quantity::WedgeAngle) {
    if (!body.empty() && body != scene.bodies[size_t(lead)].name)
      return "wedge_angle is measured under the lead body " + scene.bodies[size_t(lead)].name + " only";
    if (!RunAnalysis::measures_wedge(scene))
      return "wedge_angle needs a lead body moving vertically (a descending plate), frames "
             "(outputs.frame_interval_s > 0) and the velocity field in outputs.fields";
  }
  return "";
}

double extract(Quantity q, const sweep::RunMetrics& m, const nlohmann::json& run_json, const std::string& body,
               std::string* why) {
  auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return kNaN;
  };
  if (q == Quantity::Fluctuation) {
    if (!body.empty() && body != run_json.value("/analysis/lead_body"_json_pointer, std::string()))
      return fail("fluctuation is measured on the lead body only");
    const auto f = run_json.value("/analysis/drag/relative_fluctuation"_json_pointer, nlohmann::json());
    if (!f.is_number()) return fail("run.json has no drag fluctuation (no lead body, or too short a travel)");
    return f.get<double>();
  }
  if (q == Quantity::WedgeAngle) {
    const auto a = run_json.value("/analysis/wedge/late_median_apex_angle_deg"_json_pointer, nlohmann::json());
    if (!a.is_number()) return fail("no wedge was found in the frames of the second half of the travel");
    return a.get<double>();
  }
  const sweep::BodyMetrics* b = nullptr;
  for (const auto& bm : m.bodies)
    if (body.empty() ? bm.moving : bm.name == body) {
      b = &bm;
      break;
    }
  if (!b) return fail("no such moving body in the run");
  const double v = q == Quantity::DragMean   ? b->mean_drag_N_per_m
                   : q == Quantity::LiftMean ? b->mean_lift_N_per_m
                                             : b->peak_drag_N_per_m;
  if (!std::isfinite(v))
    return fail(q == Quantity::PeakForce ? "the drag never fell 5% below a maximum (no initial peak)"
                                         : "the averaging window saw no step");
  return v;
}

Richardson richardson(double h1, double q1, double h2, double q2, double h3, double q3) {
  Richardson r;
  if (!(h1 > h2 && h2 > h3 && h3 > 0.0)) {
    r.note = "needs three distinct dx";
    return r;
  }
  const double d12 = q1 - q2, d23 = q2 - q3;
  if (d23 == 0.0 || d12 == 0.0) {
    r.note = "two rungs agree exactly";
    return r;
  }
  const double ratio = d12 / d23;
  if (ratio <= 0.0) {
    r.note = "not monotone in dx (the differences change sign)";
    return r;
  }
  // (h1^p - h2^p) / (h2^p - h3^p) grows with p; bisect for the observed ratio over a plausible range
  auto g = [&](double p) { return (std::pow(h1, p) - std::pow(h2, p)) / (std::pow(h2, p) - std::pow(h3, p)) - ratio; };
  double lo = 0.1, hi = 8.0;
  if (g(lo) > 0.0 || g(hi) < 0.0) {
    r.note = "observed order outside [0.1, 8]";
    return r;
  }
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0.0 ? hi : lo) = mid;
  }
  r.order = 0.5 * (lo + hi);
  const double C = d23 / (std::pow(h2, r.order) - std::pow(h3, r.order));
  r.extrapolated = q3 - C * std::pow(h3, r.order);
  r.ok = true;
  return r;
}

Summary analyse(std::vector<Rung>& rungs) {
  Summary s;
  s.reference = kNaN;
  for (auto& r : rungs) r.diff_finest = r.extrapolated = r.diff_extrapolated = r.order = r.error_relative = kNaN;
  auto groups = by_group(rungs);
  std::map<std::string, Richardson> extrap;
  for (auto& [name, g] : groups) {
    const Rung* finest = g.back();
    for (size_t i = 0; i < g.size(); ++i) {
      g[i]->diff_finest = g[i]->value - finest->value;
      if (i + 2 < g.size()) {
        const Richardson o = richardson(g[i]->dx_m, g[i]->value, g[i + 1]->dx_m, g[i + 1]->value, g[i + 2]->dx_m,
                                        g[i + 2]->value);
        if (o.ok) g[i]->order = o.order;
      }
    }
    Richardson r;
    r.note = "fewer than three finished rungs";
    if (g.size() >= 3) {
      const size_t n = g.size();
      r = richardson(g[n - 3]->dx_m, g[n - 3]->value, g[n - 2]->dx_m, g[n - 2]->value, g[n - 1]->dx_m, g[n - 1]->value);
    }
    extrap[name] = r;
    s.groups.emplace_back(name, r);
    for (Rung* x : g)
      if (r.ok) {
        x->extrapolated = r.extrapolated;
        x->diff_extrapolated = x->value - r.extrapolated;
      }
  }
  // the reference comes from the most expensive finished rung
  const Rung* best = nullptr;
  for (const auto& [name, g] : groups)
    for (const Rung* x : g)
      // ties (e.g. shape functions at one dx) go to the one that took longer: the higher order
      if (!best || x->estimated_particle_steps > best->estimated_particle_steps ||
          (x->estimated_particle_steps == best->estimated_particle_steps && x->wall_s > best->wall_s))
        best = x;
  if (!best) return s;
  const Richardson& r = extrap[best->group];
  if (r.ok) {
    s.reference = r.extrapolated;
    s.reference_from = "Richardson extrapolation of " + (best->group.empty() ? std::string("the dx ladder") : best->group) +
                       " (observed order " + fmt("%.2f", r.order) + ")";
  } else {
    s.reference = best->value;
    s.reference_from = "the most expensive rung, " + best->dir + " (no extrapolation: " + r.note + ")";
  }
  for (auto& x : rungs)
    if (x.ok && std::isfinite(x.value) && s.reference != 0.0)
      x.error_relative = std::abs(x.value - s.reference) / std::abs(s.reference);
  return s;
}

double predict_wall_s(const std::vector<Rung>& rungs, const Rung& r, std::string* basis) {
  std::vector<const Rung*> same, any;
  for (const auto& x : rungs) {
    if (&x == &r || !x.ok || !(x.wall_s > 0.0) || !(x.estimated_particle_steps > 0.0)) continue;
    any.push_back(&x);
    if (x.group == r.group) same.push_back(&x);
  }
  auto proportional = [&](const Rung* x, const std::string& what) {
    if (basis) *basis = what + " " + x->dir;
    return x->wall_s * r.estimated_particle_steps / x->estimated_particle_steps;
  };
  if (same.size() >= 2) {
    // least squares through the group's rungs: a fixed start-up cost plus a cost per particle-step
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const Rung* x : same) {
      sx += x->estimated_particle_steps, sy += x->wall_s;
      sxx += x->estimated_particle_steps * x->estimated_particle_steps;
      sxy += x->estimated_particle_steps * x->wall_s;
    }
    const double n = double(same.size()), den = n * sxx - sx * sx;
    const double b = den > 0.0 ? (n * sxy - sx * sy) / den : 0.0, a = (sy - b * sx) / n;
    if (b > 0.0 && a >= 0.0) {
      if (basis) *basis = "line through " + std::to_string(same.size()) + " rungs of the same settings";
      return a + b * r.estimated_particle_steps;
    }
  }
  auto most_expensive = [](const std::vector<const Rung*>& v) {
    return *std::max_element(v.begin(), v.end(), [](const Rung* a, const Rung* b) {
      return a->estimated_particle_steps < b->estimated_particle_steps;
    });
  };
  if (!same.empty()) return proportional(most_expensive(same), "scaled from");
  if (!any.empty()) return proportional(most_expensive(any), "scaled from (other settings)");
  if (basis) *basis = "nothing finished yet";
  return kNaN;
}

// ---- outputs ------------------------------------------------------------------------------------

std::string study_csv(const std::vector<sweep::Vary>& ladders, Quantity q, const std::vector<Rung>& rungs) {
  const std::string u = column_suffix(q);
  std::string s = "rung";
  for (const auto& l : ladders) s += "," + sweep::csv_quote(l.column);
  s += ",dx_m,status," + quantity_column(q) + ",diff_from_finest" + u + ",extrapolated" + u +
       ",diff_from_extrapolated" + u + ",observed_order,error_vs_reference_percent,predicted_wall_s,wall_s,particles,"
       "steps,particle_steps,peak_memory_MB,state_memory_MB,threads,note\n";
  for (const auto& r : rungs) {
    s += sweep::csv_quote(r.dir);
    for (const auto& v : r.values) s += "," + sweep::csv_quote(v);
    const bool done = r.ok;
    s += "," + fmt("%.9g", r.dx_m) + "," + (done ? (r.reused ? "reused" : "ok") : (r.error.empty() ? "pending" : "failed"));
    s += "," + fmt("%.9g", r.value) + "," + fmt("%.9g", r.diff_finest) + "," + fmt("%.9g", r.extrapolated) + "," +
         fmt("%.9g", r.diff_extrapolated) + "," + fmt("%.4g", r.order) + "," + fmt("%.6g", 100.0 * r.error_relative);
    s += "," + fmt("%.4g", r.predicted_wall_s) + "," + (done ? fmt("%.4g", r.wall_s) : "") + "," +
         (done ? fmt("%.0f", r.particles) : "") + "," + (done ? fmt("%.0f", r.steps) : "") + "," +
         (done ? fmt("%.6g", r.particle_steps) : "") + "," + (done ? fmt("%.1f", r.peak_resident_bytes / 1e6) : "") +
         "," + (done ? fmt("%.2f", r.state_bytes / 1e6) : "") + "," + (done ? std::to_string(r.threads) : "") + "," +
         sweep::csv_quote(r.error) + "\n";
  }
  return s;
}

std::string study_markdown(const std::string& scene_name, const std::vector<sweep::Vary>& ladders, Quantity q,
                           const std::string& body, const std::vector<Rung>& rungs, const Summary& s) {
  const std::string unit = quantity_unit(q);
  std::string md = "# Study of " + scene_name + ": " + quantity_name(q) + "\n\n";
  md += "Quantity: " + quantity_meaning(q) + (body.empty() ? "" : " (body " + body + ")") + ".\n\n";
  md += "Ladders:";
  for (const auto& l : ladders) md += " `" + l.spec + "`";
  md += "\n\nReference (best estimate of the converged value): " +
        (std::isfinite(s.reference) ? fmt("%.6g", s.reference) + " " + unit + ", from " + s.reference_from : "none yet") +
        ".\n\n";
  md += "| rung | value (" + unit + ") | vs finest (" + unit + ") | vs extrapolated (" + unit +
        ") | order | error vs reference | wall predicted | wall measured | particle-steps | peak memory |\n";
  md += "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& r : rungs) {
    std::string label;
    for (size_t k = 0; k < ladders.size(); ++k) label += (k ? ", " : "") + ladders[k].column + "=" + r.values[k];
    const std::string status = r.ok ? "" : (r.error.empty() ? " (not run)" : " (failed: " + r.error + ")");
    md += "| " + label + status + " | " + fmt("%.5g", r.value) + " | " + fmt("%+.4g", r.diff_finest) + " | " +
          fmt("%+.4g", r.diff_extrapolated) + " | " + fmt("%.2f", r.order) + " | " +
          (std::isfinite(r.error_relative) ? fmt("%.2f", 100.0 * r.error_relative) + "%" : "") + " | " +
          wall_text(r.predicted_wall_s) + " | " +
          (r.ok ? wall_text(r.wall_s) : "") + " | " + (r.ok ? fmt("%.3g", r.particle_steps) : "") + " | " +
          (r.ok ? fmt("%.0f MB", r.peak_resident_bytes / 1e6) : "") + " |\n";
  }
  md += "\n";
  for (const auto& [g, r] : s.groups)
    md += "- Richardson in dx" + (g.empty() ? std::string() : " for " + g) + ": " +
          (r.ok ? fmt("%.6g", r.extrapolated) + " " + unit + ", observed order " + fmt("%.2f", r.order)
                : "none (" + r.note + ")") +
          "\n";
  // the answer a user wants: the cheapest rung that reaches a given error
  for (double tol : {0.10, 0.05, 0.02, 0.01}) {
    const Rung* cheapest = nullptr;
    for (const auto& r : rungs)
      if (r.ok && std::isfinite(r.error_relative) && r.error_relative <= tol && (!cheapest || r.wall_s < cheapest->wall_s))
        cheapest = &r;
    md += "- Within " + fmt("%.0f", 100 * tol) + "% of the reference: " +
          (cheapest ? "cheapest is " + cheapest->dir + " (" + wall_text(cheapest->wall_s) + ", error " +
                          fmt("%.2f", 100.0 * cheapest->error_relative) + "%)"
                    : std::string("no rung")) +
          "\n";
  }
  md += "\nErrors are relative to the reference; the rung the reference comes from has no error of its own\n"
        "when there is no extrapolation. Wall times are this machine's, with the threads in study.csv; the\n"
        "prediction before each rung uses only the rungs finished before it.\n";
  return md;
}

render::PlotFigure study_figure(const std::string& scene_name, Quantity q, const std::vector<Rung>& rungs,
                                const Summary& s) {
  render::PlotFigure f;
  f.title = "Study of " + scene_name + ": " + quantity_name(q) + ", error against cost";
  render::PlotPanel cost, conv;
  cost.title = "error vs wall time";
  cost.x_label = "wall time (s); points labelled by dx";
  cost.y_label = "|error| vs reference (%)";
  cost.log_x = cost.log_y = true;
  cost.legend_top = true;  // errors fall to the bottom right as the cost grows
  conv.title = quantity_name(q) + " vs dx";
  conv.x_label = "dx (mm)";
  conv.y_label = quantity_name(q) + " (" + quantity_unit(q) + ")";
  conv.log_x = true;
  std::map<std::string, std::vector<const Rung*>> groups;
  for (const auto& r : rungs)
    if (r.ok && std::isfinite(r.value)) groups[r.group].push_back(&r);
  double dx_lo = HUGE_VAL, dx_hi = -HUGE_VAL;
  int color = 0;
  for (auto& [g, v] : groups) {
    std::stable_sort(v.begin(), v.end(), [](const Rung* a, const Rung* b) { return a->wall_s < b->wall_s; });
    render::PlotSeries e, c;
    e.label = c.label = g.empty() ? quantity_name(q) : g;
    e.color = c.color = color++;
    for (const Rung* r : v) {
      e.x.push_back(r->wall_s);
      e.y.push_back(100.0 * r->error_relative);
      e.point_labels.push_back(fmt("%.3g", 1000.0 * r->dx_m) + " mm");
    }
    std::stable_sort(v.begin(), v.end(), [](const Rung* a, const Rung* b) { return a->dx_m > b->dx_m; });
    for (const Rung* r : v) {
      c.x.push_back(1000.0 * r->dx_m);
      c.y.push_back(r->value);
      dx_lo = std::min(dx_lo, 1000.0 * r->dx_m), dx_hi = std::max(dx_hi, 1000.0 * r->dx_m);
    }
    cost.series.push_back(e);
    conv.series.push_back(c);
  }
  if (std::isfinite(s.reference) && dx_lo <= dx_hi) {
    render::PlotSeries ref;
    ref.label = "reference";
    ref.x = {dx_lo, dx_hi};
    ref.y = {s.reference, s.reference};
    ref.dashed = true;
    ref.markers = false;
    ref.color = 5;
    conv.series.push_back(ref);
    conv.notes.push_back("reference " + fmt("%.5g", s.reference) + " " + quantity_unit(q));
  }
  f.panels = {cost, conv};
  return f;
}

}  // namespace furrow::study
