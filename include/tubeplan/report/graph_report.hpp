#pragma once
// The contact-state graph as `tubeplan graph` prints it (docs/graph.md): what was found, the
// saturation curve, start, goal and the part elements reached, and, when asked, what an evaluate
// report's verdicts did to it and how complete it is.

#include <optional>
#include <ostream>
#include <span>
#include <string>

#include <tubeplan/graph/completeness.hpp>
#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::report {

/// The files `tubeplan graph` writes; an empty path: not asked for.
struct GraphFiles {
  std::string dot_path;
  std::string svg_path;  ///< the DOT drawn by Graphviz's dot
  std::string json_path;
};

/// The graph of `scene` (read from `scene_path`), explored with `explore` and pruned: states,
/// transitions, motions by kind and the work done; the saturation curve and whether, or why not,
/// it saturated; start, goal and the part elements never touched. Then the verdicts' counts (when
/// `verdicts_path`, the evaluate report they came from, is not empty), the completeness measured
/// (when given) and the files written.
void PrintGraph(std::ostream& out, const std::string& scene_path, const scene::Scene& scene,
                const graph::ContactGraph& graph, const graph::ExploreOptions& explore,
                const std::string& verdicts_path, std::span<const graph::Completeness> completeness,
                const GraphFiles& written);

}  // namespace tubeplan::report
