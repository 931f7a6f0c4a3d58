#include "app/progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace furrow::cli {

std::string format_duration(double s) {
  if (s < 0 || !std::isfinite(s)) return "--:--";
  char buf[32];
  const long t = long(std::lround(s));
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%02ld:%02ld", t / 60, t % 60);
  return buf;
}

ProgressPrinter::ProgressPrinter(std::string label, bool quiet)
    : label_(std::move(label)), tty_(isatty(STDERR_FILENO)), quiet_(quiet) {}

void ProgressPrinter::operator()(const RunProgress& p) {
  if (quiet_) return;
  const double rate = p.particle_steps_per_s / 1e6;
  if (tty_) {
    constexpr int width = 30;
    const int filled = int(p.fraction * width);
    std::string bar(filled, '#');
    bar.resize(width, '.');
    std::fprintf(stderr, "\r%s [%s] %5.1f%%  t=%.4f s  step %lld  %.1f Mps/s  elapsed %s  ETA %s ",
                 label_.c_str(), bar.c_str(), 100.0 * p.fraction, p.time_s, (long long)p.steps, rate,
                 format_duration(p.wall_s).c_str(), format_duration(p.eta_s).c_str());
    std::fflush(stderr);
    drawn_ = true;
  } else if (p.wall_s - last_plain_wall_s_ >= 10.0 || p.fraction >= 1.0) {
    // logs get a line every ten seconds, not a carriage-return animation
    std::fprintf(stderr, "%s: %5.1f%%  t=%.4f s  step %lld  %.1f M particle-steps/s  elapsed %s  ETA %s\n",
                 label_.c_str(), 100.0 * p.fraction, p.time_s, (long long)p.steps, rate,
                 format_duration(p.wall_s).c_str(), format_duration(p.eta_s).c_str());
    last_plain_wall_s_ = p.wall_s;
  }
}

void ProgressPrinter::finish() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace furrow::cli
