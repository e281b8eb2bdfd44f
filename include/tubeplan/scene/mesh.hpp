#pragma once
// Triangle meshes of rigid parts loaded from CAD: the triangles as read, and the checks that
// make a mesh a closed solid the contact model can use. Plain data in the part's frame P,
// metres; files are read by io/mesh_file.hpp.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tubeplan::scene {

/// A triangle soup or a welded mesh: vertex indices in counter-clockwise order seen from outside
/// (the right-hand rule gives the outward normal).
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices_P_m;  ///< in the part's frame P [m]
  std::vector<std::array<int, 3>> triangles;  ///< indices into vertices_P_m
  /// Per triangle: index into `names` of its OBJ group or object (or STL solid), -1 for none.
  std::vector<int> triangle_names;
  std::vector<std::string> names;
};

/// The weld tolerance relative to the bounding box's diagonal: vertices closer than this (in
/// every coordinate) are one vertex. 1e-6 of a 100 mm part is 0.1 um, far below any feature a
/// part is made with, and above the rounding of the same point written twice (a float's 6e-8).
inline constexpr double kWeldRelativeTolerance = 1e-6;

/// The weld tolerance of `mesh` [m]: kWeldRelativeTolerance times its bounding box's diagonal.
double WeldTolerance_m(const TriangleMesh& mesh);

/// Merges vertices closer than `tolerance_m` (along every axis) into the first of them, drops
/// vertices no triangle uses and triangles that collapse (two corners welded into one), and
/// keeps the triangles' order. `source_triangle`, if given, receives each kept triangle's index
/// in `mesh`. Deterministic.
TriangleMesh WeldVertices(const TriangleMesh& mesh, double tolerance_m,
                          std::vector<int>* source_triangle = nullptr);

// --- Checks ---------------------------------------------------------------------------------

/// The most triangles a part may have: at this size welding, checks, elements and the distance
/// tree take about 1.5 s (docs/meshes.md), and a contact model needs far fewer.
inline constexpr std::size_t kMaxTriangles = 200000;

enum class MeshProblemKind {
  kTooManyTriangles,
  kDegenerate,           ///< a triangle of (near) zero area
  kOpenEdge,             ///< an edge of one triangle only: the mesh has a hole
  kNonManifoldEdge,      ///< an edge of more than two triangles
  kInconsistentWinding,  ///< two neighbours that run their shared edge the same way
  kInverted,             ///< a closed body of negative volume: its normals point inwards
  kSelfIntersection,     ///< two triangles that share no vertex cross each other
};

/// One problem, at a triangle (index into TriangleMesh::triangles; -1 for the whole mesh). Every
/// kind is an error (docs/meshes.md says why).
struct MeshProblem {
  MeshProblemKind kind = MeshProblemKind::kDegenerate;
  int triangle = -1;
  int other_triangle = -1;  ///< the neighbour or the crossing triangle, where there is one
  std::string message;      ///< what is wrong, and what was expected (without the place)
};

/// Every problem of a welded mesh; empty when it is a closed, consistently wound, outward
/// facing, non self-intersecting solid. Self-intersection is looked for with a bounding-volume
/// tree (n log n), and only when the mesh is otherwise sound.
std::vector<MeshProblem> CheckMesh(const TriangleMesh& mesh);

/// Unit normal of triangle t (zero when degenerate).
Eigen::Vector3d TriangleNormal(const TriangleMesh& mesh, int t);

}  // namespace tubeplan::scene
