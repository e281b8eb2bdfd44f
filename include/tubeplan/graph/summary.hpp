#pragma once
// What an explored graph holds, counted for its summary (`tubeplan graph`).

#include <map>
#include <string>

#include <tubeplan/graph/contact_graph.hpp>

namespace tubeplan::graph {

struct GraphCounts {
  long kept_arcs = 0;                           ///< kept by pruning
  long simultaneous_arcs = 0;                   ///< changing two PCs at once
  std::map<std::string, int> motions_by_kind;   ///< by the first word of Motion::kind
  long feasible_arcs = 0, infeasible_arcs = 0;  ///< as ApplyVerdicts coloured them
  long replay_nodes = 0, replay_arcs = 0;       ///< seen only in replays (from_replay)
};

GraphCounts CountGraph(const ContactGraph& graph);

}  // namespace tubeplan::graph
