// Minimal argument parsing shared by every furrow subcommand: each command declares the options
// it accepts, so an unknown option is an error (exit 2) rather than silently ignored.
#pragma once
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace furrow::cli {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct OptionSpec {
  std::string name;        // "--out"
  bool takes_value = false;
  bool repeatable = false;  // e.g. --set a=1 --set b=2
  std::string help;         // one line for --help
  std::string value_name = "VALUE";
};

struct Command {
  std::string name;
  std::string summary;          // one line for `furrow --help`
  std::string usage;            // "furrow run SCENE.json [options]"
  std::string description;      // paragraph for `furrow CMD --help`
  std::vector<OptionSpec> options;
  int min_positional = 0, max_positional = 0;
  int (*main)(const struct Parsed&) = nullptr;
};

struct Parsed {
  const Command* command = nullptr;
  std::vector<std::string> positional;
  std::map<std::string, std::vector<std::string>> values;  // option -> values given
  bool has(const std::string& opt) const { return values.count(opt) > 0; }
  std::string get(const std::string& opt, const std::string& fallback = "") const {
    auto it = values.find(opt);
    return it == values.end() || it->second.empty() ? fallback : it->second.back();
  }
  const std::vector<std::string>& all(const std::string& opt) const {
    static const std::vector<std::string> none;
    auto it = values.find(opt);
    return it == values.end() ? none : it->second;
  }
};

// Throws UsageError naming the offending argument.
Parsed parse(const Command& cmd, const std::vector<std::string>& args);
std::string help_text(const Command& cmd);

// All subcommands, in the order `furrow --help` lists them.
const std::vector<Command>& commands();

}  // namespace furrow::cli
