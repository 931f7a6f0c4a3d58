// Line scripts shared by `furrow inspect` and `furrow edit`: reading a file of one action per
// line ('#' comments), and replaying the parsed steps headless as one JSON line each.
#pragma once
#include <nlohmann/json.hpp>

#include <exception>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace furrow::render {

// The words of a line, without its '#' comment.
std::vector<std::string> script_words(const std::string& line);
// A finite number written as the whole of `s`.
bool script_number(const std::string& s, double* v);
// Reads `count` (+ up to `optional`) numbers from w[1..]; false, with *error "expected 'EXPECTED'",
// when they are not that.
bool script_numbers(const std::vector<std::string>& w, size_t count, size_t optional, std::vector<double>* out,
                    const std::string& expected, std::string* error);

// Calls `parse(line_number, line)` for every line of the file; `parse` returns an error text (empty
// when the line is fine). Throws std::runtime_error "FILE:LINE: ERROR, got 'LINE'" for the first
// bad line, or naming a file it cannot read.
void parse_script_lines(const std::string& path, const std::function<std::string(int, const std::string&)>& parse);

// Replays steps (anything with an int `line`) headless: `apply` gives each step's result, printed
// on `out` as one JSON line with "line" added. A result with "ok": false (an action refused, e.g.
// an invalid edit) is also reported on `err` and the replay goes on; an exception stops it.
// Either is reported as "COMMAND: SCRIPT:LINE: message"; returns 1 after any, else 0.
template <class Step, class Apply>
int replay_script(const std::vector<Step>& steps, const std::string& script, const std::string& command,
                  Apply&& apply, std::ostream& out, std::ostream& err) {
  int status = 0;
  for (const auto& step : steps) {
    nlohmann::json r;
    try {
      r = apply(step);
    } catch (const std::exception& e) {
      err << command << ": " << script << ":" << step.line << ": " << e.what() << "\n";
      return 1;
    }
    r["line"] = step.line;
    out << r.dump() << "\n" << std::flush;
    if (r.value("ok", true) == false) {
      err << command << ": " << script << ":" << step.line << ": " << r.value("error", std::string("refused")) << "\n";
      status = 1;
    }
  }
  return status;
}

}  // namespace furrow::render
