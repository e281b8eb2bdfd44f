#include <tubeplan/graph/summary.hpp>

namespace tubeplan::graph {

GraphCounts CountGraph(const ContactGraph& graph) {
  GraphCounts c;
  for (const Arc& a : graph.arcs) {
    c.kept_arcs += a.kept;
    c.simultaneous_arcs += a.simultaneous;
    c.feasible_arcs += a.batch == BatchResult::kFeasible;
    c.infeasible_arcs += a.batch == BatchResult::kInfeasible;
    c.replay_arcs += a.from_replay;
  }
  for (const Node& n : graph.nodes) c.replay_nodes += n.from_replay;
  for (const Motion& m : graph.motions) ++c.motions_by_kind[m.kind.substr(0, m.kind.find(' '))];
  return c;
}

}  // namespace tubeplan::graph
