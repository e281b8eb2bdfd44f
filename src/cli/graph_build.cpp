#include "graph_build.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <unistd.h>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/report.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/verdicts.hpp>
#include <tubeplan/io/scene_yaml.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

// The judged plans of an evaluate report (docs/evaluate.md), or nullopt after reporting why not.
std::optional<std::vector<graph::ReplayedPlan>> ReadVerdicts(const std::string& path,
                                                             std::ostream& err) {
  const std::optional<std::string> text = io::ReadTextFile(path);
  const nlohmann::json report =
      text ? nlohmann::json::parse(*text, nullptr, false) : nlohmann::json();
  std::vector<graph::ReplayedPlan> plans;
  bool ok = text && !report.is_discarded() && report.is_object() &&
            report.value("tubeplan_evaluate", 0) >= 1 &&
            report.value("tubeplan_evaluate", 0) <= batch::kEvaluateJsonVersion &&
            report.contains("plans") && report["plans"].is_array();
  for (std::size_t i = 0; ok && i < report["plans"].size(); ++i) {
    const nlohmann::json& p = report["plans"][i];
    graph::ReplayedPlan r;
    ok = p.is_object() && p.contains("transitions") && p["transitions"].is_array() &&
         p.contains("observed") && p["observed"].is_array();
    for (std::size_t k = 0; ok && k < p["transitions"].size(); ++k) {
      const nlohmann::json& t = p["transitions"][k];
      ok = t.is_object() && t.value("from", nlohmann::json()).is_string() &&
           t.value("to", nlohmann::json()).is_string() &&
           t.value("verdict", nlohmann::json()).is_string() &&
           (t.value("t_start_s", nlohmann::json()).is_number() ||
            t.value("t_start_s", nlohmann::json(0)).is_null()) &&
           (t.value("t_end_s", nlohmann::json()).is_number() ||
            t.value("t_end_s", nlohmann::json(0)).is_null());
      // A transition the replay never got to has no span (null times): no step falls in it.
      // One a live run did not finish is no verdict on the arcs.
      if (ok && t["verdict"] != "not judged")
        r.transitions.push_back({t["from"], t["to"], t["verdict"] != "infeasible",
                                 t["t_start_s"].is_null() ? 0.0 : t["t_start_s"].get<double>(),
                                 t["t_end_s"].is_null() ? 0.0 : t["t_end_s"].get<double>()});
    }
    for (std::size_t k = 0; ok && k < p["observed"].size(); ++k) {
      const nlohmann::json& o = p["observed"][k];
      ok = o.is_object() && o.value("t", nlohmann::json()).is_number() &&
           o.value("cf", nlohmann::json()).is_string();
      if (ok) r.observed.push_back({o["t"].get<double>(), o["cf"].get<std::string>()});
    }
    plans.push_back(std::move(r));
  }
  if (!ok) {
    err << path
        << ": error: not a readable tubeplan evaluate report, expected the JSON that "
           "`tubeplan evaluate --report` writes (version 1 to "
        << batch::kEvaluateJsonVersion << ")\n";
    return std::nullopt;
  }
  return plans;
}

// "friction=1,energy=0.5,distance=2" over the scene's weights.
bool ParseWeights(const std::string& text, graph::PruneWeights& w, std::string& error) {
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    const std::size_t eq = item.find('=');
    double* target = nullptr;
    const std::string key = item.substr(0, eq);
    if (key == "friction") target = &w.friction;
    if (key == "energy") target = &w.energy;
    if (key == "distance") target = &w.distance;
    char* end = nullptr;
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    const double v = value.empty() ? -1.0 : std::strtod(value.c_str(), &end);
    if (target == nullptr || value.empty() || *end != '\0' || !(v >= 0.0 && v <= 1e6)) {
      error = "--weights: \"" + item +
              "\" is not a weight, expected name=value with name friction, energy or distance "
              "and a value between 0 and 1e6, e.g. friction=1,energy=1,distance=1";
      return false;
    }
    *target = v;
    start = comma + 1;
  }
  return true;
}

}  // namespace

