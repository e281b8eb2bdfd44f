#pragma once
// Who borders whom in a triangle mesh: its undirected edges and each triangle's neighbours
// across them. Shared by the checks and the elements (src/scene/mesh_check.cpp,
// mesh_elements.cpp).

#include <array>
#include <vector>

#include <tubeplan/scene/mesh.hpp>

namespace tubeplan::scene {

/// A neighbour index that is no triangle: the edge has one triangle, or more than two.
inline constexpr int kOpen = -1;
inline constexpr int kNonManifold = -2;

struct MeshTopology {
  /// Per undirected edge: its two vertices (ascending) and its triangles, in mesh order.
  std::vector<std::array<int, 2>> edge_vertices;
  std::vector<std::vector<int>> edge_triangles;
  /// Per triangle and local edge k (corner k to corner k+1): the undirected edge, and the
  /// triangle across it (kOpen, kNonManifold).
  std::vector<std::array<int, 3>> triangle_edge;
  std::vector<std::array<int, 3>> neighbour;
};

MeshTopology BuildTopology(const TriangleMesh& mesh);

/// Whether triangle t runs from vertex a to vertex b along one of its edges.
bool RunsFromTo(const TriangleMesh& mesh, int t, int a, int b);

}  // namespace tubeplan::scene
