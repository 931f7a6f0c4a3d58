// Internals shared by engine/scene/scene_*.cpp (not part of the engine's API): the schema's key lists,
// the error helper and the text helpers for messages.
#pragma once
#include <nlohmann/json.hpp>

#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "engine/scene/scene_io.hpp"

namespace furrow::scene_detail {

using json = nlohmann::json;
using KeyList = std::vector<std::string>;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxDepth = 64;             // JSON nesting
constexpr size_t kMaxListItems = 1000;  // knots, vertices, bodies...: keeps validation fast (O(n^2) checks)

// ---- messages ----
std::string short_dump(const json& v);  // always printable, at most 80 characters
std::string num_str(double x);          // shortest text that reads back as x
std::string vec_str(const Vec2& v);
std::string approx(double x);  // derived values: 4 significant digits
std::string approx(const Vec2& v);
std::string escape_pointer_token(const std::string& key);
std::string join(const KeyList& keys, const std::string& sep = ", ");
// " (did you mean "x"?)" when a candidate is a plausible typo of `got`, else "".
std::string suggestion(const std::string& got, const KeyList& candidates);
std::string one_of(const KeyList& names);  // "\"a\"" or "one of \"a\", \"b\""

// ---- schema: the keys of every object, in README order ----
extern const KeyList kRootKeys, kDomainKeys, kSolverKeys, kMaterialNdpmKeys, kMaterialDpmKeys, kBedKeys, kBodyKeys, kBoxKeys, kCircleKeys, kPolygonKeys, kUnionKeys, kConstantMotionKeys, kPathMotionKeys, kKnotKeys, kWallsKeys, kFrontBackKeys, kFrictionWallKeys, kPlainWallKeys, kEffectsKeys, kOutputsKeys, kLayoutKeys, kWindowKeys, kModels, kShapeTypes, kMotionTypes, kWallTypes, kShapeFunctions, kContactMethods;
// Keys of a variant object (shape/motion/wall "type", material "model") for the variant `obj`
// names; every variant's keys when it names none.
KeyList shape_keys(const json* obj, bool is_part);
KeyList material_keys(const json* obj);
KeyList motion_keys(const json* obj);
KeyList wall_keys(const json* obj);
std::string variant_tag(const json* obj, const char* key);

// ---- errors ----
struct Ctx {
  std::string source;
  ValidationOptions options;
};
[[noreturn]] void fail(const Ctx& c, const std::string& path, const std::string& value, const std::string& expected);
[[noreturn]] void fail(const Ctx& c, const std::string& path, const char* value, const std::string& expected);
[[noreturn]] void fail(const Ctx& c, const std::string& path, const json& value, const std::string& expected);

// ---- checks across sections (scene_check.cpp) ----
std::string idx_path(const char* array, size_t i, const std::string& key = "");  // "/array/i/key"
void check_scene(const Ctx& c, const Scene& s);  // geometry and cost, after every section is read

// ---- paths ----
// "a.b.0" or a JSON pointer "/a/b/0" into its segments.
std::vector<std::string> split_path(const std::string& key_path);
bool all_digits(const std::string& s);

}  // namespace furrow::scene_detail
