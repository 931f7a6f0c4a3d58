// Scene files: templates, round trips, estimates, overrides, and a table of malformed scenes that
// must each be rejected with the JSON path at fault and what was expected.
#include "engine/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

namespace fs = std::filesystem;
using furrow::Scene;
using furrow::SceneError;
using json = nlohmann::json;

namespace {

const fs::path kSceneDir = fs::path(FURROW_SOURCE_DIR) / "scenes";

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

json template_json(const std::string& name) { return json::parse(read_text(kSceneDir / (name + ".json"))); }

Scene load_template(const std::string& name, const std::vector<std::string>& overrides = {}) {
  return furrow::load_scene((kSceneDir / (name + ".json")).string(), overrides);
}

std::vector<std::string> template_names() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(kSceneDir))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

// P-wave modulus written independently of the K + 4G/3 form used by the code.
double p_wave_speed(double E, double nu, double rho_g, double phi_c) {
  return std::sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / (rho_g * phi_c));
}

}  // namespace

TEST(SceneTemplates, EveryTemplateValidatesAndIsNamedAfterItsFile) {
  const auto names = template_names();
  ASSERT_EQ(names.size(), 12u);
  for (const auto& n : names) {
    SCOPED_TRACE(n);
    Scene s;
    ASSERT_NO_THROW(s = load_template(n));
    EXPECT_EQ(s.name, n);
    EXPECT_FALSE(s.description.empty());
    // a preview dx, with the way to the finer one in the description
    EXPECT_NE(s.description.find("--set domain.dx_m="), std::string::npos);
    // "runs in about a minute to a few minutes": at most ~1e10 particle-steps at ~20-40 M/s
    const double work = double(furrow::estimate_particle_count(s)) * double(furrow::estimate_step_count(s));
    EXPECT_LT(work, 1e10);
  }
}

TEST(SceneTemplates, EmbeddedCopiesMatchTheFiles) {
  const auto names = template_names();
  ASSERT_EQ(furrow::scene_templates().size(), names.size());
  for (const auto& n : names) {
    const auto* t = furrow::find_scene_template(n);
    ASSERT_NE(t, nullptr) << n;
    EXPECT_EQ(t->text, read_text(kSceneDir / (n + ".json"))) << n;
    EXPECT_EQ(t->description, template_json(n)["description"].get<std::string>());
  }
  EXPECT_EQ(furrow::find_scene_template("plate-intrusion"), furrow::find_scene_template("plate_intrusion"));
  EXPECT_EQ(furrow::find_scene_template("plate"), nullptr);
}

TEST(SceneTemplates, ResolvedJsonRoundTrips) {
  for (const auto& n : template_names()) {
    SCOPED_TRACE(n);
    const Scene s = load_template(n);
    const json j = furrow::scene_to_json(s);
    EXPECT_EQ(furrow::scene_to_json(furrow::parse_scene(j, "resolved")), j);
    // the pretty text is the same document
    const Scene again = furrow::parse_scene_text(furrow::format_scene(s), "formatted");
    EXPECT_EQ(furrow::scene_to_json(again), j);
    // resolved means complete: every key the schema allows at the top and in each section
    for (const auto& k : furrow::schema_keys(j, "")) EXPECT_TRUE(j.contains(k)) << k;
    for (const char* sec : {"/domain", "/solver", "/walls", "/effects", "/outputs"})
      for (const auto& k : furrow::schema_keys(j, sec)) EXPECT_TRUE(j[json::json_pointer(sec)].contains(k)) << sec << "/" << k;
  }
}

