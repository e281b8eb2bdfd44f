#pragma once
// How complete an explored graph is, measured (docs/graph.md, "Completeness"): motions the
// explorer did not make (random guarded motions and perturbed replays of the candidate plans, of
// another seed) are run through the core, their states counted after the same dwell as the
// explorer's, and what they reach that the graph lacks is listed.

#include <span>
#include <string>
#include <utility>
#include <vector>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/motion.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::graph {

struct Completeness {
  std::string motions_of;  ///< what the motions were, e.g. "random guarded motions"
  int motions = 0;
  long states_seen = 0, states_in_graph = 0;
  long transitions_seen = 0, transitions_in_graph = 0;
  /// By use: ticks spent in states the graph has, of all; transitions taken that it has (a
  /// transition taken five times counts five), of all.
  long ticks = 0, ticks_in_graph = 0, taken = 0, taken_in_graph = 0;
  std::vector<std::string> missing_states;
  /// Each with how often the motions took it.
  std::vector<std::pair<std::pair<std::string, std::string>, int>> missing_transitions;
};

/// Runs each of `motions` through a core from the scene's start (each ends where the operator
/// force passes `force_limit_N` or the coupling reaches the device's force, as the explorer's
/// do), counts a state once the core has kept it `dwell_s`, and compares the states and
/// transitions counted with `graph`'s. A transition that changes two PCs at once is in the graph
/// when it records the change through a state between.
Completeness CheckCompleteness(const scene::Scene& scene, const ContactGraph& graph,
                               std::span<const Motion> motions, double dwell_s,
                               double force_limit_N);

/// The same over motions the explorer did not make, counted after its dwell: `count` random
/// guarded motions of another seed (RandomMotions from explore.seed + 1000003), then about
/// `count` perturbed replays of the candidate plans of `graph` (PerturbedReplays from that seed
/// of CandidateTrajectories, as many copies of each as make `count`; none without a path to the
/// goal).
std::vector<Completeness> CheckCompleteness(const scene::Scene& scene, const ContactGraph& graph,
                                            const ExploreOptions& explore, int count);

}  // namespace tubeplan::graph
