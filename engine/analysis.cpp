#include "engine/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "engine/scene/scene_io.hpp"

namespace furrow {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

// |sum_n x_n w_n e^{-2 pi i k n / N}|^2
double dft_power(const std::vector<double>& x, const std::vector<double>* window, int k) {
  const size_t n = x.size();
  double re = 0.0, im = 0.0;
  const double w0 = -2.0 * kPi * k / double(n);
  for (size_t i = 0; i < n; ++i) {
    const double v = window ? x[i] * (*window)[i] : x[i];
    re += v * std::cos(w0 * double(i));
    im += v * std::sin(w0 * double(i));
  }
  return re * re + im * im;
}

// Samples in [lo, hi] box-averaged into whole bins of about `bin` travel (empty bins interpolated
// between filled neighbours), then the least-squares line in travel removed.
struct Binned {
  int64_t samples = 0;
  int bins = 0;
  double bin_m = 0.0, mean = kNaN, slope = 0.0;
  std::vector<double> residual;  // per bin, detrended; empty when no sample fell in the window
};

Binned bin_and_detrend(const std::vector<double>& travel_m, const std::vector<double>& value, double lo,
                       double hi, double bin) {
  Binned out;
  const double len = hi - lo;
  const int nb = std::max(1, int(std::floor(len / bin + 1e-9)));
  out.bins = nb;
  out.bin_m = len / nb;  // whole bins spanning the window exactly
  std::vector<double> sum(nb, 0.0);
  std::vector<int> count(nb, 0);
  for (size_t k = 0; k < travel_m.size(); ++k) {
    const double s = travel_m[k];
    if (!(s >= lo && s <= hi) || !std::isfinite(value[k])) continue;
    const int b = std::min(nb - 1, int((s - lo) / out.bin_m));
    sum[b] += value[k];
    ++count[b];
    ++out.samples;
  }
  std::vector<double> y(nb, kNaN);
  std::vector<int> filled;
  for (int b = 0; b < nb; ++b)
    if (count[b]) {
      y[b] = sum[b] / count[b];
      filled.push_back(b);
    }
  if (filled.empty()) return out;
  for (int b = 0; b < nb; ++b) {
    if (count[b]) continue;
    auto it = std::lower_bound(filled.begin(), filled.end(), b);
    if (it == filled.begin()) y[b] = y[*it];
    else if (it == filled.end()) y[b] = y[filled.back()];
    else {
      const int r = *it, l = *(it - 1);
      y[b] = y[l] + (y[r] - y[l]) * double(b - l) / double(r - l);
    }
  }
  double sx = 0, sy = 0;
  for (int b = 0; b < nb; ++b) {
    sx += (b + 0.5) * out.bin_m;
    sy += y[b];
  }
  const double xm = sx / nb, ym = sy / nb;
  double sxx = 0, sxy = 0;
  for (int b = 0; b < nb; ++b) {
    const double dxb = (b + 0.5) * out.bin_m - xm;
    sxx += dxb * dxb;
    sxy += dxb * (y[b] - ym);
  }
  out.mean = ym;
  out.slope = sxx > 0.0 ? sxy / sxx : 0.0;
  out.residual.resize(nb);
  for (int b = 0; b < nb; ++b) out.residual[b] = y[b] - ym - out.slope * ((b + 0.5) * out.bin_m - xm);
  return out;
}

}  // namespace

