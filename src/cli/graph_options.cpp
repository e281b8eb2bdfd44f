#include "graph_options.hpp"

#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <unistd.h>
#include <variant>

#include <tubeplan/batch/graph.hpp>
#include <tubeplan/graph/explore.hpp>

#include "app.hpp"
#include "commands.hpp"

namespace tubeplan::cli {

std::variant<batch::BuiltGraph, int> BuildGraph(
    const GraphOptions& o, Streams io,
    const std::function<std::optional<int>(const scene::Scene&)>& before) {
  batch::GraphRequest request;
  request.scene_path = o.scene_path;
  request.weights = o.weights;
  request.tolerance = o.tolerance;
  request.verdicts_path = o.verdicts_path;
  request.explore.seed = o.seed;
  request.explore.random_motions = o.random;
  request.explore.closing_motions = o.closing;
  request.explore.replay_copies = o.replays;
  request.explore.max_motions = o.budget;
  request.explore.time_limit_s = o.time_limit_s;
  request.explore.jobs = o.jobs;
  // Progress on a terminal only, about once a second, on one line (a log stays clean).
  if (isatty(STDERR_FILENO) != 0) {
    request.explore.status = [&io, path = o.scene_path](const graph::ExploreStatus& st) {
      char line[200];
      std::snprintf(line, sizeof line,
                    "\rexploring %s: %s, %d motions done, %d started; the graph so far %d CFs, "
                    "%d transitions; %.0f s\033[K",
                    path.c_str(), st.phase.c_str(), st.motions_done, st.motions_started, st.nodes,
                    st.arcs, st.seconds);
      io.err << line << std::flush;
    };
  }
  std::optional<int> stopped;
  batch::BuiltGraph built;
  const batch::GraphEnd end = batch::BuildGraph(request, built, io.err, [&](const scene::Scene& s) {
    if (before) stopped = before(s);
    return !stopped;
  });
  switch (end) {
    case batch::GraphEnd::kBadInput:
      return kExitBadInput;
    case batch::GraphEnd::kStopped:
      return *stopped;
    case batch::GraphEnd::kBuilt:
      break;
  }
  if (request.explore.status) io.err << "\r\033[K" << std::flush;
  return built;
}

void AddGraphOptions(CLI::App* sub, GraphOptions& o) {
  sub->add_option("--seed", o.seed, "seed of the random motions")->capture_default_str();
  sub->add_option("--random", o.random,
                  "random motions after the sweeps and aims, before every state found is "
                  "probed with small motions until no new one appears (saturation)")
      ->check(CLI::Range(0, 10000))
      ->capture_default_str();
  sub->add_option("--closing", o.closing,
                  "once every state is probed, rounds of this many more random motions (and "
                  "--replays), each followed by probing what it found, until a round adds no "
                  "state and no transition (0: no random motions in them; docs/graph.md)")
      ->check(CLI::Range(0, 10000))
      ->capture_default_str();
  sub->add_option(
         "--replays", o.replays,
         "after each group of 16 probes and in each closing round, replay this many "
         "copies of each candidate plan's trajectory (as `plans` first tries them from "
         "the graph so far), each moved by up to 4 mm, with tremor and 0.8-1.25x the speed; "
         "the plans' states are probed first (0: none; docs/graph.md)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  sub->add_option("--budget", o.budget,
                  "run at most this many motions in all (a motion: one list of guarded moves of "
                  "the hand from the start pose; docs/graph.md), saturated or not (said in the "
                  "output)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  sub->add_option("--time-limit", o.time_limit_s,
                  "stop exploring this many seconds of wall time after the start, saturated or not "
                  "(said in the output), once the goal state has a stay; until then up to 60 s "
                  "more (0: no limit)")
      ->check(CLI::Range(0.0, 1e7))
      ->capture_default_str();
  sub->add_option("--jobs", o.jobs, "threads (default: the machine's cores)")
      ->check(CLI::Range(1, 256));
  sub->add_option("--weights", o.weights,
                  "heuristic weights over the scene's, e.g. friction=1,energy=1,distance=1");
  sub->add_option("--tolerance", o.tolerance,
                  "keep arcs whose weighted score is within this of the best (scene's default)");
}

}  // namespace tubeplan::cli
