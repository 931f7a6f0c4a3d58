// Scene text and files: JSON parsing with duplicate-key and depth checks, syntax errors with line
// and column, `--set` overrides, and load_scene.
#include <algorithm>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include "engine/scene/scene_detail.hpp"

namespace furrow {

using namespace scene_detail;

namespace {

// Tracks where the parser is so that duplicate keys and deep nesting can be reported by path.
struct ParseTracker {
  struct Frame {
    bool is_array = false;
    long index = -1;
    std::string key;
    std::set<std::string> keys;
  };
  const Ctx* ctx = nullptr;
  std::vector<Frame> stack;

  std::string path() const {
    std::string p;
    for (size_t i = 0; i + 1 < stack.size(); ++i)
      p += "/" + (stack[i].is_array ? std::to_string(stack[i].index) : escape_pointer_token(stack[i].key));
    return p;
  }
  void element() {
    if (!stack.empty() && stack.back().is_array) stack.back().index++;
  }
  void push(bool is_array) {
    element();
    stack.push_back(Frame{is_array, -1, "", {}});
    if (stack.size() > size_t(kMaxDepth))
      fail(*ctx, path(), "nesting " + std::to_string(stack.size()) + " deep", "at most " + std::to_string(kMaxDepth) + " nested levels");
  }
  bool operator()(int, json::parse_event_t ev, json& parsed) {
    switch (ev) {
      case json::parse_event_t::object_start: push(false); break;
      case json::parse_event_t::array_start: push(true); break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!stack.empty()) stack.pop_back();
        break;
      case json::parse_event_t::key: {
        Frame& f = stack.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second) {
          stack.push_back(Frame{});  // so path() includes the key
          const std::string p = path();
          stack.pop_back();
          fail(*ctx, p, short_dump(parsed) + " a second time", "each key once per object");
        }
        break;
      }
      case json::parse_event_t::value: element(); break;
    }
    return true;
  }
};

// Turns a nlohmann parse failure into a SceneError with line, column and a snippet.
[[noreturn]] void syntax_error(const Ctx& c, const std::string& text, size_t byte, const std::string& what) {
  byte = std::min(byte, text.size());
  int line = 1, column = 1;
  for (size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n') ++line, column = 1;
    else ++column;
  }
  std::string detail = what;
  if (auto p = detail.find(": "); p != std::string::npos && detail.find("parse error") != std::string::npos)
    detail = detail.substr(p + 2);
  if (auto p = detail.find("] "); detail.rfind("[json.exception", 0) == 0 && p != std::string::npos)
    detail = detail.substr(p + 2);
  const size_t from = byte > 24 ? byte - 24 : 0;
  std::string snippet = text.substr(from, byte - from);
  for (char& ch : snippet)
    if (ch == '\n' || ch == '\r' || ch == '\t') ch = ' ';
  const bool at_end = byte >= text.size() && (detail.find("end of input") != std::string::npos ||
                                               detail.find("missing closing") != std::string::npos);
  snippet = (at_end ? "end of input after " : "") +
            short_dump(json(snippet));
  throw SceneError(c.source, "", snippet, "valid JSON (" + detail + ")", "", line, column, byte);
}

json parse_text(const Ctx& c, const std::string& text) {
  ParseTracker tracker;
  tracker.ctx = &c;
  try {
    return json::parse(text, std::ref(tracker));
  } catch (const json::parse_error& e) {
    syntax_error(c, text, e.byte, e.what());
  } catch (const json::exception& e) {
    // number overflow (e.g. 1e999) carries no position: find the literal
    std::string what = e.what();
    size_t byte = text.size();
    if (auto q = what.find('\''); q != std::string::npos) {
      const std::string lit = what.substr(q + 1, what.rfind('\'') - q - 1);
      if (auto at = text.find(lit); !lit.empty() && at != std::string::npos) byte = at + lit.size();
    }
    syntax_error(c, text, byte, what);
  }
}