DragStats drag_statistics(const std::vector<double>& travel_m, const std::vector<double>& drag_N_per_m,
                          const DragStatsOptions& o) {
  if (travel_m.size() != drag_N_per_m.size())
    throw std::invalid_argument("drag_statistics: travel and drag have different lengths");
  DragStats st;
  st.mean_N_per_m = st.trend_N_per_m2 = st.rms_N_per_m = st.relative_fluctuation = st.period_m = kNaN;
  double lo = o.from_m, hi = o.to_m;
  if (hi < 0.0) {
    hi = -std::numeric_limits<double>::infinity();
    for (double s : travel_m) hi = std::max(hi, s);
  }
  st.from_m = lo;
  st.to_m = hi;
  if (!(hi > lo)) return st;
  const double len = hi - lo;
  const Binned bd = bin_and_detrend(travel_m, drag_N_per_m, lo, hi, o.bin_m > 0.0 ? o.bin_m : len / 1024.0);
  st.bin_m = bd.bin_m;
  st.samples = bd.samples;
  const int nb = bd.bins;
  st.bins = nb;
  if (bd.residual.empty()) return st;
  const std::vector<double>& r = bd.residual;
  double ss = 0.0;
  for (double v : r) ss += v * v;
  const double ym = bd.mean;
  st.mean_N_per_m = ym;
  if (nb < 3) return st;  // a line through two bins leaves nothing to measure
  st.trend_N_per_m2 = bd.slope;
  st.rms_N_per_m = std::sqrt(ss / nb);
  st.relative_fluctuation = ym != 0.0 ? st.rms_N_per_m / std::abs(ym) : kNaN;

  // periodogram of the detrended signal, Fisher's g-test on its largest ordinate
  const int M = (nb - 1) / 2;  // Fourier frequencies strictly between 0 and Nyquist
  if (M < 2 || ss <= 0.0) return st;
  std::vector<double> I(M + 1, 0.0);
  double total = 0.0;
  int kmax = 1;
  for (int k = 1; k <= M; ++k) {
    I[k] = dft_power(r, nullptr, k);
    total += I[k];
    if (I[k] > I[kmax]) kmax = k;
  }
  const double g = I[kmax] / total;
  // P(g_max > g) <= M (1 - g)^(M - 1): the first, dominant term of Fisher's exact series; an upper
  // bound, so the test is conservative
  st.period_p_value = std::min(1.0, M * std::pow(std::max(0.0, 1.0 - g), M - 1));
  if (st.period_p_value >= o.alpha || kmax < 2 || kmax >= M) return st;

  // refine on the Hann-windowed spectrum (narrow, smooth main lobe), Gaussian interpolation
  std::vector<double> hann(nb);
  for (int b = 0; b < nb; ++b) hann[b] = 0.5 - 0.5 * std::cos(2.0 * kPi * (b + 0.5) / nb);
  int kh = kmax;
  double best = dft_power(r, &hann, kh);
  for (int k : {kmax - 1, kmax + 1}) {
    if (k < 2 || k > M - 1) continue;
    const double p = dft_power(r, &hann, k);
    if (p > best) {
      best = p;
      kh = k;
    }
  }
  const double a = std::log(std::max(dft_power(r, &hann, kh - 1), 1e-300));
  const double c = std::log(std::max(dft_power(r, &hann, kh + 1), 1e-300));
  const double b = std::log(std::max(best, 1e-300));
  const double den = a - 2.0 * b + c;
  const double delta = den < 0.0 ? std::clamp(0.5 * (a - c) / den, -0.5, 0.5) : 0.0;
  const double cycles = kh + delta;
  if (cycles < o.min_cycles) return st;
  st.period_m = len / cycles;
  return st;
}