TEST(SceneTemplates, PaperGeometry) {
  const double tol = 1e-12;
  {  // case 2: plate bottom 5 mm above the bed surface, centred
    const Scene s = load_template("plate_intrusion");
    ASSERT_EQ(s.bodies.size(), 1u);
    const auto& b = s.bodies[0];
    EXPECT_NEAR(b.start_m.y() - 0.5 * b.shape.size_m.y() - s.beds[0].max_m.y(), 0.005, tol);
    EXPECT_NEAR(b.start_m.x(), 0.6, tol);
    EXPECT_NEAR(b.shape.size_m.x(), 0.10, tol);
    EXPECT_EQ(s.materials[0].mu, 0.40);
    EXPECT_EQ(s.solver.end_displacement_m, 0.14);
    EXPECT_EQ(furrow::estimate_particle_count(s), 28800u);  // 1.2 * 0.6 / 0.01^2 * 2^2
  }
  {  // case 2 pair: 0.02 m between inner edges (s/L 0.2, the preview's peak), symmetric about x = 0.6
    const Scene s = load_template("two_plates");
    ASSERT_EQ(s.bodies.size(), 2u);
    const auto &a = s.bodies[0], &b = s.bodies[1];
    const double gap_m = (b.start_m.x() - 0.5 * b.shape.size_m.x()) - (a.start_m.x() + 0.5 * a.shape.size_m.x());
    EXPECT_NEAR(gap_m, 0.02, tol);
    EXPECT_NEAR(gap_m / a.shape.size_m.x(), 0.2, tol);
    EXPECT_NEAR(0.5 * (a.start_m.x() + b.start_m.x()), 0.6, tol);
    EXPECT_EQ(a.start_m.y(), b.start_m.y());
  }
  {  // case 1: D = 4 mm, centre 0.03 m below the surface, moving +x
    const Scene s = load_template("cylinder_drag");
    const auto& b = s.bodies[0];
    EXPECT_NEAR(2 * b.shape.radius_m, 0.004, tol);
    EXPECT_NEAR(s.beds[0].max_m.y() - b.start_m.y(), 0.03, tol);
    EXPECT_GT(b.motion.velocity_m_s.x(), 0.0);
    EXPECT_EQ(s.materials[0].mu, 0.48);
    EXPECT_EQ(b.friction, 0.35);
  }
  {  // case 3: plate bottom 0.05 m below the surface, dense DPM
    const Scene s = load_template("plowing");
    const auto& b = s.bodies[0];
    EXPECT_NEAR(s.beds[0].max_m.y() - (b.start_m.y() - 0.5 * b.shape.size_m.y()), 0.05, tol);
    EXPECT_EQ(s.materials[0].model, furrow::MaterialModel::DPM);
    EXPECT_GT(s.beds[0].packing_fraction, s.materials[0].phi_c);
    EXPECT_TRUE(s.effects.dilatancy);
  }
  {  // case 4: loose poppy seeds, plate starting just above the surface
    const Scene s = load_template("loose_intrusion");
    const auto& b = s.bodies[0];
    const double gap = b.start_m.y() - 0.5 * b.shape.size_m.y() - s.beds[0].max_m.y();
    EXPECT_GE(gap, 0.0);
    EXPECT_LE(gap, s.domain.dx_m + tol);
    EXPECT_LT(s.beds[0].packing_fraction, s.materials[0].phi_c);
    EXPECT_EQ(s.materials[0].grain_density_kg_m3, 1100);
  }
}

TEST(SceneEstimates, TimeStepParticlesAndSteps) {
  const Scene s = load_template("plate_intrusion");
  const double c = p_wave_speed(5e6, 0.3, 2520, 0.60);
  EXPECT_NEAR(furrow::wave_speed_m_s(s.materials[0]), c, 1e-12 * c);
  const double dt = 0.4 * 0.01 / (c + 0.1);
  EXPECT_NEAR(furrow::estimate_time_step_s(s), dt, 1e-15);
  EXPECT_NEAR(furrow::estimate_end_time_s(s), 1.4, 1e-12);  // 0.14 m at 0.1 m/s, before end_time_s 1.5
  EXPECT_EQ(furrow::estimate_step_count(s), int64_t(std::ceil(1.4 / dt)));

  // dt is set by the stiffest material; a softer second material does not change it
  Scene two = s;
  furrow::Material soft = s.materials[0];
  soft.youngs_modulus_Pa = 1e5;
  two.materials.push_back(soft);
  EXPECT_EQ(furrow::estimate_time_step_s(two), furrow::estimate_time_step_s(s));
  soft.youngs_modulus_Pa = 5e7;
  two.materials.back() = soft;
  EXPECT_NEAR(furrow::estimate_time_step_s(two), 0.4 * 0.01 / (p_wave_speed(5e7, 0.3, 2520, 0.6) + 0.1), 1e-15);
}

