#pragma once
// Batch results on the graph (tubeplan graph --verdicts REPORT): arcs coloured by what plan
// replays found, and the states and transitions replays saw that exploration missed added to the
// graph and marked (the paper: "missing contact states can be added").

#include <string>
#include <vector>

#include <tubeplan/graph/contact_graph.hpp>

namespace tubeplan::graph {

/// One judged plan, as the evaluate report gives it.
struct ReplayedPlan {
  struct Transition {
    std::string from, to;
    bool feasible = false;  ///< feasible or feasible with a detour
    double t_start_s = 0.0, t_end_s = 0.0;
  };
  std::vector<Transition> transitions;
  std::vector<std::pair<double, std::string>> observed;  ///< (entry time, CF), in order
};

/// Adds the observed states and consecutive-state transitions the graph lacks (marked
/// from_replay), then colours arcs: kFeasible when a replay went along it within a feasible
/// planned transition, else kInfeasible when it is a planned transition judged infeasible or a
/// replay went along it within one; kUntried otherwise. Returns how many nodes were added.
int ApplyVerdicts(ContactGraph& graph, const std::vector<ReplayedPlan>& plans);

}  // namespace tubeplan::graph
