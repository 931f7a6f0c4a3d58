// outputs.layout: the paper's movie layout a scene names. Every paper template names one that
// validates; a bad one is an error at its JSON path, but overrides that leave it nothing to draw
// (no frames, the body held) do not invalidate the scene; it round-trips and leaves the scene's
// hash alone (a layout is drawn from the stored frames, it changes no result).
#include <gtest/gtest.h>

#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"

using namespace furrow;

namespace {
const std::string kSrc = "<template loose_intrusion>";
std::string text() { return find_scene_template("loose_intrusion")->text; }

void rejects(const std::vector<std::string>& overrides, const std::string& path, const std::string& word) {
  SCOPED_TRACE(overrides.back());
  try {
    parse_scene_text(text(), kSrc, overrides);
    ADD_FAILURE() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path, path) << e.what();
    EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(LayoutScene, PaperTemplatesNameTheirMovieLayout) {
  for (const auto& [name, layout] : {std::pair{"cylinder_drag", "movie_S1"}, {"plate_intrusion", "movie_S2"},
                                     {"two_plates", "movie_S2"}, {"plowing", "movie_S3"},
                                     {"loose_intrusion", "movie_S4"}}) {
    const Scene s = parse_scene_text(find_scene_template(name)->text, name);
    EXPECT_EQ(s.outputs.layout.name, layout) << name;
    EXPECT_FALSE(s.outputs.layout.fields.empty()) << name;
  }
  const MovieLayout l = parse_scene_text(text(), kSrc).outputs.layout;
  EXPECT_EQ(l.fields, (std::vector<std::string>{"velocity_y", "strain_rate"}));
  EXPECT_EQ(l.frame_of, "plate");
  EXPECT_EQ(l.zoom, 2.0);
  EXPECT_TRUE(l.normalize);
}

TEST(LayoutScene, BadLayoutsAreErrorsAtTheirPath) {
  rejects({"outputs.layout.fields=[\"velocity_z\"]"}, "/outputs/layout/fields/0", "velocity_x");
  rejects({"outputs.layout.fields=[\"strain_rate\",\"strain_rate\"]"}, "/outputs/layout/fields/1", "once");
  // fields the run does not store leave the layout's movie out; the scene stays valid
  EXPECT_NO_THROW(parse_scene_text(text(), kSrc, {"outputs.fields=[]", "outputs.movies=[]"}));
  rejects({"outputs.layout.fields=[]"}, "/outputs/layout/fields", "");
  rejects({"outputs.layout.frame_of=\"wheel\""}, "/outputs/layout/frame_of", "plate");
  rejects({"outputs.layout.zoom=0.5"}, "/outputs/layout/zoom", "");
  rejects({"outputs.layout.frame_of=null", "outputs.layout.zoom=3"}, "/outputs/layout/zoom", "frame_of");
  rejects({"outputs.layout.name=\"../x\""}, "/outputs/layout/name", "a name");
  rejects({"outputs.layout.speed=1"}, "/outputs/layout/speed", "");
  rejects({"outputs.layout.normalize=1"}, "/outputs/layout/normalize", "true or false");
  // the plate held still: nothing to normalize by, yet the scene stays valid (drawn in units)
  EXPECT_NO_THROW(parse_scene_text(text(), kSrc,
                                   {"bodies.plate.motion.velocity_m_s=[0,0]", "solver.end_displacement_m=null",
                                    "outputs.average_window={\"from_s\":0}"}));
}

TEST(LayoutScene, RoundTripsAndChangesNoHash) {
  const Scene s = parse_scene_text(text(), kSrc);
  const Scene again = parse_scene_text(format_scene(s), "again");
  EXPECT_EQ(again.outputs.layout.name, s.outputs.layout.name);
  EXPECT_EQ(again.outputs.layout.fields, s.outputs.layout.fields);
  EXPECT_EQ(again.outputs.layout.frame_of, s.outputs.layout.frame_of);
  EXPECT_EQ(again.outputs.layout.zoom, s.outputs.layout.zoom);
  EXPECT_EQ(again.outputs.layout.normalize, s.outputs.layout.normalize);
  const Scene other = parse_scene_text(text(), kSrc, {"outputs.layout.zoom=4"});
  EXPECT_EQ(scene_hash(other), scene_hash(s));
  EXPECT_FALSE(result_defining_json(s)["outputs"].contains("layout"));
}