TEST(SceneKinematics, PiecewiseLinearVelocityPath) {
  furrow::Motion m;
  m.kind = furrow::Motion::Kind::Path;
  m.path = {{0.0, {0.0, 0.0}}, {1.0, {1.0, 0.0}}, {2.0, {1.0, 0.0}}};
  // ramp: x = t^2/2 on [0, 1], then constant speed
  EXPECT_NEAR(furrow::motion_displacement_m(m, 0.5).x(), 0.125, 1e-15);
  EXPECT_NEAR(furrow::motion_displacement_m(m, 1.0).x(), 0.5, 1e-15);
  EXPECT_NEAR(furrow::motion_displacement_m(m, 3.0).x(), 2.5, 1e-15);
  EXPECT_NEAR(furrow::motion_velocity_m_s(m, 0.25).x(), 0.25, 1e-15);
  EXPECT_NEAR(furrow::time_to_displacement_s(m, 0.125, 10.0), 0.5, 1e-9);
  EXPECT_NEAR(furrow::time_to_displacement_s(m, 1.0, 10.0), 1.5, 1e-9);
  EXPECT_TRUE(std::isinf(furrow::time_to_displacement_s(m, 100.0, 10.0)));
  EXPECT_EQ(furrow::motion_max_speed_m_s(m), 1.0);
}

TEST(SceneOverrides, ValuesPathsAndNames) {
  json j = template_json("two_plates");
  furrow::apply_override(j, "domain.dx_m=0.005", "t.json");
  EXPECT_EQ(j["domain"]["dx_m"], 0.005);
  furrow::apply_override(j, "description=hello world", "t.json");  // not JSON: a string
  EXPECT_EQ(j["description"], "hello world");
  furrow::apply_override(j, "bodies.plate_right.friction=0.5", "t.json");  // element by name
  EXPECT_EQ(j["bodies"][1]["friction"], 0.5);
  furrow::apply_override(j, "bodies.0.shape.size_m=[0.05,0.02]", "t.json");
  EXPECT_EQ(j["bodies"][0]["shape"]["size_m"], json::parse("[0.05,0.02]"));
  furrow::apply_override(j, "/walls/bottom/friction=0.6", "t.json");  // JSON pointer form
  EXPECT_EQ(j["walls"]["bottom"]["friction"], 0.6);
  furrow::apply_override(j, "outputs.fields.3=\"velocity\"", "t.json");  // index == size appends
  EXPECT_EQ(j["outputs"]["fields"].size(), 4u);
  EXPECT_NO_THROW(furrow::parse_scene(j, "t.json"));

  // a valid key absent from the document is created (a minimal scene can take any --set)
  json minimal = json::parse(R"({"schema_version": 1, "domain": {"width_m": 1, "height_m": 1, "dx_m": 0.05},
    "solver": {"end_time_s": 0.1}, "materials": [{"name": "m", "model": "ndpm", "grain_density_kg_m3": 2500,
    "phi_c": 0.6, "mu_s": 0.4}], "beds": [{"material": "m", "min_m": [0, 0], "max_m": [1, 0.5]}]})");
  furrow::apply_override(minimal, "effects.gravity=false", "m.json");
  furrow::apply_override(minimal, "solver.threads=1", "m.json");
  const Scene s = furrow::parse_scene(minimal, "m.json");
  EXPECT_FALSE(s.effects.gravity);
  EXPECT_EQ(s.solver.threads, 1);
  EXPECT_EQ(s.name, "m");  // defaults to the file's stem
  EXPECT_EQ(s.beds[0].packing_fraction, 0.6);  // defaults to the material's phi_c

  auto error_of = [&](json doc, const std::string& assignment) -> SceneError {
    try {
      furrow::apply_override(doc, assignment, "o.json");
    } catch (const SceneError& e) {
      return e;
    }
    ADD_FAILURE() << "no error for " << assignment;
    return SceneError("", "", "", "");
  };
  const json base = template_json("two_plates");
  SceneError e = error_of(base, "domian.dx_m=0.01");
  EXPECT_EQ(e.path, "/domian");
  EXPECT_NE(std::string(e.what()).find("did you mean \"domain\""), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("--set domian.dx_m=0.01"), std::string::npos) << e.what();
  e = error_of(base, "solver.cfll=0.3");
  EXPECT_EQ(e.path, "/solver/cfll");
  EXPECT_NE(std::string(e.what()).find("\"cfl\""), std::string::npos) << e.what();
  e = error_of(base, "bodies.5.friction=1");
  EXPECT_EQ(e.path, "/bodies/5");
  EXPECT_NE(std::string(e.what()).find("[0, 1]"), std::string::npos) << e.what();
  e = error_of(base, "bodies.plate_lft.friction=1");
  EXPECT_NE(std::string(e.what()).find("did you mean \"plate_left\""), std::string::npos) << e.what();
  e = error_of(base, "domain.dx_m.value=1");
  EXPECT_EQ(e.path, "/domain/dx_m");
  e = error_of(base, "domain.dx_m");
  EXPECT_NE(std::string(e.what()).find("key.path=value"), std::string::npos) << e.what();
}