// Applies one override; returns the JSON pointer it wrote.
std::string apply_override_at(json& root, const std::string& assignment, const std::string& source) {
  const Ctx c{source, {}};
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    fail(c, "", json(assignment), "an override key.path=value (e.g. domain.dx_m=0.005)");
  const std::string key_path = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  json value;
  try {
    value = json::parse(text);
  } catch (const json::exception&) {
    value = text;  // not JSON: a plain string
  }
  const std::vector<std::string> segs = split_path(key_path);
  const std::string note = "in --set " + assignment;
  json* node = &root;
  std::string pointer;
  for (size_t i = 0; i < segs.size(); ++i) {
    const std::string& seg = segs[i];
    const bool last = i + 1 == segs.size();
    if (seg.empty()) throw SceneError(source, pointer, "an empty key", "a key.path like domain.dx_m", note);
    if (node->is_array()) {
      size_t idx = node->size() + 1;
      if (all_digits(seg)) {
        idx = std::stoul(seg);
      } else {
        for (size_t k = 0; k < node->size(); ++k)
          if ((*node)[k].is_object() && (*node)[k].value("name", json()).is_string() && (*node)[k]["name"] == seg)
            idx = k;
      }
      const bool append = last && idx == node->size();
      if (idx >= node->size() && !append) {
        KeyList names;
        for (const auto& e : *node)
          if (e.is_object() && e.contains("name") && e["name"].is_string()) names.push_back(e["name"].get<std::string>());
        std::string expected = node->empty() ? "index 0 (appending to the empty array)"
                                             : "an index in [0, " + std::to_string(node->size() - 1) + "]" +
                                                   (last ? " or " + std::to_string(node->size()) + " to append" : "");
        if (!names.empty()) expected += " or an element name: " + one_of(names) + suggestion(seg, names);
        throw SceneError(source, pointer + "/" + escape_pointer_token(seg), short_dump(json(seg)), expected, note);
      }
      pointer += "/" + std::to_string(idx);
      if (append) node->push_back(json());
      node = &(*node)[idx];
    } else if (node->is_object()) {
      pointer += "/" + escape_pointer_token(seg);
      if (!node->contains(seg)) {
        const std::string parent = pointer.substr(0, pointer.rfind('/'));
        // keys of any variant are let through: the reader explains e.g. "chi" on an NDPM material
        const KeyList allowed = schema_keys(root, parent), any_variant = schema_keys(json::object(), parent);
        if (std::find(allowed.begin(), allowed.end(), seg) == allowed.end() &&
            std::find(any_variant.begin(), any_variant.end(), seg) == any_variant.end()) {
          KeyList here = allowed;
          for (auto it = node->begin(); it != node->end(); ++it)
            if (std::find(here.begin(), here.end(), it.key()) == here.end()) here.push_back(it.key());
          throw SceneError(source, pointer, short_dump(json(seg)),
                           "a key of " + (parent.empty() ? std::string("/") : parent) + suggestion(seg, here) +
                               (here.empty() ? std::string("") : "; keys here: " + join(here)),
                           note);
        }
        (*node)[seg] = last ? json() : json::object();
      }
      node = &(*node)[seg];
    } else {
      throw SceneError(source, pointer, short_dump(*node),
                       "an object or array to hold \"" + seg + "\" (the path goes through a " +
                           std::string(node->type_name()) + ")",
                       note);
    }
  }
  *node = value;
  return pointer;
}

}  // namespace

void apply_override(json& j, const std::string& assignment, const std::string& source) {
  apply_override_at(j, assignment, source);
}

Scene parse_scene_text(const std::string& text, const std::string& source,
                       const std::vector<std::string>& overrides, const ValidationOptions& options) {
  const Ctx c{source, options};
  json j = parse_text(c, text);
  std::vector<std::pair<std::string, std::string>> written;  // pointer, assignment
  for (const auto& o : overrides) written.emplace_back(apply_override_at(j, o, source), o);
  try {
    return parse_scene(j, source, options);
  } catch (const SceneError& e) {
    // name the override responsible for the value at fault (the last one that wrote there)
    for (auto it = written.rbegin(); it != written.rend(); ++it) {
      const std::string& p = it->first;
      const bool inside = e.path == p || (e.path.size() > p.size() && e.path.compare(0, p.size(), p) == 0 &&
                                          e.path[p.size()] == '/');
      if (inside) throw SceneError(e.file, e.path, e.value, e.expected, "set by --set " + it->second);
    }
    throw;
  }
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides,
                 const ValidationOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, "", "a file that cannot be opened", "a readable scene file (JSON)");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw SceneError(path, "", "a read error", "a readable scene file (JSON)");
  return parse_scene_text(ss.str(), path, overrides, options);
}

}  // namespace furrow