ForceSmoothness force_smoothness(const std::vector<double>& s, const std::vector<double>& F, double cell_m,
                                 double from_m, double to_m, double bin_m) {
  if (s.size() != F.size()) throw std::invalid_argument("force_smoothness: travel and force have different lengths");
  ForceSmoothness r;
  r.mean_N_per_m = r.peak_ratio = r.peak_at_m = r.rms_relative = r.cell_amplitude_relative = r.tick_max_relative = kNaN;
  std::vector<double> prefix(s.size() + 1, 0.0);
  for (size_t k = 0; k < s.size(); ++k) prefix[k + 1] = prefix[k] + F[k];
  double sum = 0.0, dev2 = 0.0;
  for (size_t k = 0; k < s.size(); ++k) {
    if (!(s[k] >= from_m && s[k] <= to_m)) continue;
    const size_t lo = size_t(std::lower_bound(s.begin(), s.end(), s[k] - 0.5 * cell_m) - s.begin());
    const size_t hi = size_t(std::upper_bound(s.begin(), s.end(), s[k] + 0.5 * cell_m) - s.begin());
    const double m = (prefix[hi] - prefix[lo]) / double(hi - lo);
    if (!(F[k] / m <= r.peak_ratio)) {
      r.peak_ratio = F[k] / m;
      r.peak_at_m = s[k];
    }
    sum += F[k];
    dev2 += (F[k] - m) * (F[k] - m);
    ++r.samples;
  }
  if (r.samples == 0) return r;
  r.mean_N_per_m = sum / double(r.samples);
  r.rms_relative = std::sqrt(dev2 / double(r.samples)) / std::abs(r.mean_N_per_m);
  double tick = 0.0;
  for (size_t k = 1; k + 1 < s.size(); ++k)
    if (s[k - 1] >= from_m && s[k + 1] <= to_m) tick = std::max(tick, std::abs(F[k] - 0.5 * (F[k - 1] + F[k + 1])));
  r.tick_max_relative = tick / std::abs(r.mean_N_per_m);
  // binned and detrended as drag_statistics does, then projected on the cell period
  const Binned bd = bin_and_detrend(s, F, from_m, to_m, bin_m);
  double c = 0.0, q = 0.0;
  const size_t nb = bd.residual.size();
  for (size_t b = 0; b < nb; ++b) {
    const double phase = 2.0 * kPi * (from_m + (double(b) + 0.5) * bd.bin_m) / cell_m;
    c += bd.residual[b] * std::cos(phase);
    q += bd.residual[b] * std::sin(phase);
  }
  r.cell_amplitude_relative = 2.0 * std::hypot(c, q) / double(nb) / std::abs(bd.mean);
  return r;
}

bool in_average_window(const Outputs& out, double t_s, double travel_m) {
  if (out.average_from_m >= 0.0)
    return travel_m >= out.average_from_m && (out.average_to_m < 0.0 || travel_m <= out.average_to_m);
  return t_s >= out.average_from_s && (out.average_to_s < 0.0 || t_s <= out.average_to_s);
}

FlowHoles count_flow_holes(const FieldFrame& f, const std::string& field, double flow_threshold,
                           double hole_threshold) {
  const auto it = f.scalars.find(field);
  if (it == f.scalars.end()) throw std::invalid_argument("count_flow_holes: the frame holds no field '" + field + "'");
  const std::vector<float>& v = it->second;
  FlowHoles h;
  for (int j = 0; j < f.ny; ++j)
    for (int i = 0; i < f.nx; ++i) {
      if (!f.active[f.index(i, j)]) continue;
      double sum = 0;
      int n = 0;
      for (int b = std::max(j - 1, 0); b <= std::min(j + 1, f.ny - 1); ++b)
        for (int a = std::max(i - 1, 0); a <= std::min(i + 1, f.nx - 1); ++a)
          if ((a != i || b != j) && f.active[f.index(a, b)]) sum += v[f.index(a, b)], ++n;
      if (n < 3 || !(sum / n > flow_threshold)) continue;
      ++h.flowing;
      if (v[f.index(i, j)] < hole_threshold) ++h.holes;
    }
  return h;
}

