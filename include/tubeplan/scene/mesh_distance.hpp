#pragma once
// The signed distance to a closed triangle mesh placed in the world, with its gradient, its
// nearest point, the element that point lies on and, near a feature edge or vertex, the
// distance's second derivative: what the contact stage asks of every part (core::PartDistance is
// the box's). Queries walk an AABB tree over the triangles and allocate nothing.
//
// Why an own tree and not FCL's BVHModel: on a 10,000-triangle torus, for points within 5 mm of
// its surface (tests/scene/mesh_distance_test.cpp, "[.bench]"), the median query takes 1.6 us
// and 9.4 us through fcl::distance with a sphere of radius 0, which also allocates twice a query
// (the tick allocates nothing; docs/meshes.md, "Distance to a mesh"). The core makes 10-60 queries
// a part in a 1 ms tick.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/scene/aabb_tree.hpp>
#include <tubeplan/scene/mesh.hpp>

namespace tubeplan::scene {

enum class MeshFeatureKind : std::uint8_t { kFace, kEdge, kVertex };

/// An element of MeshElements: faces[index], edges[index] or vertices[index].
struct MeshFeature {
  MeshFeatureKind kind = MeshFeatureKind::kFace;
  int index = 0;
  friend bool operator==(const MeshFeature&, const MeshFeature&) = default;
};

/// The nearest point of a mesh to a query point.
struct MeshDistance {
  double distance_m = 0.0;  ///< signed: negative inside [m]
  /// Unit outward normal: the gradient of the signed distance.
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();  ///< nearest point on the surface
  /// The element the nearest point lies on: a face (inside a triangle, or on an edge or corner
  /// between triangles of one face), a feature edge, or a feature vertex.
  MeshFeature feature;
  int triangle = 0;  ///< a triangle the nearest point lies on
  /// The distance's second derivative [1/m]: (I - n n^T - a a^T) / d on a feature edge of
  /// direction a, (I - n n^T) / d at a corner of a feature edge or a feature vertex, zero on a
  /// face (and at d = 0). d is signed, so it holds inside too (behind a concave edge).
  Eigen::Matrix3d curvature_per_m = Eigen::Matrix3d::Zero();
};

/// A piece of a feature edge in the world, for tests against the tube between its sections.
struct MeshEdgeSegment {
  Eigen::Vector3d a_W = Eigen::Vector3d::Zero(), b_W = Eigen::Vector3d::Zero();
  int edge = 0;  ///< into MeshElements::edges
};

class MeshGeometry {
 public:
  MeshGeometry() = default;
  /// The mesh (sound: CheckMesh found nothing) and its elements, placed at X_WP.
  MeshGeometry(const TriangleMesh& mesh, const MeshElements& elements,
               const Eigen::Isometry3d& X_WP);

  /// Signed distance of p_W to the mesh, signed by angle-weighted pseudo-normals (Baerentzen
  /// and Aanaes 2005): exact for a closed, consistently wound mesh. No allocation.
  MeshDistance Distance(const Eigen::Vector3d& p_W) const;

  const std::vector<MeshEdgeSegment>& edge_segments() const { return edge_segments_; }
  /// Feature vertices in the world, indexed as MeshElements::vertices.
  const std::vector<Eigen::Vector3d>& vertices_W() const { return feature_vertices_W_; }
  const Eigen::Vector3d& min_W() const { return min_W_; }
  const Eigen::Vector3d& max_W() const { return max_W_; }

 private:
  // What a query touches per triangle, together: corners, normal, and the pseudo-normal slots
  // and features of its edges and corners.
  struct Triangle {
    Eigen::Vector3d a, b, c, normal;
    std::array<int, 3> edge{};    ///< undirected mesh edge of side k (corner k to k+1)
    std::array<int, 3> vertex{};  ///< mesh vertex of corner k
    int face = 0;
  };
  std::vector<Triangle> triangles_;
  AabbTree tree_;
  std::vector<Eigen::Vector3d> edge_normals_W_;    ///< per mesh edge, unit
  std::vector<Eigen::Vector3d> vertex_normals_W_;  ///< per mesh vertex, unit
  std::vector<int> edge_feature_;                  ///< per mesh edge: its feature edge or -1
  std::vector<int> vertex_feature_;                ///< per mesh vertex: feature vertex or -1
  std::vector<int> vertex_edge_;                   ///< per mesh vertex: a feature edge or -1
  std::vector<MeshEdgeSegment> edge_segments_;
  std::vector<Eigen::Vector3d> feature_vertices_W_;
  Eigen::Vector3d min_W_ = Eigen::Vector3d::Zero(), max_W_ = Eigen::Vector3d::Zero();
};

}  // namespace tubeplan::scene
