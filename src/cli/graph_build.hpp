#pragma once
// Private to the cli library: the options `graph` and `plans` share, and the exploration both
// start from (the scene loaded, explored with the core and pruned).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <variant>

#include <CLI/CLI.hpp>

#include <tubeplan/graph/explore.hpp>
#include <tubeplan/scene/scene.hpp>

#include "commands.hpp"

namespace tubeplan::cli {

struct GraphOptions {
  std::string scene_path;
  std::string dot_path;
  std::string svg_path;  // graph only: the DOT rendered by Graphviz's dot
  std::string json_path;
  bool unpruned = false;
  std::uint64_t seed = 1;
  int random = 120;
  int closing = 30;  // random motions per closing round (plans: none; see plans_command.cpp)
  int budget = 3000;
  double time_limit_s = 0.0;  // 0: none
  int jobs = 0;               // 0: the machine's cores
  std::string weights;
  std::optional<double> tolerance;
  std::string verdicts_path;  // graph only: an evaluate report
  int check = 0;              // graph only: independent random motions measuring completeness
};

/// The explored and pruned graph of a scene, with what it was built from.
struct Built {
  scene::Scene scene;
  graph::ContactGraph graph;
  graph::ExploreOptions explore;
  graph::PruneWeights weights;
};

/// Loads the scene, explores and prunes; on bad input reports and returns the exit code.
/// `before` (may be empty) sees the scene before the exploration and may end the command there
/// with an exit code.
std::variant<Built, int> BuildGraph(
    const GraphOptions& o, Streams io,
    const std::function<std::optional<int>(const scene::Scene&)>& before = {});

/// The exploration's options, shared by `graph` and `plans`.
void AddGraphOptions(CLI::App* sub, GraphOptions& o);

}  // namespace tubeplan::cli
