// The bench's mesh twin of a box part (bench/tessellated_box.hpp): a sound closed mesh of the
// intended size whose elements are a box's six faces, twelve edges and eight corners.
#include <bench/tessellated_box.hpp>
#include <set>
#include <stdexcept>
#include <string>

#include <catch2/catch.hpp>

#include <tubeplan/scene/mesh.hpp>

namespace {

using namespace tubeplan;

}  // namespace

TEST_CASE("A tessellated box is a closed mesh with a box's faces, edges and corners", "[mesh]") {
  // The groove's floor at the bench's 29 cells an edge.
  const Eigen::Vector3d size_m(0.060, 0.200, 0.010);
  const int n = 29;
  const scene::TriangleMesh mesh = bench::TessellatedBox(size_m, n);
  // Two triangles a cell, n^2 cells a face; a closed genus-0 mesh has V = T / 2 + 2 (Euler).
  CHECK(mesh.triangles.size() == 12u * n * n);
  CHECK(mesh.triangles.size() == 10092u);
  CHECK(mesh.vertices_P_m.size() == 6u * n * n + 2u);
  CHECK(scene::CheckMesh(mesh).empty());

  // Every vertex on the box's surface: one coordinate at a half extent, the others within.
  const Eigen::Vector3d half_m = 0.5 * size_m;
  // Welding keeps the first of merged points, whose coordinates are sums of a few doubles.
  constexpr double kRound_m = 1e-12;
  for (const Eigen::Vector3d& v : mesh.vertices_P_m) {
    CHECK((v.cwiseAbs() - half_m).maxCoeff() <= kRound_m);
    CHECK((v.cwiseAbs() - half_m).cwiseAbs().minCoeff() <= kRound_m);
  }

  const scene::MeshElements elements = scene::FindElements(mesh);
  REQUIRE(elements.faces.size() == 6);
  const std::vector<std::string> ids(scene::kBoxFaceIds.begin(), scene::kBoxFaceIds.end());
  const Eigen::Vector3d normals[6] = {Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ(),
                                      Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(),
                                      Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitY()};
  for (std::size_t f = 0; f < 6; ++f) {
    INFO("face " << f);
    const scene::MeshFace& face = elements.faces[f];
    CHECK(face.name == ids[f]);
    CHECK(face.planar);
    CHECK(face.triangles.size() == 2u * n * n);
    // A grid on a plane of the box: its mean normal is the axis to the rounding of a cross product.
    CHECK((face.normal_P - normals[f]).norm() < 1e-9);
  }
  CHECK(elements.edges.size() == 12);
  std::set<std::string> edge_names;
  for (const scene::MeshEdge& e : elements.edges) {
    edge_names.insert(e.name);
    CHECK(e.convex);
    // Each edge of the box is cut at the n cells of the faces along it.
    CHECK(e.segments.size() == std::size_t(n));
  }
  CHECK(edge_names.size() == 12);
  CHECK(edge_names.count("top_xpos") == 1);
  CHECK(edge_names.count("top_bottom") == 0);  // opposite faces share no edge
  REQUIRE(elements.vertices.size() == 8);
  for (const scene::MeshVertex& v : elements.vertices) {
    CHECK(v.faces.size() == 3);
    CHECK((v.position_P_m.cwiseAbs() - half_m).cwiseAbs().maxCoeff() <= kRound_m);
  }

  // The part's mesh: the same surface, its bounds the box's, centred on its frame.
  const auto part_mesh = bench::TessellatedBoxMesh(size_m, n);
  const scene::Part part = scene::MakeMeshPart("floor", part_mesh, Eigen::Isometry3d::Identity());
  CHECK((part.size_m - size_m).norm() < kRound_m);
  CHECK(scene::BoundsInPart(part).center().norm() < kRound_m);
}

TEST_CASE("A tessellated box refuses no cells and flat sizes", "[mesh]") {
  CHECK_THROWS_AS(bench::TessellatedBox(Eigen::Vector3d(0.01, 0.01, 0.01), 0),
                  std::invalid_argument);
  CHECK_THROWS_AS(bench::TessellatedBox(Eigen::Vector3d(0.01, 0.0, 0.01), 3),
                  std::invalid_argument);
  // One cell a face: the 12 triangles of a plain box.
  CHECK(bench::TessellatedBox(Eigen::Vector3d(0.01, 0.02, 0.03), 1).triangles.size() == 12);
}
