#include <algorithm>
#include <cstdlib>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/graph.hpp>
#include <tubeplan/batch/report.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/verdicts.hpp>
#include <tubeplan/io/scene_yaml.hpp>

#include "io/text_file.hpp"

namespace tubeplan::batch {
namespace {

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

GraphEnd BuildGraph(const GraphRequest& request, BuiltGraph& built, std::ostream& err,
                    const std::function<bool(const scene::Scene&)>& go_on) {
  io::SceneLoadResult loaded = io::LoadSceneFile(request.scene_path);
  err << loaded.diagnostics.FormatAll();
  if (!loaded.scene) return GraphEnd::kBadInput;
  const scene::Scene& s = *loaded.scene;

  graph::PruneWeights weights{s.heuristics.friction, s.heuristics.energy, s.heuristics.distance,
                              s.heuristics.tolerance};
  std::string error;
  if (!request.weights.empty() && !ParseWeights(request.weights, weights, error)) {
    err << "tubeplan graph: error: " << error << "\n";
    return GraphEnd::kBadInput;
  }
  if (request.tolerance) {
    if (!(*request.tolerance >= 0.0)) {
      err << "tubeplan graph: error: --tolerance must be zero or more\n";
      return GraphEnd::kBadInput;
    }
    weights.tolerance = *request.tolerance;
  }
  graph::ExploreOptions explore = request.explore;
  explore.weights = weights;
  if (explore.jobs <= 0)
    explore.jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::optional<std::vector<graph::ReplayedPlan>> verdicts;
  if (!request.verdicts_path.empty()) {
    verdicts = ReadVerdicts(request.verdicts_path, err);
    if (!verdicts) return GraphEnd::kBadInput;
  }
  if (go_on && !go_on(s)) return GraphEnd::kStopped;
  graph::ContactGraph g = graph::Explore(s, explore);
  explore.status = nullptr;
  graph::Prune(g, weights);
  if (verdicts) graph::ApplyVerdicts(g, *verdicts);
  built = BuiltGraph{s, std::move(g), explore, weights};
  return GraphEnd::kBuilt;
}

std::optional<std::vector<graph::ReplayedPlan>> ReadVerdicts(const std::string& path,
                                                             std::ostream& err) {
  const std::optional<std::string> text = io::ReadTextFile(path);
  const nlohmann::json report =
      text ? nlohmann::json::parse(*text, nullptr, false) : nlohmann::json();
  std::vector<graph::ReplayedPlan> plans;
  bool ok = text && !report.is_discarded() && report.is_object() &&
            report.value("tubeplan_evaluate", 0) >= 1 &&
            report.value("tubeplan_evaluate", 0) <= kEvaluateJsonVersion &&
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
        << kEvaluateJsonVersion << ")\n";
    return std::nullopt;
  }
  return plans;
}

}  // namespace tubeplan::batch
