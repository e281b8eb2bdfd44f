#pragma once
// The contact-state graph as JSON (schema in docs/graph.md): what `graph --json` writes.

#include <string>

#include <nlohmann/json.hpp>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::report {

inline constexpr int kGraphJsonVersion = 2;

/// The graph, pruned as `weights` say, with the moves of every motion a node's or an arc's
/// witness lies in (the others are listed by kind only).
nlohmann::json GraphToJson(const graph::ContactGraph& graph, const scene::Scene& scene,
                           const std::string& scene_path, const graph::ExploreOptions& explore,
                           const graph::PruneWeights& weights);

}  // namespace tubeplan::report
