// The colorbar tick chooser over ranges from 1e-3 to 1e6: round values in 1-2-5 steps inside the
// range, 3..8 of them, short distinct labels and the right SI prefix; decades on log ranges.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "render/ticks.hpp"

using namespace furrow::render;

namespace {
// The step between ticks is 1, 2 or 5 times a power of ten (within round-off).
bool is_125(double step) {
  const double e = std::floor(std::log10(step) + 1e-9);
  const double m = step / std::pow(10.0, e);
  return std::abs(m - 1) < 1e-6 || std::abs(m - 2) < 1e-6 || std::abs(m - 5) < 1e-6;
}

void expect_sane(const Ticks& t, double lo, double hi, bool log, const std::string& what) {
  ASSERT_EQ(t.values.size(), t.labels.size()) << what;
  EXPECT_GE(t.values.size(), 3u) << what;
  EXPECT_LE(t.values.size(), 8u) << what;
  std::set<std::string> distinct(t.labels.begin(), t.labels.end());
  EXPECT_EQ(distinct.size(), t.labels.size()) << what;
  for (size_t k = 0; k < t.values.size(); ++k) {
    EXPECT_GE(t.values[k], lo) << what;
    EXPECT_LE(t.values[k], hi) << what;
    // "1.00e-3" beside "9.8e-4" is the longest (a range 10% wide at 1e-3 of a unit with no prefix)
    EXPECT_LE(t.labels[k].size(), 7u) << what << ": '" << t.labels[k] << "'";
    // the label reads the value in the prefixed unit
    const double read = std::stod(t.labels[k]) * t.scale;
    EXPECT_NEAR(read, t.values[k], 1e-6 * std::max(std::abs(t.values[k]), (hi - lo))) << what << " " << t.labels[k];
    if (k > 0) {
      EXPECT_GT(t.values[k], t.values[k - 1]) << what;
      if (!log) {
        EXPECT_TRUE(is_125(t.values[k] - t.values[k - 1])) << what << " step " << t.values[k] - t.values[k - 1];
      }
    }
  }
}
}  // namespace

TEST(Ticks, PressureReadsInKilopascalAtRoundValues) {
  // the old colorbar said 0, 2437, 4874, 7310, 9747 Pa
  const Ticks t = choose_ticks(0.0, 9747.0, 6, false, "Pa");
  EXPECT_EQ(t.unit, "kPa");
  EXPECT_EQ(t.prefix, "k");
  EXPECT_DOUBLE_EQ(t.scale, 1000.0);
  EXPECT_EQ(t.labels, (std::vector<std::string>{"0", "2", "4", "6", "8"}));
  EXPECT_DOUBLE_EQ(t.values.back(), 8000.0);
  const Ticks half = choose_ticks(4874.0, 9747.0, 6, false, "Pa");
  EXPECT_EQ(half.labels, (std::vector<std::string>{"5", "6", "7", "8", "9"}));
  const Ticks mega = choose_ticks(0.0, 2.4e6, 6, false, "Pa");
  EXPECT_EQ(mega.unit, "MPa");
  EXPECT_EQ(mega.labels, (std::vector<std::string>{"0", "0.5", "1.0", "1.5", "2.0"}));
  const Ticks small = choose_ticks(0.0, 0.8, 6, false, "Pa");  // a nearly empty bed
  EXPECT_EQ(small.unit, "mPa");
  EXPECT_EQ(small.labels, (std::vector<std::string>{"0", "200", "400", "600", "800"}));
}

TEST(Ticks, SignedAndDimensionlessRanges) {
  const Ticks s = choose_ticks(-480.0, 1530.0, 6, false, "Pa");
  EXPECT_EQ(s.unit, "kPa");
  EXPECT_EQ(s.labels, (std::vector<std::string>{"0", "0.5", "1.0", "1.5"}));
  const Ticks w = choose_ticks(-520.0, 1530.0, 6, false, "Pa");
  EXPECT_EQ(w.labels, (std::vector<std::string>{"-0.5", "0", "0.5", "1.0", "1.5"}));
  // packing fraction takes no prefix ("-": no unit at all)
  const Ticks phi = choose_ticks(0.552, 0.624, 6, false, "-");
  EXPECT_EQ(phi.unit, "");
  EXPECT_EQ(phi.labels, (std::vector<std::string>{"0.56", "0.58", "0.60", "0.62"}));
  // velocity: mm/s
  const Ticks v = choose_ticks(0.0, 0.0537, 6, false, "m/s");
  EXPECT_EQ(v.unit, "mm/s");
  EXPECT_EQ(v.labels, (std::vector<std::string>{"0", "10", "20", "30", "40", "50"}));
  // bulk density: no kkg/m^3
  const Ticks rho = choose_ticks(1380.0, 1560.0, 6, false, "kg/m^3");
  EXPECT_EQ(rho.unit, "kg/m^3");
  EXPECT_EQ(rho.labels, (std::vector<std::string>{"1400", "1450", "1500", "1550"}));
  EXPECT_TRUE(unit_takes_prefix("N/m"));
  EXPECT_FALSE(unit_takes_prefix("1/s"));
  EXPECT_FALSE(unit_takes_prefix("m^2"));
}

