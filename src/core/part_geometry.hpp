#pragma once
// The rigid parts as the contact stage sees them: a signed distance with its gradient and the
// element (face, edge, vertex) the nearest point lies on, and the sharp features (edges as
// segments, vertices as points) that can poke into the tube between its sections. Boxes,
// cylinders and meshes; a cylinder's rims are polygons of short segments and its side bears on
// the tube between sections as its axis does, grown by its radius. A mesh's convex edges poke
// as chains of its triangles' edges, a curved face's ridges as edges of that face (the nearest
// one to a piece of the tube only), its convex corners as points.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/scene/aabb_tree.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::core {

/// An element's index within its part (scene::ElementsOf), or none.
using ElementIndex = std::uint16_t;
inline constexpr ElementIndex kNoElement = 0xFFFF;
static_assert(scene::kMaxElements < kNoElement, "every element of a part has an index");

/// The nearest point of a part to a query point.
struct PartDistance {
  double distance_m = 0.0;  ///< signed: negative inside the part [m]
  /// Unit outward normal at the nearest point: the direction in which the distance grows.
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();  ///< nearest point on the part's surface
  ElementIndex element = kNoElement;                  ///< the element the nearest point lies on
  /// The distance's second derivative: (I - n n^T - a a^T) / distance near an edge (a its unit
  /// direction), (I - n n^T) / distance near a vertex, zero near a flat face or inside; near a
  /// cylinder's side, its curving about the axis.
  Eigen::Matrix3d curvature_per_m = Eigen::Matrix3d::Zero();
};

struct PartEdge {
  Eigen::Vector3d a_W = Eigen::Vector3d::Zero(), b_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d min_W = Eigen::Vector3d::Zero(), max_W = Eigen::Vector3d::Zero();  ///< its box
  ElementIndex element = kNoElement;
  ElementIndex a_element = kNoElement, b_element = kNoElement;  ///< the vertices it ends in
  /// Whether a load at an end is this segment's: not where a rim's polygon goes on into its next
  /// segment (that one bears the shared point), not at a round side's axis ends (the rims do).
  bool a_bears = true, b_bears = true;
  /// A round side is its axis as an edge with the side's radius: the surface lies this far from
  /// the segment [m]; 0 for a sharp edge.
  double radius_m = 0.0;
  /// A ridge of a curved mesh face, between two of its triangles: of a face's ridges, only the
  /// one nearest a piece of the tube bears on that piece, as the one nearest point of a smooth
  /// surface would (parallel ridges within epsilon would otherwise add their stiffnesses).
  bool ridge = false;
  /// The outward unit normals of the two faces that meet at it (zero for a round side's axis:
  /// it bears all round).
  std::array<Eigen::Vector3d, 2> face_normals_W{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
};

class PartGeometry {
 public:
  PartGeometry() = default;
  explicit PartGeometry(const scene::Part& part);

  /// Signed distance of p_W to the part. Inside, the distance is to the faces of the element
  /// `entry` when it names one (where the point came in: a thin box is not crossed by pushing
  /// a point past its middle), else to the nearest face. A point pushed past a cylinder's axis
  /// or a mesh's middle leaves by the surface nearest it: a push beyond K (eps + half the
  /// thickness) can cross such a part, as `check` warns for thin parts.
  PartDistance Distance(const Eigen::Vector3d& p_W, ElementIndex entry = kNoElement) const;

  const std::vector<PartEdge>& edges() const { return edges_; }
  /// Calls visit(e) for the index of every edge whose box meets [lo_W, hi_W], in no set order.
  template <class Visit>
  void EdgesOverlapping(const Eigen::Vector3d& lo_W, const Eigen::Vector3d& hi_W,
                        Visit&& visit) const {
    edge_tree_.Overlapping(lo_W, hi_W, visit);
  }
  const std::vector<Eigen::Vector3d>& vertices_W() const { return vertices_W_; }
  const std::vector<ElementIndex>& vertex_elements() const { return vertex_elements_; }
  /// Whether element a lies on element b's boundary or is b (an edge bounds its faces, a vertex
  /// its edges and faces).
  bool Bounds(ElementIndex a, ElementIndex b) const;
  const Eigen::Vector3d& min_W() const { return min_W_; }
  const Eigen::Vector3d& max_W() const { return max_W_; }
  /// How thin the part is (scene::ThinnestSize_m) [m].
  double thinnest_m() const { return thinnest_m_; }

 private:
  // Boxes and cylinders name their elements by the faces they lie on (BoxFace, CylinderFace
  // bits): what the shapes' own code works in, turned into element indices at the surface.
  void BuildBox();
  void BuildCylinder();
  void BuildMesh();
  void AddMeshEdges();
  PartDistance BoxDistance(const Eigen::Vector3d& p_P, std::uint8_t entry_mask,
                           std::uint8_t& mask) const;
  PartDistance CylinderDistance(const Eigen::Vector3d& p_P, std::uint8_t entry_mask,
                                std::uint8_t& mask) const;
  ElementIndex ElementOfMask(std::uint8_t mask) const { return element_of_mask_[mask]; }
  PartDistance MeshDistance(const Eigen::Vector3d& p_W) const;

  scene::PartShape shape_ = scene::PartShape::kBox;
  Eigen::Matrix3d R_WP_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_WP_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_m_ = Eigen::Vector3d::Zero();  ///< half extents in the part's frame
  std::vector<PartEdge> edges_;
  std::vector<Eigen::Vector3d> vertices_W_;
  std::vector<ElementIndex> vertex_elements_;
  std::array<ElementIndex, 64> element_of_mask_{};
  std::vector<std::uint8_t> mask_of_element_;
  std::shared_ptr<const scene::PartMesh> mesh_;
  /// Per mesh element, the elements it lies on, itself left out: an edge's two faces; a vertex's
  /// faces and the edges whose chains end in it. Ascending.
  std::vector<std::vector<ElementIndex>> bounded_;
  scene::AabbTree edge_tree_;
  double thinnest_m_ = 0.0;
  Eigen::Vector3d min_W_ = Eigen::Vector3d::Zero(), max_W_ = Eigen::Vector3d::Zero();
};

/// Bit of BoxFace `face` in a face mask.
constexpr std::uint8_t FaceBit(scene::BoxFace face) {
  return static_cast<std::uint8_t>(1u << static_cast<int>(face));
}

/// Bit of CylinderFace `face` in a face mask.
constexpr std::uint8_t FaceBit(scene::CylinderFace face) {
  return static_cast<std::uint8_t>(1u << static_cast<int>(face));
}

/// Segments of a cylinder's rim polygon: the polygon lies within R (1 - cos(pi / 64)), 0.12 % of
/// the radius, of the circle.
inline constexpr int kRimSegments = 64;

}  // namespace tubeplan::core
