#pragma once
// Triangle meshes of rigid parts loaded from CAD (docs/meshes.md): the triangles as read, the
// checks that make a mesh a closed solid the contact model can use, and its named surface
// elements (faces, edges, vertices) as the paper's polyhedral contact model needs them. Plain
// data in the part's frame P, metres; files are read by io/mesh_file.hpp.

#include <array>
#include <cstddef>
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
  kFlat,                 ///< a closed body of no volume: a sheet seen from both sides
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

// --- Elements -------------------------------------------------------------------------------

/// The most faces, edges and vertices a part may have together: the core names a contact's
/// element by its index within the part in 16 bits (one value kept for none).
inline constexpr std::size_t kMaxElements = 65534;

/// Neighbouring triangles whose normals differ by less than this lie on one face: a tessellated
/// cylinder of 19 or more segments or a fillet of 5 or more is one face, a box's sides are six.
inline constexpr double kFeatureAngle_deg = 20.0;
/// A face is planar when every triangle's normal is within this of the face's mean normal.
inline constexpr double kPlanarAngle_deg = 1.0;

struct MeshFace {
  std::string name;
  bool planar = true;
  std::vector<int> triangles;                          ///< in mesh order
  Eigen::Vector3d normal_P = Eigen::Vector3d::Zero();  ///< area-weighted mean, unit
};

struct MeshEdge {
  std::string name;            ///< "face_a" + '_' + "face_b"
  int face_a = 0, face_b = 0;  ///< face_a <= face_b
  bool convex = true;          ///< the material's angle at the edge is below 180 deg
  /// Mesh vertex index pairs, in order along the chain where it is one.
  std::vector<std::array<int, 2>> segments;
};

struct MeshVertex {
  std::string name;        ///< the faces' names joined by '_'
  std::vector<int> faces;  ///< ascending
  int mesh_vertex = 0;
  Eigen::Vector3d position_P_m = Eigen::Vector3d::Zero();
};

/// The named surface elements of a sound mesh, and where each triangle's pieces lie.
struct MeshElements {
  std::vector<MeshFace> faces;
  std::vector<MeshEdge> edges;
  std::vector<MeshVertex> vertices;
  /// Per triangle: its face.
  std::vector<int> triangle_face;
  /// Per triangle and local edge k (from corner k to k+1): the feature edge it lies on, or -1.
  std::vector<std::array<int, 3>> triangle_edge;
  /// Per mesh vertex: the feature vertex it is, or -1.
  std::vector<int> vertex_element;
  /// Per mesh vertex that is no feature vertex: a feature edge it lies on, or -1.
  std::vector<int> vertex_edge;
};

/// Faces, feature edges and feature vertices of a mesh CheckMesh found no problem in. Faces are
/// numbered in order of their first triangle, and named after their triangles' group (the first
/// triangle's; "_1", "_2"... when a group makes several faces) or "f0", "f1"... without one.
MeshElements FindElements(const TriangleMesh& mesh);

/// Unit normal of triangle t (zero when degenerate).
Eigen::Vector3d TriangleNormal(const TriangleMesh& mesh, int t);

}  // namespace tubeplan::scene
