#pragma once
// Geometry a scene is checked with before anything runs on it (io/scene_yaml.cpp): parts that
// overlap each other, and parts that reach into the tube at its start.

#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include <tubeplan/scene/scene.hpp>

namespace tubeplan::scene {

/// Separating-axis test of two oriented boxes: true when they share a volume thicker than
/// `tolerance_m` along every axis (boxes that only touch do not overlap).
bool BoxesOverlap(const BoxPart& a, const BoxPart& b, double tolerance_m);

/// Every pair {later, earlier} of overlapping parts (BoxesOverlap), sorted by the later part's
/// index, then the earlier's. Only parts whose bounding boxes meet are compared (FCL's dynamic
/// AABB tree): time grows as n log n with n parts spread in space, memory as n.
std::vector<std::pair<std::size_t, std::size_t>> OverlappingParts(std::span<const BoxPart> parts,
                                                                  double tolerance_m);

/// How deep `part` reaches into the straight tube held at X_WH: the flat-ended cylinder of
/// `radius_m` along the held frame's +z from its origin (the held end) to `length_m` (the tip).
/// The depth is the radius less the distance from the tube's axis to the part's piece between
/// the ends' planes (the radius itself when the part crosses the axis); nullopt when the part
/// does not reach into the tube by more than `tolerance_m`, sideways or past an end's plane. Exact:
/// the piece is a convex polygon when seen along the axis, and its distance to the axis is a
/// point-polygon distance.
std::optional<double> StraightTubeOverlap(const Eigen::Isometry3d& X_WH, double radius_m,
                                          double length_m, const BoxPart& part, double tolerance_m);

}  // namespace tubeplan::scene
