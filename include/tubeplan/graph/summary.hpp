#pragma once
// What an explored graph holds, counted for its summary (`tubeplan graph`).

#include <map>
#include <string>
#include <vector>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::graph {

struct GraphCounts {
  long kept_arcs = 0;                           ///< kept by pruning
  long simultaneous_arcs = 0;                   ///< changing two PCs at once
  std::map<std::string, int> motions_by_kind;   ///< by the first word of Motion::kind
  long feasible_arcs = 0, infeasible_arcs = 0;  ///< as ApplyVerdicts coloured them
  long replay_nodes = 0, replay_arcs = 0;       ///< seen only in replays (from_replay)
};

GraphCounts CountGraph(const ContactGraph& graph);

/// The states nearest a goal the graph never reached, for the user to compare with it: those with
/// the goal's contacts (the same tube and part elements) under other markers; if none, those
/// touching every part element the goal names. By least operator force, at most `most`.
std::vector<int> NearGoal(const ContactGraph& graph, const states::ContactFormation& goal,
                          std::size_t most);
/// NearGoal's states as text, "{...} (0.107 N), {...} (0.19 N)"; empty if there are none.
std::string NearGoalText(const ContactGraph& graph, const states::ContactFormation& goal,
                         std::size_t most);

}  // namespace tubeplan::graph
