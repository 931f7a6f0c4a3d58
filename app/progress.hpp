// Progress reporting for long runs: a bar with ETA on a terminal, plain lines otherwise.
#pragma once
#include <string>

#include "engine/run.hpp"

namespace furrow::cli {

class ProgressPrinter {
 public:
  explicit ProgressPrinter(std::string label, bool quiet = false);
  void operator()(const RunProgress& p);
  void finish();

 private:
  std::string label_;
  bool tty_ = false, quiet_ = false, drawn_ = false;
  double last_plain_wall_s_ = -1e9;
};

std::string format_duration(double seconds);

}  // namespace furrow::cli
