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
using tubeplan::scene::MeshElements;

std::set<std::string> EdgeNames(const MeshElements& e) {
  std::set<std::string> names;
  for (const auto& edge : e.edges) names.insert(edge.name);
  return names;
}

std::set<std::string> VertexNames(const MeshElements& e) {
  std::set<std::string> names;
  for (const auto& vertex : e.vertices) names.insert(vertex.name);
  return names;
}

// The diagnostics' text, one per line, for messages in failures and substring checks.
std::string Text(const MeshLoadResult& r) { return r.diagnostics.FormatAll(); }

bool Has(const MeshLoadResult& r, const std::string& text) {
  return Text(r).find(text) != std::string::npos;
}

// The box "cube" with the cube's extents: its element names are the box's naming rule.
std::vector<tubeplan::scene::PartElement> BoxElements() {
  tubeplan::scene::Scene scene;
  tubeplan::scene::Part box;
  box.name = "cube";
  box.size_m = Eigen::Vector3d::Ones();
  scene.parts.push_back(box);
  return tubeplan::scene::EnumerateElements(scene);
}

}  // namespace

TEST_CASE("A cube in OBJ has six planar faces, twelve convex edges, eight vertices", "[mesh]") {
  const MeshLoadResult r = LoadMeshBytes(tubeplan::testing::CubeObj(), "cube.obj", 1.0);
  INFO(Text(r));
  REQUIRE(r.elements);
  REQUIRE_FALSE(r.diagnostics.HasErrors());
  const MeshElements& e = *r.elements;
  CHECK(r.mesh->vertices_P_m.size() == 8);
  CHECK(r.mesh->triangles.size() == 12);
  REQUIRE(e.faces.size() == 6);
  for (std::size_t f = 0; f < 6; ++f) {
    CHECK(e.faces[f].name == tubeplan::testing::kCubeFaceNames[f]);
    CHECK(e.faces[f].planar);
    CHECK(e.faces[f].triangles.size() == 2);
  }
  REQUIRE(e.edges.size() == 12);
  for (const auto& edge : e.edges) {
    CHECK(edge.convex);
    CHECK(edge.segments.size() == 1);
  }
  REQUIRE(e.vertices.size() == 8);
  // Names as the box's elements have them, "cube." left off.
  std::set<std::string> box_edges, box_vertices;
  for (const auto& element : BoxElements()) {
    const std::string name = element.name.substr(5);
    if (element.kind == tubeplan::scene::ElementKind::kEdge) box_edges.insert(name);
    if (element.kind == tubeplan::scene::ElementKind::kVertex) box_vertices.insert(name);
  }
  CHECK(EdgeNames(e) == box_edges);
  CHECK(VertexNames(e) == box_vertices);
  // Each vertex sits at the corner its three faces share: top_xpos_ypos at (1, 1, 1).
  for (const auto& v : e.vertices) {
    const Eigen::Vector3d expected(v.name.find("xpos") != std::string::npos ? 1.0 : 0.0,
                                   v.name.find("ypos") != std::string::npos ? 1.0 : 0.0,
                                   v.name.find("top") != std::string::npos ? 1.0 : 0.0);
    CHECK(v.position_P_m == expected);
  }
}

TEST_CASE("The cube as ASCII and as binary STL has the same elements", "[mesh]") {
  const auto triangles = tubeplan::testing::CubeTriangles();
  const MeshLoadResult ascii =
      LoadMeshBytes(tubeplan::testing::AsciiStl(triangles), "cube.stl", 1.0);
  // The binary file's header starts with "solid": its size tells it apart.
  const MeshLoadResult binary =
      LoadMeshBytes(tubeplan::testing::BinaryStl(triangles), "cube.STL", 1.0);
  const MeshLoadResult obj = LoadMeshBytes(tubeplan::testing::CubeObj(), "cube.obj", 1.0);
  INFO(Text(ascii) << Text(binary));
  REQUIRE(ascii.elements);
  REQUIRE(binary.elements);
  // STL shares no vertices: 36 corners welded into the cube's 8.
  CHECK(ascii.mesh->vertices_P_m.size() == 8);
  CHECK(binary.mesh->vertices_P_m.size() == 8);
  for (const MeshLoadResult* r : {&ascii, &binary}) {
    const MeshElements& e = *r->elements;
    REQUIRE(e.faces.size() == 6);
    // Without groups the faces are f0..f5 in the order of their first triangle: the OBJ's order.
    for (std::size_t f = 0; f < 6; ++f) {
      CHECK(e.faces[f].name == "f" + std::to_string(f));
      CHECK(e.faces[f].triangles == obj.elements->faces[f].triangles);
    }
    CHECK(e.edges.size() == 12);
    CHECK(e.vertices.size() == 8);
    CHECK(r->mesh->vertices_P_m == obj.mesh->vertices_P_m);
  }
  CHECK(EdgeNames(*ascii.elements) == EdgeNames(*binary.elements));
  CHECK(VertexNames(*ascii.elements) == VertexNames(*binary.elements));
  CHECK(ascii.mesh->triangles == binary.mesh->triangles);
}

