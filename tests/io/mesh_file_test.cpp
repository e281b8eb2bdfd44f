// Mesh files: OBJ and STL (ASCII, binary) read into the same solid; faces, feature edges and
// vertices counted on shapes whose elements are known by construction (a cube, a cylinder, an
// L), named as a box's are; every kind of bad mesh reported at its line and column.
#include <algorithm>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/io/mesh_file.hpp>
#include <tubeplan/scene/elements.hpp>

#include "mesh_test_meshes.hpp"

namespace {

using tubeplan::io::LoadMeshBytes;
using tubeplan::io::MeshLoadResult;

// The diagnostics' text, one per line, for messages in failures and substring checks.
std::string Text(const MeshLoadResult& r) { return r.diagnostics.FormatAll(); }

bool Has(const MeshLoadResult& r, const std::string& text) {
  return Text(r).find(text) != std::string::npos;
}

}  // namespace

TEST_CASE("The file's numbers are scaled to metres", "[mesh]") {
  const MeshLoadResult r = LoadMeshBytes(tubeplan::testing::CubeObj(), "cube.obj", 0.001);
  REQUIRE(r.mesh);
  Eigen::Vector3d hi = Eigen::Vector3d::Zero();
  for (const auto& v : r.mesh->vertices_P_m) hi = hi.cwiseMax(v);
  CHECK(hi == Eigen::Vector3d::Constant(0.001));
  CHECK_THROWS_AS(LoadMeshBytes("", "cube.obj", 0.0), std::invalid_argument);
}

TEST_CASE("Vertices within the weld tolerance are one, beyond it two", "[mesh]") {
  // The cube's corner 8 written again as vertex 9, 1e-7 of the diagonal away (within 1e-6), and
  // the top face made with it: one vertex.
  auto with_ninth = [](const std::string& v9) {
    std::string obj = tubeplan::testing::CubeObj();
    obj.insert(obj.find("# faces"), v9);
    obj.replace(obj.find("f 5 6 8 7"), 9, "f 5 6 9 7");
    return obj;
  };
  const MeshLoadResult welded = LoadMeshBytes(with_ninth("v 1.0000001 1 1\n"), "cube.obj", 1.0);
  INFO(Text(welded));
  REQUIRE(welded.mesh);
  CHECK(welded.mesh->vertices_P_m.size() == 8);
  // 1e-5 of the diagonal away: a vertex of its own, and the surface has a crack.
  const MeshLoadResult cracked = LoadMeshBytes(with_ninth("v 1.00002 1 1\n"), "cube.obj", 1.0);
  CHECK_FALSE(cracked.mesh);
  CHECK(Has(cracked, "the mesh has a hole"));
}

TEST_CASE("Each kind of bad mesh is reported at its place", "[mesh]") {
  using tubeplan::testing::CubeObj;
  // The face of kCubeFaces[k] is on line 11 + 2k (mesh_test_meshes.hpp).
  SECTION("open: a face left out leaves four edges of one triangle each") {
    const MeshLoadResult r = LoadMeshBytes(CubeObj(4), "open.obj", 1.0);
    const std::string text = Text(r);
    // ypos's neighbours: top (11), bottom (13), xpos (15), xneg (17).
    for (int line : {11, 13, 15, 17})
      CHECK(Has(r, "open.obj:" + std::to_string(line) + ":1: error: the edge from"));
    CHECK(std::count(text.begin(), text.end(), '\n') == 4);
    CHECK(Has(r, "borders this triangle only: the mesh has a hole, expected a closed surface"));
  }
  SECTION("non-manifold: a fin on an edge") {
    const MeshLoadResult r = LoadMeshBytes(CubeObj() + "v 0.5 2 2\nf 7 8 9\n", "fin.obj", 1.0);
    CHECK(Has(r,
              "fin.obj:23:1: error: the edge from (1000, 1000, 1000) mm to (0, 1000, 1000) mm "
              "borders 3 triangles, expected two"));
  }
  SECTION("degenerate: three corners on a line") {
    const MeshLoadResult r = LoadMeshBytes(CubeObj() + "v 0.5 0 0\nf 1 9 2\n", "flat.obj", 1.0);
    CHECK(Has(r, "flat.obj:23:1: error: this triangle has (nearly) no area: its height is 0 mm"));
  }
  SECTION("inconsistent winding: one face reversed") {
    const MeshLoadResult r = LoadMeshBytes(CubeObj(-1, 5), "wound.obj", 1.0);
    // yneg (line 21) is the later triangle at each of its four edges.
    const std::string text = Text(r);
    CHECK(std::count(text.begin(), text.end(), '\n') == 4);
    CHECK(Has(r, "wound.obj:21:1: error: this triangle and its neighbour run the edge from"));
    CHECK(Has(r,
              "the same way, expected opposite ways (both counter-clockwise seen from "
              "outside) (the other triangle: the face at line 13)"));
  }
  SECTION("inverted: every face reversed") {
    const MeshLoadResult r = LoadMeshBytes(CubeObj(-1, -1, true), "inside.obj", 1.0);
    CHECK(Text(r) ==
          "inside.obj:11:1: error: the closed body of this triangle has a negative volume (-1e+09 "
          "mm^3): its normals point inwards, expected corners counter-clockwise seen from outside "
          "(reverse each face's corners, or export with outward normals)\n");
  }
  SECTION("self-intersecting: two cubes through each other") {
    // The second cube shifted by amounts that make no crossing pass through a corner or along a
    // quad's diagonal (a touch there would not count).
    const std::string second = CubeObj(-1, -1, false, Eigen::Vector3d(0.31, 0.27, 0.43));
    std::string obj = CubeObj();
    // The second cube's indices follow the first's eight vertices.
    std::istringstream lines(second);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("f ", 0) == 0) {
        std::istringstream words(line.substr(2));
        line = "f";
        for (int i; words >> i;) line += " " + std::to_string(i + 8);
      }
      obj += line + "\n";
    }
    const MeshLoadResult r = LoadMeshBytes(obj, "two.obj", 1.0);
    CHECK(Has(r, "error: this triangle crosses another one that shares no corner with it"));
    // Only the first cube's top, xpos and ypos meet the second's bottom, xneg and yneg.
    const std::string text = Text(r);
    for (const std::string line : {"11", "15", "19"})
      CHECK(Has(r, "(the other triangle: the face at line " + line + ")"));
    CHECK_FALSE(Has(r, "(the other triangle: the face at line 13)"));
  }
}

