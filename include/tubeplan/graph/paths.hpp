#pragma once
// Candidate plans: the k cheapest start -> goal paths through the kept arcs of a pruned graph
// (Yen's algorithm over Boost.Graph's Dijkstra). The cost of an arc is 1 + its heuristic score
// above the cheapest kept arc's, so every transition costs at least one (shorter plans first)
// and the heuristics order plans of the same length.

#include <array>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::graph {

struct Path {
  std::vector<int> nodes;  ///< node indices, start first, goal last
  double cost = 0.0;
};

/// Cost of each arc (indexed like graph.arcs) as described above; dropped arcs get +infinity.
std::vector<double> ArcCosts(const ContactGraph& graph, const PruneWeights& weights);

/// Up to k loopless paths from graph.start to graph.goal over arcs of finite cost, cheapest
/// first (ties: the lexicographically smaller node sequence), none when there is no goal.
std::vector<Path> KShortestPaths(const ContactGraph& graph, const std::vector<double>& arc_cost,
                                 int k);

/// Where a candidate plan aims the hand at each state of its path.
enum class Aim : unsigned char {
  kHand,        ///< the hand's pose at the state's witness
  kHeld,        ///< the held end's pose there (the hand no longer pulling the coupling out)
  kLeastForce,  ///< the held end's pose at the state's stay of least operator force
  /// As kLeastForce, and where the tube's end first meets a part (a state with an end PC after
  /// one without), the hand first goes to that pose drawn back along the held end's axis by the
  /// tube's radius and the contact threshold, then straight in: the end arrives along the tube.
  kAlongAxis,
  /// As kAlongAxis, and where the pose of the path's first state after the start is lower than
  /// the start, the hand goes first over it at the start's height, then down (to the pose, or
  /// to kAlongAxis's pose drawn back along the tube): a reach from the start that would cut
  /// through a part's rim on its slant (into a pocket beside the start) goes round it.
  kOver,
};

/// The hand's poses along a path: the scene's start, then one pose per later state as `aim`
/// says, more where kAlongAxis draws the hand back first or kOver goes over the first state
/// (kLeastForce, kAlongAxis and kOver fall back to kHeld's pose for a state with no stay of
/// measured force). A candidate plan's trajectory goes through them.
std::vector<Eigen::Isometry3d> PathWaypoints(const scene::Scene& scene, const ContactGraph& graph,
                                             const Path& path, Aim aim);

/// The aims the explorer's and the completeness check's replays of the candidate plans take.
inline constexpr std::array<Aim, 3> kReplayAims = {Aim::kHand, Aim::kHeld, Aim::kLeastForce};
/// The aims a candidate plan tries (`plans`) at each speed: those, then the end brought in along
/// the tube, for a reach that would slant onto a part, and, where none of those holds, that with
/// the first reach going over the parts, for one that would cut through a part's rim.
inline constexpr std::array<Aim, 5> kPlanAims = {Aim::kHand, Aim::kHeld, Aim::kLeastForce,
                                                 Aim::kAlongAxis, Aim::kOver};

/// The path's waypoints for each of `aims`, in that order, each distinct list once (an aim whose
/// poses equal an earlier one's is left out).
std::vector<std::pair<Aim, std::vector<Eigen::Isometry3d>>> DistinctAims(const scene::Scene& scene,
                                                                         const ContactGraph& graph,
                                                                         const Path& path,
                                                                         std::span<const Aim> aims);

/// Whether two lists of poses are the same, bit for bit (two aims that coincide).
bool SamePoses(std::span<const Eigen::Isometry3d> a, std::span<const Eigen::Isometry3d> b);

}  // namespace tubeplan::graph
