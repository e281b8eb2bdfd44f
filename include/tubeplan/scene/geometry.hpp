#pragma once
// Geometry a scene is checked with before anything runs on it (io/scene_yaml.cpp): parts that
// overlap each other, and parts that reach into the tube at its start.

#include <cstddef>
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

}  // namespace tubeplan::scene