// ---------------------------------------------------------------------------------------------
// malformed scenes

namespace {

struct BadCase {
  std::string what;
  std::function<std::string()> text;  // the scene file's content
  std::vector<std::string> overrides;
  std::string path;  // expected JSON pointer ("" for syntax errors)
  std::string word;  // must appear in the message
};

std::string edit(const std::string& tmpl, const std::function<void(json&)>& f) {
  json j = template_json(tmpl);
  f(j);
  return j.dump(2);
}

std::function<std::string()> with(const std::string& tmpl, std::function<void(json&)> f) {
  return [tmpl, f] { return edit(tmpl, f); };
}

std::function<std::string()> raw(std::string s) {
  return [s] { return s; };
}

std::function<std::string()> plain(const std::string& tmpl) {
  return [tmpl] { return read_text(kSceneDir / (tmpl + ".json")); };
}

// the parser gives up one level past 64
std::string deep_path() {
  std::string p;
  for (int i = 0; i < 64; ++i) p += "/0";
  return p;
}

std::vector<BadCase> bad_cases() {
  const std::string P = "plate_intrusion", D = "plowing", T = "two_plates";
  return {
      {"truncated JSON", [] { return read_text(kSceneDir / "plate_intrusion.json").substr(0, 200); }, {}, "", "valid JSON"},
      {"trailing comma", raw("{\"schema_version\": 1,}"), {}, "", "valid JSON"},
      {"number overflow", raw("{\"schema_version\": 1,\n \"domain\": {\"dx_m\": 1e999}}"), {}, "", "valid JSON"},
      {"duplicate key", raw("{\"schema_version\": 1, \"beds\": [{}, {\"material\": 1, \"material\": 2}]}"), {}, "/beds/1/material", "once"},
      {"too deeply nested", raw(std::string(100, '[') + std::string(100, ']')), {}, deep_path(), "nested"},
      {"not an object", raw("[1, 2]"), {}, "", "object"},
      {"schema_version 2", with(P, [](json& j) { j["schema_version"] = 2; }), {}, "/schema_version", "schema_version"},
      {"missing dx", with(P, [](json& j) { j["domain"].erase("dx_m"); }), {}, "/domain/dx_m", "(missing)"},
      {"width as string", with(P, [](json& j) { j["domain"]["width_m"] = "1.2"; }), {}, "/domain/width_m", "number"},
      {"bodies not an array", with(P, [](json& j) { j["bodies"] = json::object(); }), {}, "/bodies", "array"},
      {"unknown top-level key", with(P, [](json& j) { j["domian"] = 1; }), {}, "/domian", "did you mean \"domain\""},
      {"unknown solver key", with(P, [](json& j) { j["solver"]["cfl_number"] = 0.3; }), {}, "/solver/cfl_number", "keys here"},
      {"unknown contact method", with(P, [](json& j) { j["solver"]["contact"] = "penalty"; }), {}, "/solver/contact", "\"particle\""},
      {"contact method not a string", plain(P), {"solver.contact=2"}, "/solver/contact", "\"node\""},
      {"mu_2 below mu_s", plain(P), {"materials.0.mu_2=0.2"}, "/materials/0/mu_2", "at least mu_s"},
      {"I0 not positive", plain(P), {"materials.0.I0=0"}, "/materials/0/I0", "(0, 10]"},
      {"grain diameter negative", plain(P), {"materials.0.grain_diameter_m=-0.001"}, "/materials/0/grain_diameter_m", "m"},
      {"rate_dependence not a boolean", plain(P), {"effects.rate_dependence=1"}, "/effects/rate_dependence", "true or false"},
      {"unknown shape key", with(P, [](json& j) { j["bodies"][0]["shape"]["sizem"] = 1; }), {}, "/bodies/0/shape/sizem", "did you mean \"size_m\""},
      {"unknown knot key", with(P, [](json& j) {
         j["bodies"][0]["motion"] = json::parse(R"({"type": "path", "knots": [{"t_s": 0, "velocity": [0, -0.1]}]})");
       }), {}, "/bodies/0/motion/knots/0/velocity", "velocity_m_s"},
      {"friction on a slip wall", with(P, [](json& j) { j["walls"]["left"]["friction"] = 0.3; }), {}, "/walls/left/friction", "no \"friction\""},
      {"negative width", with(P, [](json& j) { j["domain"]["width_m"] = -1.2; }), {}, "/domain/width_m", "> 0"},
      {"zero dx", {plain(P)}, {"domain.dx_m=0"}, "/domain/dx_m", "> 0"},
      {"NaN as a string", with(P, [](json& j) { j["domain"]["dx_m"] = "nan"; }), {}, "/domain/dx_m", "number"},
      {"inf through --set", plain(P), {"domain.height_m=inf"}, "/domain/height_m", "set by --set"},
      {"overflowing number through --set", plain(P), {"solver.cfl=1e999"}, "/solver/cfl", "number"},
      {"body overlapping the left wall", with(P, [](json& j) { j["bodies"][0]["start_m"][0] = 0.055; }), {}, "/bodies/0/start_m", "overlaps the left wall"},
      {"body outside the domain", with(P, [](json& j) { j["bodies"][0]["start_m"][1] = 0.8; }), {}, "/bodies/0/start_m", "inside the domain"},
      {"body driven into the floor", plain(P), {"solver.end_displacement_m=null", "solver.end_time_s=8"}, "/bodies/0/motion", "bottom wall"},
      {"dx larger than the plate", plain(P), {"domain.dx_m=0.03"}, "/bodies/0/shape/size_m", "one cell"},
      {"empty bed", with(P, [](json& j) { j["beds"][0]["max_m"] = j["beds"][0]["min_m"]; }), {}, "/beds/0/max_m", "empty"},
      {"bed outside the domain", with(P, [](json& j) { j["beds"][0]["max_m"][0] = 1.3; }), {}, "/beds/0/max_m", "inside the domain"},
      {"unknown material", with(P, [](json& j) { j["beds"][0]["material"] = "glass_bead"; }), {}, "/beds/0/material", "did you mean \"glass_beads\""},
      {"huge particle count", plain(P), {"domain.dx_m=0.0001"}, "/domain/dx_m", "--yes"},
      {"huge step count", plain("hydrostatic_bed"), {"solver.end_time_s=200"}, "/solver/end_time_s", "steps"},
      {"bad field name", with(P, [](json& j) { j["outputs"]["fields"][0] = "strain"; }), {}, "/outputs/fields/0", "field name"},
      {"movie not in fields", with(P, [](json& j) { j["outputs"]["movies"] = {"velocity"}; }), {}, "/outputs/movies/0", "/outputs/fields"},
      {"phi_d on NDPM", with(P, [](json& j) { j["outputs"]["fields"].push_back("phi_d"); }), {}, "/outputs/fields/4", "DPM"},
      {"fields without frames", with(P, [](json& j) { j["outputs"]["frame_interval_s"] = 0; }), {}, "/outputs/frame_interval_s", "> 0"},
      {"chi on NDPM", with(P, [](json& j) { j["materials"][0]["chi"] = 2.5; }), {}, "/materials/0/chi", "DPM-only"},
      {"mu_s on DPM", with(D, [](json& j) { j["materials"][0]["mu_s"] = 0.4; }), {}, "/materials/0/mu_s", "mu_c"},
      {"dilatancy with only NDPM", with(P, [](json& j) { j["effects"]["dilatancy"] = true; }), {}, "/effects/dilatancy", "dpm"},
      {"packing fraction 0.8", with(P, [](json& j) { j["beds"][0]["packing_fraction"] = 0.8; }), {}, "/beds/0/packing_fraction", "(0.3, 0.75)"},
      {"phi_c 0.2", with(P, [](json& j) { j["materials"][0]["phi_c"] = 0.2; }), {}, "/materials/0/phi_c", "(0.3, 0.75)"},
      {"poisson ratio 0.5", with(P, [](json& j) { j["materials"][0]["poisson_ratio"] = 0.5; }), {}, "/materials/0/poisson_ratio", "[0, 0.5)"},
      {"zero Young's modulus", with(P, [](json& j) { j["materials"][0]["youngs_modulus_Pa"] = 0; }), {}, "/materials/0/youngs_modulus_Pa", "> 0"},
      {"negative density", with(P, [](json& j) { j["materials"][0]["grain_density_kg_m3"] = -2520; }), {}, "/materials/0/grain_density_kg_m3", "kg/m^3"},
      {"cfl above 1", with(P, [](json& j) { j["solver"]["cfl"] = 1.5; }), {}, "/solver/cfl", "(0, 1]"},
      {"9 particles per cell", with(P, [](json& j) { j["solver"]["particles_per_cell_1d"] = 9; }), {}, "/solver/particles_per_cell_1d", "[1, 8]"},
      {"fractional particles per cell", with(P, [](json& j) { j["solver"]["particles_per_cell_1d"] = 2.5; }), {}, "/solver/particles_per_cell_1d", "integer"},
      {"zero end time", with(P, [](json& j) { j["solver"]["end_time_s"] = 0; }), {}, "/solver/end_time_s", "> 0"},
      {"negative body friction", with(P, [](json& j) { j["bodies"][0]["friction"] = -0.1; }), {}, "/bodies/0/friction", "[0, 5]"},
      {"negative wall friction", with(P, [](json& j) { j["walls"]["bottom"]["friction"] = -0.4; }), {}, "/walls/bottom/friction", "[0, 5]"},
      {"duplicate body names", with(T, [](json& j) { j["bodies"][1]["name"] = "plate_left"; }), {}, "/bodies/1/name", "another body"},
      {"duplicate material names", with(P, [](json& j) { j["materials"].push_back(j["materials"][0]); }), {}, "/materials/1/name", "another material"},
      {"clockwise polygon", with(P, [](json& j) {
         j["bodies"][0]["shape"] = json::parse(R"({"type": "polygon", "vertices_m": [[-0.05, 0], [0, 0.04], [0.05, 0]]})");
       }), {}, "/bodies/0/shape/vertices_m/1", "counter-clockwise"},
      {"knot times not increasing", with(P, [](json& j) {
         j["bodies"][0]["motion"] = json::parse(
             R"({"type": "path", "knots": [{"t_s": 0, "velocity_m_s": [0, -0.1]}, {"t_s": 0, "velocity_m_s": [0, 0]}]})");
       }), {}, "/bodies/0/motion/knots/1/t_s", "increase"},
      {"offset on a top-level shape", with(P, [](json& j) { j["bodies"][0]["shape"]["offset_m"] = {0, 0}; }), {}, "/bodies/0/shape/offset_m", "union parts"},
      {"mixed averaging window", with(P, [](json& j) { j["outputs"]["average_window"]["from_s"] = 0.1; }), {}, "/outputs/average_window", "either"},
      {"end displacement without a moving body", plain("hydrostatic_bed"), {"solver.end_displacement_m=0.1"}, "/solver/end_displacement_m", "no body moves"},
      {"scene name with a slash", plain(P), {"name=\"a/b\""}, "/name", "name"},
      {"negative load ramp", plain("footing"), {"bodies.footing.load_ramp_s=-0.1"}, "/bodies/0/load_ramp_s", "seconds"},
      // free degrees of freedom and what they need (the footing: y free, its mass from a density)
      {"free DOF without a mass", with("footing", [](json& j) { j["bodies"][0].erase("density_kg_m3"); }), {}, "/bodies/0/mass_kg_per_m", "a positive mass"},
      {"zero mass", with("footing", [](json& j) { j["bodies"][0].erase("density_kg_m3"), j["bodies"][0]["mass_kg_per_m"] = 0; }), {}, "/bodies/0/mass_kg_per_m", "> 0"},
      {"negative density", plain("footing"), {"bodies.footing.density_kg_m3=-7800"}, "/bodies/0/density_kg_m3", "> 0"},
      {"negative inertia", with("footing", [](json& j) { j["bodies"][0]["inertia_kg_m"] = -1e-4; }), {}, "/bodies/0/inertia_kg_m", "> 0"},
      {"mass and density both", with("footing", [](json& j) { j["bodies"][0]["mass_kg_per_m"] = 5.0; }), {}, "/bodies/0/density_kg_m3", "not both"},
      {"a DOF listed twice", with("footing", [](json& j) { j["bodies"][0]["free"] = {"y", "y"}; }), {}, "/bodies/0/free/1", "once"},
      {"unknown DOF", with("footing", [](json& j) { j["bodies"][0]["free"] = {"z"}; }), {}, "/bodies/0/free/0", "\"angle\""},
      {"mass on a prescribed body", with(P, [](json& j) { j["bodies"][0]["mass_kg_per_m"] = 5.0; }), {}, "/bodies/0/mass_kg_per_m", "prescribed"},
      {"free body with particle contact", plain("footing"), {"solver.contact=\"particle\""}, "/bodies/0/free", "\"cell_fraction\""},
      {"load ramp on a prescribed body", plain(P), {"bodies.plate.load_ramp_s=0.1"}, "/bodies/0/load_ramp_s", "prescribed"},
  };
}

}  // namespace

