#pragma once
// The candidate plans as `tubeplan plans` prints them (docs/graph.md, "Candidate plans"): how
// many, through which graph and where written, then a line for each candidate.

#include <ostream>
#include <string>

#include <tubeplan/batch/plans.hpp>
#include <tubeplan/graph/contact_graph.hpp>

namespace tubeplan::report {

/// The header (the candidates of how many asked, through the pruned `graph` of the scene named
/// `scene_name`, how many feasible, written where), each candidate's name (or "(not written)"),
/// cost, length, states and verdict, and what to try when none is feasible.
void PrintPlans(std::ostream& out, const batch::PlansRequest& request,
                const std::string& scene_name, const graph::ContactGraph& graph,
                const batch::Plans& plans);

}  // namespace tubeplan::report
