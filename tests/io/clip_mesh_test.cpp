// The shipped snap clip (scenes/clip.obj): written again by tools/make-clip-obj byte for byte,
// and its elements as its construction makes them.
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>

#include <tubeplan/io/mesh_file.hpp>

#include "../scratch.hpp"

namespace {

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

}  // namespace

TEST_CASE("tools/make-clip-obj writes scenes/clip.obj again", "[mesh]") {
  const std::string source = TUBEPLAN_SOURCE_DIR;
  const std::string out = (tubeplan::testing::ScratchDir("clip") / "clip.obj").string();
  REQUIRE(std::system((source + "/tools/make-clip-obj " + out).c_str()) == 0);
  const std::string shipped = Slurp(source + "/scenes/clip.obj");
  REQUIRE_FALSE(shipped.empty());
  CHECK(Slurp(out) == shipped);
}

TEST_CASE("The clip's faces, edges and vertices are those of its construction", "[mesh]") {
  const auto r =
      tubeplan::io::LoadMeshFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/clip.obj", 0.001);
  INFO(r.diagnostics.FormatAll());
  REQUIRE(r.elements);
  CHECK(r.diagnostics.all().empty());
  const auto& e = *r.elements;
  // A 12-sided profile extruded: 12 sides and 2 ends, plus the post's side and end. Only the
  // post's side is curved.
  REQUIRE(e.faces.size() == 16);
  std::set<std::string> curved;
  for (const auto& f : e.faces)
    if (!f.planar) curved.insert(f.name);
  CHECK(curved == std::set<std::string>{"post"});
  // Every profile corner is an edge along the channel (12), every profile side meets each end
  // (2 x 12), and the post meets the base and its own end in a loop each: 38.
  REQUIRE(e.edges.size() == 38);
  // Concave: the four inner corners of the U (under each lip, and where the walls meet the
  // floor) and the post's foot; the other 33 are convex.
  std::set<std::string> concave;
  for (const auto& edge : e.edges)
    if (!edge.convex) concave.insert(edge.name);
  CHECK(concave == std::set<std::string>{"right_lip_right_inner", "right_inner_floor",
                                         "floor_left_inner", "left_inner_left_lip", "bottom_post"});
  // Three faces meet at each profile corner on each end (2 x 12); none on the round post.
  REQUIRE(e.vertices.size() == 24);
  for (const auto& v : e.vertices) {
    REQUIRE(v.faces.size() == 3);
    CHECK((v.position_P_m.y() == 0.0 || v.position_P_m.y() == 0.020));
  }
  // The post's loops have a segment a side.
  for (const auto& edge : e.edges)
    if (edge.name == "bottom_post" || edge.name == "post_post_end")
      CHECK(edge.segments.size() == 32);
}
