#pragma once
// The explorer's motions, each a list of guarded moves of the hand from the scene's start pose:
// sweeps across the parts, aims at their elements (and at the goal's as a whole), random
// motions, and a node's neighbour probes (docs/graph.md, "Building"). Internal to the explorer
// (src/graph/explore.cpp).

#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Geometry>

#include <tubeplan/core/core.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/motion.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::graph::explorer {

// The world-aligned box around a set of parts.
struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
};

// The box around the given parts (indices into scene.parts).
Box PartsBox(const scene::Scene& scene, const std::vector<std::uint32_t>& parts);

// Whether element e (an index into probe's elements) is covered: its outside, at its point
// facing the start, lies inside another part (a box's bottom on the floor), so nothing touches it.
bool Covered(const scene::Scene& scene, const core::Core& probe, int e);

// The sweeps across the parts' box: the tube level and tipped down, a tube radius apart.
std::vector<Motion> Sweeps(const scene::Scene& scene, const Box& box, const ExploreOptions& o);

// One motion bringing the tube's tip, and one its side, against each of `elements` (indices into
// probe's elements), where a pose clear of every part starts it.
std::vector<Motion> Aims(const scene::Scene& scene, core::Core& probe,
                         const std::vector<int>& elements, const ExploreOptions& o);

// The aim at a goal of two or more PCs as a whole: brought in along the goal faces' normals, else
// slid in along the tube's axis (none for a goal of one PC, or where no pose fits).
std::vector<Motion> GoalAims(const scene::Scene& scene, core::Core& probe, const ExploreOptions& o);

// Random motions [first, first + count) of the seed across the box.
std::vector<Motion> RandomMotionsIn(const scene::Scene& scene, const Box& box, std::uint64_t seed,
                                    int first, int count, const ExploreOptions& o);

// The neighbour probes of a node (docs/contact-states.md: one small motion of the held end takes
// a CF to its neighbour): from the hand pose of its witness, the hand moves by `step` along and
// against each of the start frame's three directions, tips the tube down and up and turns it
// left and right by `turn` about the hand; after each it holds still for longer than the dwell
// (so the state there counts), goes back and holds again. Each step out stops where the
// operator force passes the explorer's limit (ExploreForceLimit).
std::vector<Move> Probes(const scene::Scene& scene, const Eigen::Isometry3d& X_W_hand,
                         const ExploreOptions& o);

}  // namespace tubeplan::graph::explorer