TEST(SceneErrors, MalformedScenesNameThePathAndTheExpectation) {
  const auto cases = bad_cases();
  ASSERT_GE(cases.size(), 25u);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    try {
      furrow::parse_scene_text(c.text(), "case.json", c.overrides);
      ADD_FAILURE() << "accepted";
    } catch (const SceneError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(e.path, c.path) << msg;
      EXPECT_EQ(e.file, "case.json");
      EXPECT_EQ(msg.rfind("case.json", 0), 0u) << msg;
      EXPECT_NE(msg.find(", expected "), std::string::npos) << msg;
      EXPECT_NE(msg.find(c.word), std::string::npos) << msg;
      if (!c.path.empty()) {
        EXPECT_NE(msg.find("case.json: " + c.path + ": got "), std::string::npos) << msg;
      }
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a SceneError: " << e.what();
    }
  }
}

TEST(SceneErrors, SyntaxErrorsGiveLineAndColumn) {
  const std::string text = "{\n  \"schema_version\": 1,\n  \"domain\": {\"width_m\": 1.2 \"height_m\": 0.7}\n}\n";
  try {
    furrow::parse_scene_text(text, "s.json");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(e.line, 3);
    // the parser stops at the string that should have been preceded by a comma
    EXPECT_EQ(text.substr(e.byte - 1, 1), "\"") << e.what();
    EXPECT_NE(std::string(e.what()).find("s.json:3:"), std::string::npos) << e.what();
  }
}