TEST_CASE("Bad mesh files are reported at their place, all problems at once", "[mesh]") {
  SECTION("OBJ syntax") {
    const MeshLoadResult r =
        LoadMeshBytes("v 0 0 zero\nv 1 0\nv 0 1 0\nf 1 2 4\nf 1 0 x/2\nf 1 2\n", "syntax.obj", 1.0);
    CHECK(Text(r) ==
          "syntax.obj:1:7: error: 'zero' is not a number, expected a finite coordinate\n"
          "syntax.obj:2:1: error: a vertex with 2 coordinates, expected 3 (v x y z)\n"
          "syntax.obj:4:7: error: vertex 4 does not exist, expected 1 to 3 or -1 to -3 (the "
          "vertices written so far)\n"
          "syntax.obj:5:5: error: vertex 0 does not exist, expected 1 to 3 or -1 to -3 (the "
          "vertices written so far)\n"
          "syntax.obj:5:7: error: 'x/2' is not a vertex reference, expected i, i/t, i//n or "
          "i/t/n with a vertex number i\n"
          "syntax.obj:6:1: error: a face of 2 vertices, expected 3 or more (f v1 v2 v3 ...)\n");
  }
  SECTION("ASCII STL syntax") {
    std::string stl = tubeplan::testing::AsciiStl(tubeplan::testing::CubeTriangles());
    // Line 11 is the second facet's first vertex.
    stl.replace(stl.find("vertex", stl.find("facet", 10)), 6, "vertx");
    const MeshLoadResult r = LoadMeshBytes(stl, "bad.stl", 1.0);
    CHECK(Has(r, "bad.stl:11:7: error: 'vertx' where 'vertex' belongs, expected 'vertex'"));
  }
  SECTION("binary STL: a coordinate that is not a number") {
    std::string stl = tubeplan::testing::BinaryStl(tubeplan::testing::CubeTriangles());
    // Triangle 2's second corner's z: record 84 + 50, corner at 12 + 12, z at + 8.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(stl.data() + 134 + 24 + 8, &nan, 4);
    const MeshLoadResult r = LoadMeshBytes(stl, "nan.stl", 1.0);
    CHECK(Text(r) ==
          "nan.stl:1:167: error: triangle 2: corner 2's z is not a finite number, "
          "expected a coordinate\n");
  }
  SECTION("binary STL cut short") {
    std::string stl = tubeplan::testing::BinaryStl(tubeplan::testing::CubeTriangles());
    stl.replace(0, 5, "STLEX");
    stl.resize(stl.size() - 10);
    const MeshLoadResult r = LoadMeshBytes(stl, "short.stl", 1.0);
    CHECK(Text(r) ==
          "short.stl:1:81: error: the header gives 12 triangles, so a binary STL of "
          "84 + 50 x 12 = 684 bytes, but the file has 674 bytes and does not start "
          "with 'solid' either, expected an ASCII or a binary STL\n");
  }
  SECTION("too many triangles") {
    // 200,001 copies of one triangle: refused before welding, at the one too many.
    std::vector<std::array<Eigen::Vector3d, 3>> many(
        tubeplan::scene::kMaxTriangles + 1,
        {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)});
    const MeshLoadResult r = LoadMeshBytes(tubeplan::testing::BinaryStl(many), "big.stl", 1.0);
    CHECK(Text(r) ==
          "big.stl:1:10000085: error: triangle 200001 is one too many: the file has "
          "200001 triangles, expected at most 200000 (simplify the mesh in its "
          "export)\n");
  }
  SECTION("neither format") {
    const MeshLoadResult r = LoadMeshBytes("v 0 0 0\n", "cube.ply", 1.0);
    CHECK(Text(r) ==
          "cube.ply: error: the extension '.ply' names no mesh format, expected .obj "
          "or .stl\n");
  }
}
