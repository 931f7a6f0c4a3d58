#include "app/cli.hpp"

#include <sstream>

namespace furrow::cli {

Parsed parse(const Command& cmd, const std::vector<std::string>& args) {
  Parsed p;
  p.command = &cmd;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() > 1 && a[0] == '-' && !(a.size() > 1 && (isdigit(a[1]) || a[1] == '.'))) {
      std::string name = a, value;
      bool inline_value = false;
      if (auto eq = a.find('='); eq != std::string::npos && a.rfind("--", 0) == 0) {
        name = a.substr(0, eq);
        value = a.substr(eq + 1);
        inline_value = true;
      }
      const OptionSpec* spec = nullptr;
      for (const auto& o : cmd.options)
        if (o.name == name) spec = &o;
      if (!spec) throw UsageError("unknown option '" + name + "' for 'furrow " + cmd.name + "'");
      if (spec->takes_value) {
        if (!inline_value) {
          if (i + 1 >= args.size()) throw UsageError("option '" + name + "' needs a " + spec->value_name);
          value = args[++i];
        }
        if (!spec->repeatable && p.values.count(name))
          throw UsageError("option '" + name + "' given more than once");
        p.values[name].push_back(value);
      } else {
        if (inline_value) throw UsageError("option '" + name + "' takes no value");
        p.values[name];
      }
    } else {
      p.positional.push_back(a);
    }
  }
  if ((int)p.positional.size() < cmd.min_positional)
    throw UsageError("missing argument; usage: " + cmd.usage);
  if ((int)p.positional.size() > cmd.max_positional)
    throw UsageError("unexpected argument '" + p.positional[cmd.max_positional] + "'; usage: " + cmd.usage);
  return p;
}

std::string help_text(const Command& cmd) {
  std::ostringstream os;
  os << "usage: " << cmd.usage << "\n\n" << cmd.summary << "\n";
  if (!cmd.description.empty()) os << "\n" << cmd.description << "\n";
  os << "\noptions:\n";
  for (const auto& o : cmd.options) {
    std::string lhs = o.name + (o.takes_value ? " " + o.value_name : "");
    os << "  " << lhs;
    for (size_t k = lhs.size(); k < 28; ++k) os << ' ';
    os << " " << o.help << (o.repeatable ? " (repeatable)" : "") << "\n";
  }
  os << "  --help                       show this help\n";
  return os.str();
}

}  // namespace furrow::cli