TEST(SceneErrors, OverridesAreNamedInErrors) {
  try {
    load_template("plate_intrusion", {"domain.dx_m=0.01", "bodies.plate.friction=-2"});
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path, "/bodies/0/friction");
    EXPECT_EQ(e.note, "set by --set bodies.plate.friction=-2");
  }
}

TEST(SceneErrors, LargeScenesNeedAllowLarge) {
  const auto path = (kSceneDir / "plate_intrusion.json").string();
  EXPECT_THROW(furrow::load_scene(path, {"domain.dx_m=0.0002"}), SceneError);
  furrow::ValidationOptions yes;
  yes.allow_large = true;
  const Scene s = furrow::load_scene(path, {"domain.dx_m=0.0002"}, yes);
  EXPECT_GT(double(furrow::estimate_particle_count(s)), furrow::kMaxParticles);
}

TEST(SceneErrors, MissingFile) {
  try {
    furrow::load_scene("/nonexistent/dir/s.json");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/dir/s.json: ", 0), 0u) << e.what();
  }
}

TEST(SceneReadme, DocumentsEveryKeyAndItsExampleValidates) {
  const std::string readme = read_text(kSceneDir / "README.md");
  const json none = json::object();  // no variant chosen: every variant's keys
  size_t keys = 0;
  for (const char* p : {"", "/domain", "/solver", "/materials/0", "/beds/0", "/bodies/0", "/bodies/0/shape",
                        "/bodies/0/shape/parts/0", "/bodies/0/motion", "/bodies/0/motion/knots/0", "/walls",
                        "/walls/left", "/effects", "/outputs", "/outputs/average_window"}) {
    const auto ks = furrow::schema_keys(none, p);
    EXPECT_FALSE(ks.empty()) << p;
    for (const auto& k : ks) {
      ++keys;
      EXPECT_NE(readme.find("`" + k + "`"), std::string::npos) << p << "/" << k;
    }
  }
  EXPECT_GT(keys, 60u);
  // the example at the end is a complete scene
  const auto start = readme.rfind("```json\n"), end = readme.rfind("```");
  ASSERT_NE(start, std::string::npos);
  const Scene s = furrow::parse_scene_text(readme.substr(start + 8, end - start - 8), "README.md");
  EXPECT_EQ(s.name, "rod_drop");
  EXPECT_EQ(s.bodies[0].motion.path.size(), 2u);
}