double median_finite(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double slip_line_apex_angle_deg(double mu) { return 90.0 - std::atan(mu) * 180.0 / kPi; }

WedgeMeasure measure_wedge(const FieldFrame& f, const BodyOutline& plate, const Vec2& v_plate,
                           const WedgeOptions& o) {
  const size_t cells = size_t(f.nx) * size_t(f.ny);
  if (f.velocity_x.size() != cells || f.velocity_y.size() != cells || f.active.size() != cells)
    throw std::invalid_argument("measure_wedge: frame has no velocity field (store \"velocity\")");
  const double vp = v_plate.norm();
  if (!(vp > 0.0)) throw std::invalid_argument("measure_wedge: plate velocity is zero");
  if (plate.outline_m.empty()) throw std::invalid_argument("measure_wedge: plate outline is empty");
  WedgeMeasure w;
  w.apex_angle_deg = w.left_flank_deg = w.right_flank_deg = w.apex_depth_m = kNaN;
  w.left_flank_x_m = w.right_flank_x_m = kNaN;
  w.mask.assign(cells, 0);
  const double dx = f.dx_m;

  // the bottom face: the lowest vertices of the outline
  double yb = std::numeric_limits<double>::infinity();
  for (const auto& p : plate.outline_m) yb = std::min(yb, p.y());
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0;
  for (const auto& p : plate.outline_m)
    if (p.y() <= yb + 1e-3 * dx) {
      x0 = std::min(x0, p.x());
      x1 = std::max(x1, p.x());
    }
  w.face_y_m = yb;
  w.face_x0_m = x0;
  w.face_x1_m = x1;

  auto xc = [&](int i) { return f.origin_m.x() + (i + 0.5) * dx; };
  auto yc = [&](int j) { return f.origin_m.y() + (j + 0.5) * dx; };
  // rows strictly below the face, columns within a cell of the face
  const int jtop = std::min(f.ny - 1, int(std::ceil((yb - f.origin_m.y()) / dx - 0.5)) - 1);
  const int i0 = std::max(0, int(std::ceil((x0 - dx - f.origin_m.x()) / dx - 0.5)));
  const int i1 = std::min(f.nx - 1, int(std::floor((x1 + dx - f.origin_m.x()) / dx - 0.5)));
  if (jtop < 0 || i1 < i0) return w;
  // mismatch |v - v_plate| / |v_plate| per cell of the window below the face (+inf where empty).
  // No spatial smoothing: a 3 x 3 box cuts the particle-level noise of a frame but rounds the
  // outline where it meets the face and at the apex, a few degrees sharper on an ideal wedge;
  // average over frames instead.
  const int wi0 = std::max(0, i0 - 1), wi1 = std::min(f.nx - 1, i1 + 1), wn = wi1 - wi0 + 1;
  std::vector<double> mis(size_t(wn) * size_t(jtop + 1), std::numeric_limits<double>::infinity());
  auto mismatch = [&](int i, int j) { return mis[size_t(j) * wn + size_t(i - wi0)]; };
  for (int j = 0; j <= jtop; ++j)
    for (int i = wi0; i <= wi1; ++i) {
      const size_t k = f.index(i, j);
      if (f.active[k])
        mis[size_t(j) * wn + size_t(i - wi0)] =
            std::hypot(f.velocity_x[k] - v_plate.x(), f.velocity_y[k] - v_plate.y()) / vp;
    }
  auto moves_with_plate = [&](int i, int j) { return mismatch(i, j) < o.tolerance; };

  // flood fill from the first seed_rows rows under the face: material keeps about half a cell
  // from a body at the grid contact, and the layer touching the face slides along it, so the
  // first row or two may not move with the plate while the zone below does
  std::vector<std::pair<int, int>> stack;
  for (int j = jtop; j >= std::max(0, jtop - std::max(1, o.seed_rows) + 1); --j)
    for (int i = i0; i <= i1; ++i)
      if (xc(i) >= x0 - 0.5 * dx && xc(i) <= x1 + 0.5 * dx && moves_with_plate(i, j)) {
        w.mask[f.index(i, j)] = 1;
        stack.emplace_back(i, j);
      }
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    ++w.cells;
    const int nbr[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
    for (const auto& n : nbr) {
      const int a = n[0], b = n[1];
      if (a < i0 || a > i1 || b < 0 || b > jtop) continue;
      const size_t k = f.index(a, b);
      if (w.mask[k] || !moves_with_plate(a, b)) continue;
      w.mask[k] = 1;
      stack.emplace_back(a, b);
    }
  }
  if (w.cells == 0) return w;
  w.found = true;

  // per row: the region's extent [lo, hi] in cells, then each edge placed where the mismatch
  // crosses the tolerance, interpolated linearly between the last cell inside and the first one
  // outside (the field is smooth across a shear band, so this is sub-cell accurate); at a free
  // surface or void the cell edge is used
  auto edge = [&](int in, int out, int j) {
    const double side = out > in ? 0.5 : -0.5;
    if (out < wi0 || out > wi1 || !f.active[f.index(out, j)]) return xc(in) + side * dx;
    const double e_in = mismatch(in, j), e_out = mismatch(out, j);
    if (!(e_out > e_in) || e_out < o.tolerance) return xc(in) + side * dx;
    const double frac = std::clamp((o.tolerance - e_in) / (e_out - e_in), 0.0, 1.0);
    return xc(in) + 2.0 * side * frac * dx;
  };
  struct Row {
    int j, lo, hi;
  };
  std::vector<Row> rows;  // top to bottom
  for (int j = jtop; j >= 0; --j) {
    int lo = -1, hi = -1;
    for (int i = i0; i <= i1; ++i)
      if (w.mask[f.index(i, j)]) {
        if (lo < 0) lo = i;
        hi = i;
      }
    if (lo >= 0) rows.push_back({j, lo, hi});
  }
  const int jlow = rows.back().j, jhigh = rows.front().j;
  // the flanks start at the widest of the first seed_rows rows (a narrower contact layer above it
  // is not the zone's outline) and use rows at least 3 cells wide (the 1-2 cell apex rows are
  // quantisation)
  size_t first = 0;
  for (size_t k = 1; k < rows.size() && k < size_t(std::max(1, o.seed_rows)); ++k)
    if (rows[k].hi - rows[k].lo > rows[first].hi - rows[first].lo) first = k;
  double sz = 0, szz = 0, sl = 0, slz = 0, sr = 0, srz = 0;
  for (size_t k = first; k < rows.size(); ++k) {
    const Row& row = rows[k];
    if (row.hi - row.lo + 1 < 3) continue;
    const double z = yb - yc(row.j);
    const double xl = edge(row.lo, row.lo - 1, row.j), xr = edge(row.hi, row.hi + 1, row.j);
    sz += z;
    szz += z * z;
    sl += xl;
    slz += xl * z;
    sr += xr;
    srz += xr * z;
    ++w.fit_rows;
  }
  w.rows = jhigh - jlow + 1;
  w.height_m = yb - (yc(jlow) - 0.5 * dx);
  if (w.fit_rows < std::max(2, o.min_fit_rows)) return w;
  const double n = w.fit_rows, den = n * szz - sz * sz;
  if (!(den > 0.0)) return w;
  const double sL = (n * slz - sz * sl) / den, sR = (n * srz - sz * sr) / den;  // dx/dz of each edge
  const double aL = (sl - sL * sz) / n, aR = (sr - sR * sz) / n;
  const double deg = 180.0 / kPi;
  w.left_flank_deg = std::atan(sL) * deg;
  w.right_flank_deg = std::atan(-sR) * deg;
  w.apex_angle_deg = w.left_flank_deg + w.right_flank_deg;
  w.left_flank_x_m = aL, w.right_flank_x_m = aR;
  if (sL - sR > 0.0) w.apex_depth_m = (aR - aL) / (sL - sR);
  return w;
}

// ---------------------------------------------------------------- run.json hook

namespace {

bool moves_vertically(const Motion& m) {
  auto vertical = [](const Vec2& v) { return v.norm() > 0.0 && std::abs(v.x()) <= 1e-6 * v.norm(); };
  if (m.kind == Motion::Kind::ConstantVelocity) return vertical(m.velocity_m_s);
  bool any = false;
  for (const auto& k : m.path) {
    if (k.velocity_m_s.norm() == 0.0) continue;
    if (!vertical(k.velocity_m_s)) return false;
    any = true;
  }
  return any;
}

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

}  // namespace

bool RunAnalysis::measures_wedge(const Scene& scene) {
  const int lead = reference_body_index(scene);
  if (lead < 0) return false;
  const auto& fields = scene.outputs.fields;
  return scene.outputs.frame_interval_s > 0.0 && std::find(fields.begin(), fields.end(), "velocity") != fields.end() &&
         moves_vertically(scene.bodies[size_t(lead)].motion);
}

RunAnalysis::RunAnalysis(const Scene& scene) : out_(&scene.outputs), dx_m_(scene.domain.dx_m) {
  lead_ = reference_body_index(scene);
  if (lead_ < 0) return;
  lead_name_ = scene.bodies[size_t(lead_)].name;
  wedge_ = measures_wedge(scene);
}

void RunAnalysis::add_step(double t_s, double travel_m, const Vec2& force, const Vec2& velocity) {
  if (lead_ < 0 || !in_average_window(*out_, t_s, travel_m)) return;
  const double speed = velocity.norm();
  if (!(speed > 0.0)) return;  // drag is defined against the direction of motion
  travel_m_.push_back(travel_m);
  drag_N_per_m_.push_back(-force.dot(velocity) / speed);
}

void RunAnalysis::add_frame(const FieldFrame& frame, double travel_m, const Vec2& velocity) {
  if (!wedge_) return;
  nlohmann::json e = {{"t_s", frame.time_s}, {"travel_m", travel_m}};
  const BodyOutline* plate = nullptr;
  for (const auto& o : frame.bodies)
    if (o.name == lead_name_) plate = &o;
  if (plate && velocity.norm() > 0.0) {
    const WedgeMeasure m = measure_wedge(frame, *plate, velocity);
    e["apex_angle_deg"] = num(m.apex_angle_deg);
    e["height_m"] = m.found ? num(m.height_m) : nlohmann::json(nullptr);
    e["cells"] = m.cells;
    const double rows = (m.face_y_m - frame.origin_m.y()) / frame.dx_m;
    e["face_offset_cells"] = rows - std::floor(rows);
    // the flank lines themselves, so a viewer can draw them (render/inspector's overlay)
    e["face_y_m"] = m.face_y_m;
    e["left_flank_deg"] = num(m.left_flank_deg);
    e["right_flank_deg"] = num(m.right_flank_deg);
    e["left_flank_x_m"] = num(m.left_flank_x_m);
    e["right_flank_x_m"] = num(m.right_flank_x_m);
    e["apex_depth_m"] = num(m.apex_depth_m);
  } else {
    e["apex_angle_deg"] = nullptr;
    e["height_m"] = nullptr;
    e["cells"] = 0;
  }
  frames_.push_back(e);
}

double double_from_json(const nlohmann::json& j) {
  return j.is_null() ? std::numeric_limits<double>::quiet_NaN() : j.get<double>();
}

std::vector<double> doubles_from_json(const nlohmann::json& j) {
  std::vector<double> v;
  v.reserve(j.size());
  for (const auto& x : j) v.push_back(double_from_json(x));
  return v;
}

nlohmann::json RunAnalysis::state() const {
  return {{"travel_m", travel_m_}, {"drag_N_per_m", drag_N_per_m_}, {"frames", frames_}};
}

void RunAnalysis::restore(const nlohmann::json& j) {
  travel_m_ = doubles_from_json(j.at("travel_m"));
  drag_N_per_m_ = doubles_from_json(j.at("drag_N_per_m"));
  frames_ = j.at("frames");
}

nlohmann::json RunAnalysis::to_json() const {
  if (lead_ < 0) return nullptr;
  DragStatsOptions o;
  if (!travel_m_.empty()) {
    o.from_m = *std::min_element(travel_m_.begin(), travel_m_.end());
    o.to_m = *std::max_element(travel_m_.begin(), travel_m_.end());
  }
  o.bin_m = dx_m_;
  const DragStats d = drag_statistics(travel_m_, drag_N_per_m_, o);
  nlohmann::json j;
  j["lead_body"] = lead_name_;
  j["drag"] = {{"definition",
                "drag = -(force . unit velocity) of the lead body over the averaging window, box-averaged "
                "in bins of travel; fluctuation = RMS about a least-squares line in travel; period from "
                "the periodogram peak if it passes Fisher's g-test, else null"},
               {"from_m", num(d.from_m)},
               {"to_m", num(d.to_m)},
               {"samples", d.samples},
               {"bin_m", num(d.bin_m)},
               {"mean_N_per_m", num(d.mean_N_per_m)},
               {"trend_N_per_m2", num(d.trend_N_per_m2)},
               {"rms_fluctuation_N_per_m", num(d.rms_N_per_m)},
               {"relative_fluctuation", num(d.relative_fluctuation)},
               {"period_m", num(d.period_m)},
               {"period_p_value", num(d.period_p_value)}};
  if (wedge_) {
    // medians over the first quarter and the second half of the travel the frames cover
    double last = 0.0;
    for (const auto& e : frames_) last = std::max(last, e.at("travel_m").get<double>());
    std::vector<double> early, late;
    for (const auto& e : frames_) {
      if (e.at("apex_angle_deg").is_null()) continue;
      const double s = e.at("travel_m").get<double>(), a = e.at("apex_angle_deg").get<double>();
      if (s <= 0.25 * last) early.push_back(a);
      if (s >= 0.5 * last) late.push_back(a);
    }
    j["wedge"] = {{"early_median_apex_angle_deg", num(median_finite(early))},
                  {"late_median_apex_angle_deg", num(median_finite(late))},
                  {"early_frames", early.size()},
                  {"late_frames", late.size()}};
  }
  if (wedge_)
    j["wedge"].update({{"definition",
                   "cells below the plate face moving with it (|v - v_plate| < 0.1 |v_plate|), connected "
                   "to the face; apex_angle_deg = full angle between least-squares flank lines (compare "
                   "with 90 - atan(mu) deg; frames scatter by several degrees, compare medians); "
                   "height_m = depth of the region below the face; face_offset_cells = height of the "
                   "face above the grid node line below it, in cells (near 0 the grid contact lags and "
                   "the zone may be lost); flank lines: x = left_flank_x_m + tan(left_flank_deg) (face_y_m - y) "
                   "and x = right_flank_x_m - tan(right_flank_deg) (face_y_m - y), angles from the vertical, "
                   "positive when converging; apex_depth_m = where they meet below the face (null when they "
                   "do not); early/late medians over the frames with an angle in the first "
                   "quarter / second half of the travel; see engine/analysis.hpp"},
                  {"frames", frames_}});
  return j;
}


// ---------------------------------------------------------------- column collapse
CollapseGeometry collapse_geometry(const Scene& scene) {
  CollapseGeometry g;
  if (!scene.bodies.empty() || scene.beds.empty() || !scene.effects.gravity) return g;
  double x0 = scene.beds[0].min_m.x(), x1 = scene.beds[0].max_m.x(), y0 = scene.beds[0].min_m.y(),
         y1 = scene.beds[0].max_m.y();
  for (const auto& b : scene.beds) {
    x0 = std::min(x0, b.min_m.x()), x1 = std::max(x1, b.max_m.x());
    y0 = std::min(y0, b.min_m.y()), y1 = std::max(y1, b.max_m.y());
  }
  const double eps = 1e-9 * scene.domain.width_m;
  const bool left = x0 <= eps, right = x1 >= scene.domain.width_m - eps;
  if (left && right) return g;  // a bed from wall to wall: nothing to release
  g.active = true;
  g.side = left ? 1 : right ? -1 : 0;
  g.back_x_m = left ? x0 : right ? x1 : 0.5 * (x0 + x1);
  g.L0_m = g.side == 0 ? 0.5 * (x1 - x0) : x1 - x0;
  g.floor_y_m = y0;
  g.H0_m = y1 - y0;
  g.cell_m = scene.domain.dx_m;
  g.point_half_m = 0.5 * scene.domain.dx_m / std::max(1, scene.solver.particles_per_cell_1d);
  return g;
}

std::vector<std::pair<double, double>> collapse_surface(const ParticleView& p, const CollapseGeometry& g) {
  std::map<long, std::vector<std::pair<double, double>>> columns;  // cell column -> (bottom, top) of its points
  for (size_t i = 0; i < p.count; ++i) {
    const double y = p.y_m[i] - g.floor_y_m;
    columns[long(std::floor(p.x_m[i] / g.cell_m))].emplace_back(y - g.point_half_m, y + g.point_half_m);
  }
  std::vector<std::pair<double, double>> surface;
  for (auto& [c, points] : columns) {
    std::sort(points.begin(), points.end());
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& [bottom, point_top] : points) {
      if (std::isfinite(top) && bottom > top + 2.0 * g.cell_m) break;  // a grain in flight above the deposit
      top = std::max(top, point_top);
    }
    surface.emplace_back((double(c) + 0.5) * g.cell_m, top);
  }
  return surface;
}