TEST_CASE("A 64-sided cylinder is three faces, two loop edges and no vertex", "[mesh]") {
  const MeshLoadResult r = LoadMeshBytes(tubeplan::testing::CylinderObj(64), "cyl.obj", 1.0);
  INFO(Text(r));
  REQUIRE(r.elements);
  const MeshElements& e = *r.elements;
  REQUIRE(e.faces.size() == 3);
  // The side (its quads come first in the file) is curved; the caps are planar.
  CHECK_FALSE(e.faces[0].planar);
  CHECK(e.faces[0].triangles.size() == 128);
  CHECK(e.faces[1].planar);
  CHECK(e.faces[2].planar);
  REQUIRE(e.edges.size() == 2);
  for (const auto& edge : e.edges) {
    CHECK(edge.convex);
    REQUIRE(edge.segments.size() == 64);
    // Chained: each segment starts where the one before ends, and the loop closes.
    for (std::size_t s = 0; s < 64; ++s)
      CHECK(edge.segments[s][1] == edge.segments[(s + 1) % 64][0]);
  }
  CHECK(e.vertices.empty());
}

TEST_CASE("The cylinder's side is one face only while its facets turn less than 20 deg", "[mesh]") {
  // 17 sides turn 21.2 deg each: every side is a face of its own; 19 turn 18.9 deg.
  const MeshLoadResult coarse = LoadMeshBytes(tubeplan::testing::CylinderObj(17), "c.obj", 1.0);
  REQUIRE(coarse.elements);
  CHECK(coarse.elements->faces.size() == 17 + 2);
  const MeshLoadResult fine = LoadMeshBytes(tubeplan::testing::CylinderObj(19), "c.obj", 1.0);
  REQUIRE(fine.elements);
  CHECK(fine.elements->faces.size() == 3);
}

TEST_CASE("An L-shaped prism has exactly one concave edge", "[mesh]") {
  const std::vector<Eigen::Vector2d> l = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const MeshLoadResult r = LoadMeshBytes(tubeplan::testing::PrismObj(l, 1.0), "l.obj", 1.0);
  INFO(Text(r));
  REQUIRE(r.elements);
  const MeshElements& e = *r.elements;
  // Six sides and two caps; six upright edges and six on each cap; each profile corner twice.
  CHECK(e.faces.size() == 8);
  REQUIRE(e.edges.size() == 18);
  CHECK(e.vertices.size() == 12);
  std::vector<const tubeplan::scene::MeshEdge*> concave;
  for (const auto& edge : e.edges)
    if (!edge.convex) concave.push_back(&edge);
  REQUIRE(concave.size() == 1);
  // The inner corner (1, 1) upright: between side 2 (from (2,1) to (1,1)) and side 3.
  CHECK(concave[0]->name == "f2_f3");
  REQUIRE(concave[0]->segments.size() == 1);
  for (int v : concave[0]->segments[0])
    CHECK(r.mesh->vertices_P_m[std::size_t(v)].head<2>() == Eigen::Vector2d(1, 1));
}