// A hand-written scene file without solver.contact gets cell_fraction, not node's force comb;
// the templates with bodies say which method they use, so the default moves none of them.
TEST(SceneDefaults, SceneFileWithoutContactResolvesToCellFraction) {
  const std::string readme = read_text(kSceneDir / "README.md");
  const auto start = readme.rfind("```json\n"), end = readme.rfind("```");
  ASSERT_NE(start, std::string::npos);
  const std::string example = readme.substr(start + 8, end - start - 8);
  ASSERT_FALSE(json::parse(example)["solver"].contains("contact"));
  const Scene s = furrow::parse_scene_text(example, "README.md");
  ASSERT_FALSE(s.bodies.empty());
  EXPECT_EQ(s.solver.contact, furrow::ContactMethod::CellFraction);
  EXPECT_EQ(furrow::scene_to_json(s)["solver"]["contact"], "cell_fraction");  // the resolved scene says so
  EXPECT_EQ(furrow::parse_scene_text(example, "README.md", {"solver.contact=node"}).solver.contact,
            furrow::ContactMethod::Node);
  for (const auto& n : template_names()) {
    const json t = template_json(n);
    if (t.contains("bodies") && !t["bodies"].empty()) {
      EXPECT_TRUE(t["solver"].contains("contact")) << n;
    }
  }
}