CollapseSample measure_collapse(const ParticleView& p, const CollapseGeometry& g, double t_s,
                                std::vector<std::pair<double, double>>* surface) {
  CollapseSample s;
  s.t_s = t_s;
  if (p.count == 0) return s;
  std::vector<double> reach(p.count);
  for (size_t i = 0; i < p.count; ++i) {
    const double dx = p.x_m[i] - g.back_x_m;
    reach[i] = g.side > 0 ? dx : g.side < 0 ? -dx : std::abs(dx);
  }
  const size_t k = size_t(0.995 * double(p.count - 1));
  std::nth_element(reach.begin(), reach.begin() + std::ptrdiff_t(k), reach.end());
  s.front_m = reach[k] + g.point_half_m;
  s.height_m = 0.0;
  std::vector<std::pair<double, double>> columns = collapse_surface(p, g);
  for (const auto& [x, h] : columns) s.height_m = std::max(s.height_m, h);
  if (surface) *surface = std::move(columns);
  return s;
}

CollapseAnalysis::CollapseAnalysis(const Scene& scene) : g_(collapse_geometry(scene)) {
  interval_s_ = scene.outputs.frame_interval_s > 0.0 ? scene.outputs.frame_interval_s : scene.solver.end_time_s / 100.0;
}

void CollapseAnalysis::add_step(double t_s, const ParticleView& p, bool last) {
  if (!g_.active) return;
  const bool sampled_now = !samples_.empty() && samples_.back().t_s == t_s;
  if (last && sampled_now) samples_.pop_back();  // measured again below, with its surface
  if (!last && t_s < next_s_ - 1e-12) return;
  std::vector<std::pair<double, double>> surface;
  samples_.push_back(measure_collapse(p, g_, t_s, last ? &surface : nullptr));
  next_s_ = t_s + interval_s_;
  if (!last) return;
  profile_x_m_.clear();
  profile_height_m_.clear();
  for (const auto& [x, h] : surface) profile_x_m_.push_back(x), profile_height_m_.push_back(h);
}