std::variant<Built, int> BuildGraph(
    const GraphOptions& o, Streams io,
    const std::function<std::optional<int>(const scene::Scene&)>& before) {
  io::SceneLoadResult loaded = io::LoadSceneFile(o.scene_path);
  io.err << loaded.diagnostics.FormatAll();
  if (!loaded.scene) return kExitBadInput;
  const scene::Scene& s = *loaded.scene;

  graph::PruneWeights weights{s.heuristics.friction, s.heuristics.energy, s.heuristics.distance,
                              s.heuristics.tolerance};
  std::string error;
  if (!o.weights.empty() && !ParseWeights(o.weights, weights, error)) {
    io.err << "tubeplan graph: error: " << error << "\n";
    return kExitBadInput;
  }
  if (o.tolerance) {
    if (!(*o.tolerance >= 0.0)) {
      io.err << "tubeplan graph: error: --tolerance must be zero or more\n";
      return kExitBadInput;
    }
    weights.tolerance = *o.tolerance;
  }
  graph::ExploreOptions explore;
  explore.seed = o.seed;
  explore.random_motions = o.random;
  explore.closing_motions = o.closing;
  explore.max_motions = o.budget;
  explore.time_limit_s = o.time_limit_s;
  explore.jobs = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
  // Progress on a terminal only, about once a second, on one line (a log stays clean).
  if (isatty(STDERR_FILENO) != 0) {
    explore.status = [&io, path = o.scene_path](const graph::ExploreStatus& st) {
      char line[200];
      std::snprintf(line, sizeof line,
                    "\rexploring %s: %s, %d motions done, %d started; the graph so far %d CFs, "
                    "%d transitions; %.0f s\033[K",
                    path.c_str(), st.phase.c_str(), st.motions_done, st.motions_started, st.nodes,
                    st.arcs, st.seconds);
      io.err << line << std::flush;
    };
  }
  std::optional<std::vector<graph::ReplayedPlan>> verdicts;
  if (!o.verdicts_path.empty()) {
    verdicts = ReadVerdicts(o.verdicts_path, io.err);
    if (!verdicts) return kExitBadInput;
  }
  if (before)
    if (const std::optional<int> code = before(s)) return *code;
  graph::ContactGraph g = graph::Explore(s, explore);
  if (explore.status) io.err << "\r\033[K" << std::flush;
  explore.status = nullptr;
  graph::Prune(g, weights);
  if (verdicts) graph::ApplyVerdicts(g, *verdicts);
  return Built{s, std::move(g), explore, weights};
}

void AddGraphOptions(CLI::App* sub, GraphOptions& o) {
  sub->add_option("--seed", o.seed, "seed of the random motions")->capture_default_str();
  sub->add_option("--random", o.random,
                  "random motions after the sweeps and aims, before every state found is "
                  "probed with small motions until no new one appears (saturation)")
      ->check(CLI::Range(0, 10000))
      ->capture_default_str();
  sub->add_option("--closing", o.closing,
                  "once every state is probed, rounds of this many more random motions, each "
                  "followed by probing what it found, until a round adds no state and no "
                  "transition (0: none; docs/graph.md)")
      ->check(CLI::Range(0, 10000))
      ->capture_default_str();
  sub->add_option("--budget", o.budget,
                  "run at most this many motions in all (a motion: one list of guarded moves of "
                  "the hand from the start pose; docs/graph.md), saturated or not (said in the "
                  "output)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  sub->add_option("--time-limit", o.time_limit_s,
                  "stop exploring after this many seconds of wall time, saturated or not (said in "
                  "the output; default: no limit)")
      ->check(CLI::Range(0.001, 1e7));
  sub->add_option("--jobs", o.jobs, "threads (default: the machine's cores)")
      ->check(CLI::Range(1, 256));
  sub->add_option("--weights", o.weights,
                  "heuristic weights over the scene's, e.g. friction=1,energy=1,distance=1");
  sub->add_option("--tolerance", o.tolerance,
                  "keep arcs whose weighted score is within this of the best (scene's default)");
}

}  // namespace tubeplan::cli