TEST(Ticks, SaneOverRangesFrom1em3To1e6) {
  int cases = 0;
  for (double hi = 1e-3; hi <= 1e6; hi *= 1.37) {
    for (double lo_fraction : {0.0, 0.13, 0.5, 0.91, -0.3}) {
      const double lo = lo_fraction * hi;
      for (const char* unit : {"Pa", "-", "1/s"}) {
        for (int max_count : {5, 6, 8}) {
          const std::string what = std::to_string(lo) + ".." + std::to_string(hi) + " " + unit + " max " +
                                   std::to_string(max_count);
          const Ticks t = choose_ticks(lo, hi, max_count, false, unit);
          expect_sane(t, lo, hi, false, what);
          EXPECT_LE(int(t.values.size()), std::max(max_count, 8)) << what;
          if (std::string(unit) == "Pa") {
            // prefix puts the largest label in [1, 1000)
            const double biggest = std::max(std::abs(t.values.front()), std::abs(t.values.back())) / t.scale;
            EXPECT_GE(biggest, 1.0 - 1e-9) << what;
            EXPECT_LT(biggest, 1000.0) << what;
          }
          ++cases;
        }
      }
    }
  }
  EXPECT_GT(cases, 1000);
}

TEST(Ticks, LogRangesGetDecades) {
  const Ticks t = choose_ticks(1e-3, 10.0, 6, true, "1/s");
  EXPECT_EQ(t.labels, (std::vector<std::string>{"0.001", "0.01", "0.1", "1", "10"}));
  EXPECT_EQ(t.unit, "1/s");
  const Ticks odd = choose_ticks(3.7e-4, 2.9, 6, true, "1/s");
  EXPECT_EQ(odd.labels, (std::vector<std::string>{"0.001", "0.01", "0.1", "1"}));
  // ten decades: every second one
  const Ticks wide = choose_ticks(1e-5, 1e5, 6, true, "1/s");
  EXPECT_EQ(wide.labels, (std::vector<std::string>{"1e-4", "0.01", "1", "100", "10000"}));
  // under three decades: 1-2-5 inside them
  const Ticks narrow = choose_ticks(0.03, 0.6, 6, true, "1/s");
  EXPECT_EQ(narrow.labels, (std::vector<std::string>{"0.05", "0.1", "0.2", "0.5"}));
  for (double lo = 1e-3; lo < 1e6; lo *= 3.1)
    for (double decades : {0.7, 1.3, 2.5, 4.0, 6.2, 9.0}) {
      const double hi = lo * std::pow(10.0, decades);
      const Ticks r = choose_ticks(lo, hi, 6, true, "1/s");
      expect_sane(r, lo, hi, true, std::to_string(lo) + ".." + std::to_string(hi));
      if (decades >= 3) {
        for (double v : r.values) EXPECT_NEAR(std::log10(v), std::round(std::log10(v)), 1e-9) << v;
      }
    }
  EXPECT_NEAR(range_fraction(0.1, 1e-3, 10.0, true), 0.5, 1e-12);
  EXPECT_NEAR(range_fraction(2500.0, 0.0, 10000.0, false), 0.25, 1e-12);
}

TEST(Ticks, BadRangesAreErrors) {
  EXPECT_THROW(choose_ticks(1.0, 1.0, 6, false), std::invalid_argument);
  EXPECT_THROW(choose_ticks(0.0, 1.0, 6, true), std::invalid_argument);
  EXPECT_THROW(choose_ticks(0.0, NAN, 6, false), std::invalid_argument);
}
