#pragma once
// The contact-state graph in Graphviz DOT (written with Boost.Graph's write_graphviz): nodes
// labelled in the paper's notation with HTML-like labels (F&#771; for a bent element, the arcs
// &#8995; / &#8994; for concave / convex), start and goal marked, kept arcs solid orange, dropped
// arcs dashed grey and labelled with why they were dropped; after ApplyVerdicts, arcs batch
// replays went along green (feasible) or red (infeasible), states only replays saw dashed red.
// Renders with `dot -Tsvg`.

#include <string>

#include <tubeplan/graph/contact_graph.hpp>

namespace tubeplan::graph {

struct DotOptions {
  /// false: the pruned graph: kept arcs only, between the nodes a plan can pass through (reached
  /// from the start and reaching the goal along kept arcs).
  bool dropped_arcs = true;
  std::string title;  ///< graph label, e.g. the scene's name
};

std::string FormatDot(const ContactGraph& graph, const DotOptions& options);

/// One PC or CF in the paper's notation as a Graphviz HTML-like label fragment.
std::string PaperNotation(const std::string& cf_text);

}  // namespace tubeplan::graph
