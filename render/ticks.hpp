// Colorbar ticks: where to put them and how to label them. Linear ranges get round values in 1-2-5
// steps, labelled in a unit with an SI prefix when the unit takes one (pressure 0..9747 Pa reads
// 0, 2, 4, 6, 8 kPa, not 0, 2437, 4874 Pa); log ranges get decades (0.001, 0.01, 0.1, 1 1/s).
// Pure functions over plain numbers: the renderer draws what they return.
#pragma once
#include <string>
#include <vector>

namespace furrow::render {

struct Ticks {
  std::vector<double> values;       // SI values, ascending, all inside [lo, hi]
  std::vector<std::string> labels;  // one per value, in `unit`
  std::string prefix;               // SI prefix of the labels: "", "k", "M", "G", "m", "µ"
  double scale = 1.0;               // a label reads value / scale
  std::string unit;                 // prefix + the SI unit ("kPa"); "" for dimensionless ("-")
};

// Whether an SI unit string takes a prefix ("Pa", "m/s", "N/m" do; "-", "1/s", "kg/m^3" do not:
// "k1/s" or "kkg/m^3" would mislead).
bool unit_takes_prefix(const std::string& unit);

// Ticks over [lo, hi] (lo < hi, both finite; lo > 0 for log), 3 to max(max_count, 8) of them:
// the largest count <= max_count that a 1-2-5 step gives (or decades, every 1, 2, 5, ... decades,
// for log), falling back to the next finer step when a coarser one would leave fewer than 3.
// A log range narrower than three decades gets 1-2-5 ticks inside each decade. Labels are as short
// as tells the ticks apart. Throws std::invalid_argument for a bad range.
Ticks choose_ticks(double lo, double hi, int max_count, bool log, const std::string& si_unit = "");

// Where a value sits along a colour range, 0 at lo and 1 at hi (log10 for log ranges).
double range_fraction(double value, double lo, double hi, bool log);

}  // namespace furrow::render