nlohmann::json CollapseAnalysis::state() const {
  nlohmann::json samples = nlohmann::json::array();
  for (const auto& c : samples_) samples.push_back({c.t_s, c.front_m, c.height_m});
  return {{"next_s", next_s_}, {"samples", samples}};
}

void CollapseAnalysis::restore(const nlohmann::json& j) {
  next_s_ = j.at("next_s").get<double>();
  samples_.clear();
  for (const auto& c : j.at("samples")) samples_.push_back({double_from_json(c.at(0)), double_from_json(c.at(1)), double_from_json(c.at(2))});
}

nlohmann::json CollapseAnalysis::to_json() const {
  if (!g_.active || samples_.empty()) return nullptr;
  const CollapseSample& last = samples_.back();
  // settled: the front moved less than 1% of L0 over the last tenth of the run
  double front_then = last.front_m;
  for (const auto& s : samples_)
    if (s.t_s >= 0.9 * last.t_s) {
      front_then = s.front_m;
      break;
    }
  nlohmann::json t = nlohmann::json::array(), f = nlohmann::json::array(), h = nlohmann::json::array();
  for (const auto& s : samples_) t.push_back(s.t_s), f.push_back(s.front_m), h.push_back(s.height_m);
  return {{"definition",
           "front: distance from the column's back wall (both sides free: its centre line) beyond which "
           "0.5% of the material points lie, plus half their seeded spacing; height: highest top of the "
           "material resting on the floor (per cell column, up through gaps under two cells: grains "
           "in flight do not count); L0, H0: the beds' extent; runout (Lf - L0) / L0 and Hf / H0 at the end"},
          {"spreads", g_.side > 0 ? "+x" : g_.side < 0 ? "-x" : "both ways"},
          {"L0_m", g_.L0_m},
          {"H0_m", g_.H0_m},
          {"aspect_ratio", g_.H0_m / g_.L0_m},
          {"final_front_m", last.front_m},
          {"final_height_m", last.height_m},
          {"runout_relative", (last.front_m - g_.L0_m) / g_.L0_m},
          {"final_height_relative", last.height_m / g_.H0_m},
          {"settled", std::abs(last.front_m - front_then) < 0.01 * g_.L0_m},
          {"t_s", t},
          {"front_m", f},
          {"height_m", h},
          {"final_surface", {{"x_m", profile_x_m_}, {"height_m", profile_height_m_}}}};
}

}  // namespace furrow
