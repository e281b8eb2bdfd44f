// `tubeplan plans SCENE [--k N] [--out-dir DIR] [--all] [--speed V] [--tremor A] [--quantum Q]`
// and the exploration's options: the k best start -> goal paths of the pruned contact-state
// graph, each with a minimum-jerk hand trajectory through its witnesses, replayed as `evaluate`
// would; the feasible ones written as plan files (batch::MakePlans, report::PrintPlans).
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <tuple>
#include <variant>

#include <tubeplan/batch/plans.hpp>
#include <tubeplan/report/plans_report.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "graph_options.hpp"

namespace tubeplan::cli {
namespace {

struct PlansOptions {
  GraphOptions graph;
  int k = 3;
  bool all = false;
  std::string out_dir;
  std::string tremor = "0";
  std::string quantum = "0";
  std::string speed = "80 mm/s";
};

// --tremor, --quantum and --speed in SI, each checked; nullopt after saying what is wrong.
std::optional<trajectories::SynthesisOptions> ParseSynthesis(const PlansOptions& o,
                                                             std::ostream& err) {
  double tremor_m = 0.0, quantum_m = 0.0, speed_m_per_s = 0.0;
  for (auto [option, text, dimension, target] :
       {std::tuple{"--tremor", &o.tremor, io::dim::kLength, &tremor_m},
        std::tuple{"--quantum", &o.quantum, io::dim::kLength, &quantum_m},
        std::tuple{"--speed", &o.speed, io::dim::kVelocity, &speed_m_per_s}}) {
    std::string error;
    const auto values = ParseQuantityList(option, *text, 1, 1, dimension, error);
    if (!values) {
      err << "tubeplan plans: error: " << error << "\n";
      return std::nullopt;
    }
    *target = values->front();
  }
  if (tremor_m < 0.0 || tremor_m > 0.005 || quantum_m < 0.0 || quantum_m > 0.005 ||
      !(speed_m_per_s > 0.0 && speed_m_per_s <= 1.0)) {
    err << "tubeplan plans: error: expected --tremor and --quantum between 0 and 5 mm and "
           "--speed above 0 and at most 1 m/s\n";
    return std::nullopt;
  }
  trajectories::SynthesisOptions synthesis;
  synthesis.peak_speed_m_per_s = speed_m_per_s;
  synthesis.tremor_m = tremor_m;
  synthesis.quantum_m = quantum_m;
  synthesis.seed = o.graph.seed;
  return synthesis;
}

int RunPlans(const PlansOptions& o, Streams io) {
  // Quantities first: a typo should not cost an exploration.
  const std::optional<trajectories::SynthesisOptions> synthesis = ParseSynthesis(o, io.err);
  if (!synthesis) return kExitBadInput;
  const batch::PlansRequest request{.scene_path = o.graph.scene_path,
                                    .seed = o.graph.seed,
                                    .k = o.k,
                                    .all = o.all,
                                    .out_dir = o.out_dir,
                                    .synthesis = *synthesis};
  if (!batch::PlanFilesApart(request, io.err)) return kExitBadInput;
  // A goal the tube starts in leaves nothing to plan: said before any exploration.
  std::variant<batch::BuiltGraph, int> built =
      BuildGraph(o.graph, io, [&](const scene::Scene& s) -> std::optional<int> {
        if (batch::StartsInGoal(request, s, io.err)) return kExitNegative;
        return std::nullopt;
      });
  if (const int* code = std::get_if<int>(&built)) return *code;
  const batch::BuiltGraph& b = std::get<batch::BuiltGraph>(built);
  batch::Plans plans;
  switch (
      batch::MakePlans(request, b.scene, b.graph, b.explore.dwell_s, b.weights, plans, io.err)) {
    case batch::PlansEnd::kNothingToPlan:
    case batch::PlansEnd::kGoalNotReached:
      return kExitNegative;
    case batch::PlansEnd::kNotWritten:
      return kExitBadInput;
    case batch::PlansEnd::kWritten:
      break;
  }
  report::PrintPlans(io.out, request, b.scene.name, b.graph, plans);
  return plans.feasible > 0 ? kExitOk : kExitNegative;
}

}  // namespace

Command AddPlansCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<PlansOptions>();
  CLI::App* sub = app.add_subcommand(
      "plans",
      "Build and prune the scene's contact-state graph, then take the k best start -> goal paths, "
      "each with a synthesized (minimum-jerk) operator trajectory, replay each as `evaluate` "
      "would, and write the feasible ones as plan files.");
  sub->add_option("scene", options->graph.scene_path, "scene file (.yaml)")->required();
  sub->add_option("--k", options->k, "how many plans")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  sub->add_option("--out-dir", options->out_dir,
                  "where to write NAME-candidate-I.yaml and .csv (default: SCENE_NAME-plans)");
  sub->add_flag("--all", options->all,
                "also write the candidates whose replay is infeasible (after the feasible ones, "
                "their comment saying why)");
  sub->add_option("--speed", options->speed, "peak hand speed, e.g. \"80 mm/s\"")
      ->capture_default_str();
  sub->add_option("--tremor", options->tremor,
                  "amplitude of 8-12 Hz tremor added to the hand, e.g. \"0.1 mm\" (default none)");
  sub->add_option("--quantum", options->quantum,
                  "round positions to this device resolution, e.g. \"0.03 mm\" (default none)");
  AddGraphOptions(sub, options->graph);
  return {sub, [options, streams] { return RunPlans(*options, streams); }};
}

}  // namespace tubeplan::cli