TEST(SceneErrors, LongListsAreAcceptedUpToTheLimit) {
  // a 1000-knot path (slow start, then steady 0.1 m/s down) and a 1000-vertex plate-like polygon
  json j = template_json("plate_intrusion");
  json knots = json::array();
  for (int k = 0; k < 1000; ++k)
    knots.push_back({{"t_s", 0.001 * k}, {"velocity_m_s", {0.0, -0.1 * std::min(1.0, k / 100.0)}}});
  j["bodies"][0]["motion"] = {{"type", "path"}, {"knots", knots}};
  json ring = json::array();
  for (int k = 0; k < 1000; ++k) {
    const double a = 2 * M_PI * k / 1000;
    ring.push_back({0.05 * std::cos(a), 0.01 * std::sin(a)});
  }
  j["bodies"][0]["shape"] = {{"type", "polygon"}, {"vertices_m", ring}};
  const Scene s = furrow::parse_scene(j, "long.json");
  // ramp to 0.1 m/s over 0.1 s covers 0.005 m, then 0.135 m more at 0.1 m/s
  EXPECT_NEAR(furrow::estimate_end_time_s(s), 0.1 + 0.135 / 0.1, 1e-6);

  knots.push_back({{"t_s", 2.0}, {"velocity_m_s", {0.0, 0.0}}});
  j["bodies"][0]["motion"]["knots"] = knots;
  try {
    furrow::parse_scene(j, "long.json");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path, "/bodies/0/motion/knots");
    EXPECT_NE(std::string(e.what()).find("at most 1000"), std::string::npos) << e.what();
  }
}
