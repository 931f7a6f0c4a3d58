#include "render/script.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace furrow::render {

std::vector<std::string> script_words(const std::string& line) {
  std::istringstream in(line.substr(0, line.find('#')));
  std::vector<std::string> w;
  for (std::string s; in >> s;) w.push_back(s);
  return w;
}

bool script_number(const std::string& s, double* v) {
  char* end = nullptr;
  *v = std::strtod(s.c_str(), &end);
  return !s.empty() && *end == '\0' && std::isfinite(*v);
}

bool script_numbers(const std::vector<std::string>& w, size_t count, size_t optional, std::vector<double>* out,
                    const std::string& expected, std::string* error) {
  out->clear();
  const size_t given = w.size() - 1;
  bool ok = given >= count && given <= count + optional;
  for (size_t k = 1; ok && k < w.size(); ++k) {
    double v = 0;
    ok = script_number(w[k], &v);
    out->push_back(v);
  }
  if (!ok) *error = "expected '" + expected + "'";
  return ok;
}

void parse_script_lines(const std::string& path, const std::function<std::string(int, const std::string&)>& parse) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the script");
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::string error = parse(n, line);
    if (!error.empty()) throw std::runtime_error(path + ":" + std::to_string(n) + ": " + error + ", got '" + line + "'");
  }
}

}  // namespace furrow::render
