// A simulation's whole state to a stream and back (checkpoints; the run's side is in run.cpp).
#include <cstddef>
#include <cstring>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "engine/simulation.hpp"

namespace furrow {

namespace {

constexpr char kCheckpointMagic[8] = {'F', 'U', 'R', 'R', 'O', 'W', 'C', 'K'};
// 2: node-indexed state (cell-fraction contact marks, particle contacts' stencil base) in the
// column-major node order; version 1 (row-major) is still read and renumbered.
// 3: P2G's strip ranges (the points' home strips). Versions 1 and 2 are read and the points sorted
// into strips again before the next step.
// 4: bodies carry an angle, angular velocity and torque.
// 5: where each strip's rows start and the points' y drift since (strip_rows_of_bases); a version 3 or
// 4 file walks whole strips until the next reorder, as those builds did.
constexpr uint32_t kCheckpointVersion = 5;

template <class T> void put(std::ostream& out, const T& v) {
  static_assert(std::is_trivially_destructible_v<T> && !std::is_pointer_v<T>);  // plain values (Eigen's fixed-size too)
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T> void put_vector(std::ostream& out, const std::vector<T>& v) {
  static_assert(std::is_trivially_destructible_v<T> && !std::is_pointer_v<T>);  // plain values (Eigen's fixed-size too)
  put(out, uint64_t(v.size()));
  out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
}

// Reads what put/put_vector wrote; every failure names the file and the item.
struct Reader {
  std::istream& in;
  const std::string& what;
  [[noreturn]] void fail(const std::string& item, const std::string& why) const {
    throw std::runtime_error(what + ": " + item + ": " + why);
  }
  template <class T> T get(const std::string& item) {
    T v;
    if (!in.read(reinterpret_cast<char*>(&v), sizeof v)) fail(item, "file ends early");
    return v;
  }
  // `expected`: the element count this simulation has (SIZE_MAX: any)
  template <class T> void get_vector(std::vector<T>& v, const std::string& item, size_t expected = SIZE_MAX) {
    const uint64_t n = get<uint64_t>(item);
    if (expected != SIZE_MAX && n != expected)
      fail(item, std::to_string(n) + " values where this scene has " + std::to_string(expected));
    if (n > (uint64_t(1) << 40)) fail(item, "implausible length " + std::to_string(n));
    v.resize(size_t(n));
    if (!in.read(reinterpret_cast<char*>(v.data()), std::streamsize(n * sizeof(T)))) fail(item, "file ends early");
  }
};

}  // namespace

struct BodyStateV3 {  // a body's record before bodies could turn (checkpoint versions 1 to 3)
  Vec2 position_m, velocity_m_s, force_N_per_m, lo_m, hi_m;
};

void Simulation::save_state(std::ostream& out, uint32_t version) const {
  if (version == 0) version = kCheckpointVersion;
  if (version < 2 || version > kCheckpointVersion)
    throw std::invalid_argument("save_state: writes versions 2 to " + std::to_string(kCheckpointVersion));
  out.write(kCheckpointMagic, sizeof kCheckpointMagic);
  put(out, version);
  put(out, uint64_t(p_.size()));
  p_.for_each_array([&](const char* name, const auto& a) {
    put(out, uint32_t(sizeof(a[0])));
    put(out, uint32_t(std::strlen(name)));
    out.write(name, std::streamsize(std::strlen(name)));
    put_vector(out, a);
  });
  put(out, t_s_), put(out, dt_s_), put(out, steps_), put(out, stats_), put(out, phase_s_), put(out, wall_forces_);
  if (version >= 4) {
    put_vector(out, bodies_);
  } else {
    std::vector<BodyStateV3> old;
    for (const BodyState& b : bodies_) old.push_back({b.position_m, b.velocity_m_s, b.force_N_per_m, b.lo_m, b.hi_m});
    put_vector(out, old);
  }
  put(out, uint64_t(touched_.size()));
  for (const auto& t : touched_) put_vector(out, t);
  put_vector(out, contacts_);
  if (version >= 3) {
    put_vector(out, strip_start_);
    put(out, reorders_);
  }
  if (version >= 5) {
    put_vector(out, strip_row_start_);
    put(out, int32_t(strip_rows_)), put(out, drift_y_m_);
  }
}

void Simulation::load_state(std::istream& in, const std::string& what) {
  Reader r{in, what};
  char magic[sizeof kCheckpointMagic];
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kCheckpointMagic, sizeof magic) != 0)
    r.fail("header", "not a Furrow checkpoint");
  const auto version = r.get<uint32_t>("version");
  if (version < 1 || version > kCheckpointVersion)
    r.fail("version", std::to_string(version) + ", this build reads 1 to " + std::to_string(kCheckpointVersion));
  const uint64_t n = r.get<uint64_t>("particle count");
  if (n != p_.size())
    r.fail("particle count", std::to_string(n) + " points where this scene seeds " + std::to_string(p_.size()));
  p_.for_each_array([&](const char* name, auto& a) {
    const auto bytes = r.get<uint32_t>(std::string(name) + " element size");
    if (bytes != sizeof(a[0]))
      r.fail(name, std::to_string(bytes) + "-byte values where this build stores " + std::to_string(sizeof(a[0])) +
                       " (written by a build with the other FURROW_FLOAT_STATE)");
    std::string stored(r.get<uint32_t>(std::string(name) + " name length"), '\0');
    if (!in.read(stored.data(), std::streamsize(stored.size())) || stored != name)
      r.fail(name, "found array '" + stored + "' in its place");
    // an array this run does not keep (no output needs it) must be absent in the file too
    r.get_vector(a, name, a.empty() ? 0 : p_.size());
  });
  t_s_ = r.get<double>("time"), dt_s_ = r.get<double>("dt"), steps_ = r.get<int64_t>("steps");
  stats_ = r.get<StepStats>("step statistics"), phase_s_ = r.get<PhaseSeconds>("phase seconds");
  wall_forces_ = r.get<std::array<Vec2, 4>>("wall forces");
  if (version >= 4) {
    r.get_vector(bodies_, "bodies", bodies_.size());
  } else {
    std::vector<BodyStateV3> old;
    r.get_vector(old, "bodies", bodies_.size());
    for (size_t b = 0; b < old.size(); ++b) {
      bodies_[b].position_m = old[b].position_m, bodies_[b].velocity_m_s = old[b].velocity_m_s;
      bodies_[b].force_N_per_m = old[b].force_N_per_m, bodies_[b].lo_m = old[b].lo_m, bodies_[b].hi_m = old[b].hi_m;
    }
  }
  const auto marks = r.get<uint64_t>("contact marks");
  if (marks > bodies_.size()) r.fail("contact marks", std::to_string(marks) + " bodies' marks");
  touched_.resize(size_t(marks));
  for (auto& t : touched_) r.get_vector(t, "contact marks", g_.node.size());
  r.get_vector(contacts_, "contact points");
  for (const auto& c : contacts_)
    if (c.particle >= p_.size() || c.body >= bodies_.size()) r.fail("contact points", "a point out of range");
  if (version == 1) {
    // written with row-major nodes: the node k = j NX + i is now i NY + j
    const size_t NX = size_t(g_.NX), NY = size_t(g_.NY);
    auto column_major = [&](size_t k) { return (k % NX) * NY + k / NX; };
    for (auto& t : touched_) {
      std::vector<uint8_t> by_row = t;
      for (size_t k = 0; k < by_row.size(); ++k) t[column_major(k)] = by_row[k];
    }
    for (auto& c : contacts_) c.base = column_major(c.base);
  }
  if (version >= 3) {
    r.get_vector(strip_start_, "strip ranges", strip_start_.size());
    for (size_t s = 0; s + 1 < strip_start_.size(); ++s)
      if (strip_start_[s] > strip_start_[s + 1]) r.fail("strip ranges", "not in order");
    if (strip_start_.front() != 0 || strip_start_.back() != p_.size()) r.fail("strip ranges", "do not cover the points");
    set_home_strips();
    reorders_ = r.get<Reorders>("reorder counts");
  } else {
    homes_stale_ = true;
  }
  strip_row_start_.clear(), strip_rows_ = 0, drift_y_m_ = 0.0;
  if (version >= 5) {
    r.get_vector(strip_row_start_, "strip rows");
    strip_rows_ = r.get<int32_t>("strip row count");
    drift_y_m_ = r.get<double>("drift since the reorder");
    const size_t strips = strip_start_.size() - 1;
    if (strip_rows_ <= 0 || strip_row_start_.size() != strips * size_t(strip_rows_) + 1)
      r.fail("strip rows", std::to_string(strip_row_start_.size()) + " row starts for " + std::to_string(strips) + " strips");
    for (size_t k = 0; k + 1 < strip_row_start_.size(); ++k)
      if (strip_row_start_[k] > strip_row_start_[k + 1]) r.fail("strip rows", "not in order");
    for (size_t s = 0; s <= strips; ++s)
      if (strip_row_start_[s * size_t(strip_rows_)] != strip_start_[s]) r.fail("strip rows", "do not match the strip ranges");
    if (!(drift_y_m_ >= 0.0)) r.fail("drift since the reorder", "negative or not a number");
  }
  if (in.peek() != std::char_traits<char>::eof()) r.fail("end", "data after the last item");
}

}  // namespace furrow