TEST_CASE("OBJ faces in every index form, negative indices, polygons and names", "[mesh]") {
  // The cube again, its faces written with i/t, i//n, i/t/n and negative indices, one face as
  // two triangles, names by o and g, and statements that do not matter.
  const std::string obj =
      "mtllib cube.mtl\no part\n"
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
      "vt 0 0\nvn 0 0 1\ns off\nusemtl steel\n"
      "g clip_top\nf 5/1 6/1 8/1 7/1\n"
      "g\nf -8//1 -6//1 -5//1 -7//1\n"          // bottom: o's name again
      "g side\nf 2/1/1 4/1/1 8/1/1\nf 2 8 6\n"  // xpos as two triangles
      "f 1 5 7 3\nf 3 7 8 4\n"                  // xneg, ypos: still the group side
      "g Cube.001\nf 1 2 6 5\n";                // yneg: a name that is not one
  const MeshLoadResult r = LoadMeshBytes(obj, "named.obj", 1.0);
  INFO(Text(r));
  REQUIRE(r.elements);
  const MeshElements& e = *r.elements;
  REQUIRE(e.faces.size() == 6);
  std::vector<std::string> names;
  for (const auto& f : e.faces) names.push_back(f.name);
  // "side" makes three faces (xpos, xneg, ypos), numbered in order of their first triangle.
  CHECK(names ==
        std::vector<std::string>{"clip_top", "part", "side_1", "side_2", "side_3", "Cube_001"});
  CHECK(e.edges.size() == 12);
  CHECK(Has(r, "named.obj:24:3: warning: 'Cube.001' is not a name"));
}

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
  SECTION("a cavity faces inwards, and is no error") {
    // A hollow cube: the inner cube [0.25, 0.75]^3 with every face reversed, its vertices 9-16.
    std::string obj = CubeObj();
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d p =
          0.25 * Eigen::Vector3d::Ones() + 0.5 * tubeplan::testing::CubeCorner(i);
      obj += "v " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " +
             std::to_string(p.z()) + "\n";
    }
    for (const auto& f : tubeplan::testing::kCubeFaces)
      obj += "f " + std::to_string(f[0] + 9) + " " + std::to_string(f[3] + 9) + " " +
             std::to_string(f[2] + 9) + " " + std::to_string(f[1] + 9) + "\n";
    const MeshLoadResult hollow = LoadMeshBytes(obj, "hollow.obj", 1.0);
    CHECK(Text(hollow).empty());
    // The same inner cube alone faces inwards: an error.
    std::string alone;
    for (std::size_t i = obj.find("v 0.25"); i < obj.size();) {
      const std::size_t end = obj.find('\n', i) + 1;
      std::string line = obj.substr(i, end - i);
      if (line.rfind("f ", 0) == 0) {
        std::istringstream words(line.substr(2));
        line = "f";
        for (int k; words >> k;) line += " " + std::to_string(k - 8);
        line += "\n";
      }
      alone += line;
      i = end;
    }
    const MeshLoadResult inverted = LoadMeshBytes(alone, "inner.obj", 1.0);
    CHECK(Has(inverted,
              "inner.obj:9:1: error: the closed body of this triangle has a negative volume"));
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
    // 200,001 copies of one triangle: a binary STL is refused by its header's count, before
    // its records are parsed; an ASCII one at the one too many, before welding.
    std::vector<std::array<Eigen::Vector3d, 3>> many(
        tubeplan::scene::kMaxTriangles + 1,
        {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)});
    const MeshLoadResult r = LoadMeshBytes(tubeplan::testing::BinaryStl(many), "big.stl", 1.0);
    CHECK(Text(r) ==
          "big.stl:1:81: error: the header counts 200001 triangles, expected at most 200000 "
          "(simplify the mesh in its export)\n");
    std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for (std::size_t t = 0; t <= tubeplan::scene::kMaxTriangles; ++t) obj += "f 1 2 3\n";
    CHECK(Text(LoadMeshBytes(obj, "big.obj", 1.0)) ==
          "big.obj:200004:1: error: triangle 200001 is one too many: the file has 200001 "
          "triangles, expected at most 200000 (simplify the mesh in its export)\n");
  }
  SECTION("neither format") {
    const MeshLoadResult r = LoadMeshBytes("v 0 0 0\n", "cube.ply", 1.0);
    CHECK(Text(r) ==
          "cube.ply: error: the extension '.ply' names no mesh format, expected .obj "
          "or .stl\n");
  }
}

TEST_CASE("A mesh far from the origin welds without overflowing its grid", "[mesh]") {
  // 1e28 mm out, 1 mm across: the weld grid's cell (2e-6 of the diagonal) is 1e31 times finer
  // than the distance to the origin, so cells are counted from the mesh's own low corner.
  const std::string obj = "v 1e28 0 0\nv 1e28 1 0\nv 1e28 0 1\nv 1e28 0 0\nf 1 2 3\nf 4 3 2\n";
  const MeshLoadResult r = LoadMeshBytes(obj, "far.obj", 1e-3);
  CHECK_FALSE(r.mesh.has_value());
  // Vertices 1 and 4 weld into one: the two triangles are then one sheet seen from both sides,
  // closed but holding no volume.
  CHECK(r.diagnostics.FormatAll() ==
        "far.obj:5:1: error: the closed body of this triangle encloses no volume (0 mm^3): it is "
        "a sheet seen from both sides, expected a solid\n");
}
