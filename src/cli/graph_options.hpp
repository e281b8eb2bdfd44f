#pragma once
// Private to the cli library: the options `graph` and `plans` share, and the graph both start
// from (batch::BuildGraph: the scene loaded, explored with the core and pruned).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <variant>

#include <CLI/CLI.hpp>

#include <tubeplan/batch/graph.hpp>
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
  int closing = 30;  // random motions per closing round
  int replays = 4;   // perturbed copies of each candidate plan per probe group and closing round
  int budget = 3000;
  double time_limit_s = 10.0;  // 0: none; holds once the goal is reached
  int jobs = 0;                // 0: the machine's cores
  std::string weights;
  std::optional<double> tolerance;
  std::string verdicts_path;  // graph only: an evaluate report
  int check = 0;  // graph only: independent random motions and replays measuring completeness
};

/// batch::BuildGraph with these options, progress shown on a terminal; on bad input the exit
/// code. `before` (may be empty) sees the scene before the exploration and may end the command
/// there with an exit code.
std::variant<batch::BuiltGraph, int> BuildGraph(
    const GraphOptions& o, Streams io,
    const std::function<std::optional<int>(const scene::Scene&)>& before = {});

/// The exploration's options, shared by `graph` and `plans`.
void AddGraphOptions(CLI::App* sub, GraphOptions& o);

}  // namespace tubeplan::cli
