#pragma once
// The contact-state graph built as `tubeplan graph` and `tubeplan plans` do (docs/graph.md): the
// scene loaded, explored with the core, pruned with its heuristic weights or those asked for,
// and, given an evaluate report, coloured by the verdicts of its replays.

#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/verdicts.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::batch {

/// What the graph is asked.
struct GraphRequest {
  std::string scene_path;
  /// How to explore (seed, motions, budget, time limit, progress); jobs <= 0: the machine's
  /// cores.
  graph::ExploreOptions explore;
  /// "friction=1,energy=0.5,distance=2": weights over the scene's (empty: the scene's).
  std::string weights;
  std::optional<double> tolerance;  ///< over the scene's
  std::string verdicts_path;        ///< an evaluate report to colour the arcs by, or empty
};

/// The explored and pruned graph of a scene, with what it was built from.
struct BuiltGraph {
  scene::Scene scene;
  graph::ContactGraph graph;
  graph::ExploreOptions explore;  ///< as explored, without the progress callback
  graph::PruneWeights weights;    ///< as pruned
};

enum class GraphEnd {
  kBuilt,     ///< explored, pruned and (with a report) coloured
  kBadInput,  ///< the scene, the weights, the tolerance or the report: said on `err`
  kStopped,   ///< `go_on` said no
};

/// Loads the scene and checks the request, then explores, prunes and applies the verdicts.
/// `go_on` (may be empty) sees the scene before the exploration and may stop there (false).
GraphEnd BuildGraph(const GraphRequest& request, BuiltGraph& built, std::ostream& err,
                    const std::function<bool(const scene::Scene&)>& go_on = {});

/// The judged plans of an evaluate report (docs/evaluate.md), or nullopt after saying on `err`
/// why not.
std::optional<std::vector<graph::ReplayedPlan>> ReadVerdicts(const std::string& path,
                                                             std::ostream& err);

}  // namespace tubeplan::batch
