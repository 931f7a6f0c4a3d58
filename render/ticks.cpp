#include "render/ticks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace furrow::render {

namespace {
constexpr double kEps = 1e-9;  // relative slack so a tick on an end of the range counts as inside

// Number of multiples of `step` in [lo, hi].
long long multiples_in(double lo, double hi, double step) {
  return (long long)std::floor(hi / step + kEps) - (long long)std::ceil(lo / step - kEps) + 1;
}

// Steps 1, 2, 5 x 10^k in ascending order from below `span` / 1000 up to `span`.
std::vector<double> nice_steps(double span) {
  std::vector<double> steps;
  const int top = int(std::floor(std::log10(span)));
  for (int e = top - 4; e <= top + 1; ++e)
    for (double m : {1.0, 2.0, 5.0}) steps.push_back(m * std::pow(10.0, e));
  return steps;
}

// The step whose tick count is the largest <= max_count, or the next finer one when that leaves
// fewer than 3 (a 2 -> 5 jump can skip from 7 ticks to 2). `count` gives the ticks of a step.
template <class Count>
double pick_step(const std::vector<double>& ascending, int max_count, Count count) {
  for (size_t k = 0; k < ascending.size(); ++k) {
    if (count(ascending[k]) > max_count) continue;
    if (count(ascending[k]) < 3 && k > 0) return ascending[k - 1];
    return ascending[k];
  }
  return ascending.back();
}

std::string format_fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", std::clamp(decimals, 0, 12), v);
  std::string s = buf;
  if (s.find_first_not_of("-0.") == std::string::npos) s = "0";  // no "-0" or "0.00"
  return s;
}

// "2e6", "1.5e-4": the mantissa keeps the digits down to the step's.
std::string format_scientific(double v, double step) {
  if (std::abs(v) < 1e-6 * step) return "0";
  const int e = int(std::floor(std::log10(std::abs(v)) + kEps));
  const int digits = std::max(0, e - int(std::floor(std::log10(step) + kEps)));
  return format_fixed(v / std::pow(10.0, e), digits) + "e" + std::to_string(e);
}

int decimals_for(double step) { return std::max(0, -int(std::floor(std::log10(step) + kEps))); }

// Plain numbers where they stay short (0.001 .. 99999), else scientific.
std::string format_plain(double v, double step) {
  const double a = std::abs(v);
  if (a >= 1e5 || (a > 0 && a < 1e-3) || step < 1e-4) return format_scientific(v, step);
  return format_fixed(v, decimals_for(step));
}

Ticks linear_ticks(double lo, double hi, int max_count, const std::string& si_unit) {
  Ticks t;
  const double step = pick_step(nice_steps(hi - lo), max_count, [&](double s) { return multiples_in(lo, hi, s); });
  for (long long k = (long long)std::ceil(lo / step - kEps); k <= (long long)std::floor(hi / step + kEps); ++k)
    t.values.push_back(std::clamp(double(k) * step, lo, hi));
  const double biggest = std::max(std::abs(t.values.front()), std::abs(t.values.back()));
  if (unit_takes_prefix(si_unit) && biggest > 0) {
    // engineering prefix that puts the largest label in [1, 1000)
    const int e3 = std::clamp(int(std::floor(std::log10(biggest) / 3.0 + kEps)) * 3, -6, 9);
    static const char* names[] = {"µ", "m", "", "k", "M", "G"};
    t.prefix = names[e3 / 3 + 2];
    t.scale = std::pow(10.0, e3);
  }
  for (double v : t.values)
    t.labels.push_back(t.scale == 1.0 ? format_plain(v, step) : format_fixed(v / t.scale, decimals_for(step / t.scale)));
  return t;
}

Ticks log_ticks(double lo, double hi, int max_count) {
  Ticks t;
  const double dlo = std::log10(lo), dhi = std::log10(hi);
  const long long decades = (long long)std::floor(dhi + kEps) - (long long)std::ceil(dlo - kEps) + 1;
  if (decades >= 3) {
    // every 1, 2, 5, 10, ... decades
    std::vector<double> steps;
    for (double s : nice_steps(std::max(10.0, dhi - dlo)))
      if (s >= 1.0) steps.push_back(s);
    const double step = pick_step(steps, max_count, [&](double s) { return multiples_in(dlo, dhi, s); });
    for (long long k = (long long)std::ceil(dlo / step - kEps); k <= (long long)std::floor(dhi / step + kEps); ++k)
      t.values.push_back(std::clamp(std::pow(10.0, double(k) * step), lo, hi));
  } else {
    // fewer than three decades: 1-2-5 (or 1-5, or 1) inside each decade
    for (const std::vector<double>& mantissas : {std::vector<double>{1, 2, 5}, {1, 5}, {1}}) {
      std::vector<double> v;
      for (long long e = (long long)std::floor(dlo) - 1; e <= (long long)std::ceil(dhi); ++e)
        for (double m : mantissas) {
          const double x = m * std::pow(10.0, double(e));
          if (x >= lo * (1 - kEps) && x <= hi * (1 + kEps)) v.push_back(std::clamp(x, lo, hi));
        }
      if (int(v.size()) <= std::max(max_count, 3)) {
        t.values = v;
        break;
      }
    }
    if (t.values.size() < 3) return linear_ticks(lo, hi, max_count, "");  // under a decade wide
  }
  for (double v : t.values) t.labels.push_back(format_plain(v, std::pow(10.0, std::floor(std::log10(v) + kEps))));
  return t;
}
}  // namespace

bool unit_takes_prefix(const std::string& unit) {
  const size_t end = unit.find_first_of("/*^ ");
  const std::string first = unit.substr(0, end);
  if (end != std::string::npos && unit[end] == '^') return false;  // mm^2 is not 1e-3 m^2
  for (const char* s : {"Pa", "m", "N", "s", "J", "W"})
    if (first == s) return true;
  return false;
}

Ticks choose_ticks(double lo, double hi, int max_count, bool log, const std::string& si_unit) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo))
    throw std::invalid_argument("ticks need a finite range with lo < hi, got [" + std::to_string(lo) + ", " +
                                std::to_string(hi) + "]");
  if (log && !(lo > 0)) throw std::invalid_argument("log ticks need lo > 0, got " + std::to_string(lo));
  max_count = std::max(3, max_count);
  Ticks t = log ? log_ticks(lo, hi, max_count) : linear_ticks(lo, hi, max_count, si_unit);
  t.unit = si_unit == "-" ? "" : t.prefix + si_unit;
  return t;
}

double range_fraction(double value, double lo, double hi, bool log) {
  if (log) return (std::log10(value) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
  return (value - lo) / (hi - lo);
}

}  // namespace furrow::render
