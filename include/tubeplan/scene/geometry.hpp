#pragma once
// Geometry a scene is checked with before anything runs on it (io/scene_yaml.cpp): parts that
// overlap each other, and parts that reach into the tube at its start.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include <tubeplan/scene/scene.hpp>

namespace tubeplan::scene {

/// Separating-axis test of two oriented boxes: true when they share a volume thicker than
/// `tolerance_m` along every axis (boxes that only touch do not overlap).
bool BoxesOverlap(const Part& a, const Part& b, double tolerance_m);

/// Whether two parts share a volume thicker than `tolerance_m`: BoxesOverlap for two boxes; with
/// a mesh, whether a vertex or an edge of either (or a point just inside it) reaches deeper than
/// `tolerance_m` into the other, by exact signed distances (a part resting on a mesh's face only
/// touches it); FCL's penetration depth for a cylinder and a box or two cylinders.
bool PartsOverlap(const Part& a, const Part& b, double tolerance_m);

/// Every pair {later, earlier} of overlapping parts (PartsOverlap), sorted by the later part's
/// index, then the earlier's. Only parts whose bounding boxes meet are compared (FCL's dynamic
/// AABB tree): time grows as n log n with n parts spread in space, memory as n.
std::vector<std::pair<std::size_t, std::size_t>> OverlappingParts(std::span<const Part> parts,
                                                                  double tolerance_m);

/// How deep `part` reaches into the straight tube held at X_WH: the flat-ended cylinder of
/// `radius_m` along the held frame's +z from its origin (the held end) to `length_m` (the tip).
/// The depth is the radius less the distance from the tube's axis to the part's piece between
/// the ends' planes (the radius itself when the part crosses the axis); nullopt when the part
/// does not reach into the tube by more than `tolerance_m`, sideways or past an end's plane. Exact:
/// the piece is a convex polygon when seen along the axis, and its distance to the axis is a
/// point-polygon distance (a cylinder is taken as a prism of 64 sides). A mesh, which need not be
/// convex, is measured by its triangles' pieces between the ends' planes, each convex: exact too.
std::optional<double> StraightTubeOverlap(const Eigen::Isometry3d& X_WH, double radius_m,
                                          double length_m, const Part& part, double tolerance_m);

/// Whether p_W lies inside the part by more than `margin_m` (0: strictly inside).
bool Contains(const Part& part, const Eigen::Vector3d& p_W, double margin_m = 0.0);

/// A point on an element of a part and the element's outward direction there.
struct ElementPoint {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d n_W = Eigen::Vector3d::UnitZ();  ///< unit
};

/// A point of element `element` of the part (its index within the part, as ElementsOf numbers
/// them) and the element's outward normal there. A box's face's or edge's middle, or its vertex;
/// on a cylinder's side and rims, the point facing `toward_W` (a direction) most. On a mesh: of a
/// face, the triangle facing `toward_W` most (the one nearest the face's middle among equals, so
/// a flat face gives its middle where that lies on it) with its normal; of an edge, the middle of
/// its segment facing `toward_W` most, the mean normal of the segment's two triangles; of a
/// vertex, its position and the mean of its faces' normals.
ElementPoint PointOnElement(const Part& part, int element, const Eigen::Vector3d& toward_W);

}  // namespace tubeplan::scene
