// `tubeplan evaluate PLAN|DIR... [--jobs N] [--json] [--report FILE]`: replays every plan's
// trajectory through the core and gives each planned transition a verdict (docs/evaluate.md).
// All plan files are read and checked first; any problem in any of them is reported and nothing
// is evaluated (exit 2).
#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/evaluation.hpp>
#include <tubeplan/report/evaluation_report.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

struct EvaluateOptions {
  std::vector<std::string> inputs;
  int jobs = 0;
  bool json = false;
  std::string report_path;
  std::string shard;        // "I/N", empty: all
  std::string html_path;    // the HTML report (docs/report.md)
  bool html_graph = false;  // with the contact-state graph (an exploration per scene, ~5 s)
  int monte_carlo = 0;
  std::uint64_t seed = 1;
};

int RunEvaluate(const EvaluateOptions& o, Streams io) {
  const batch::EvaluationRequest request{.inputs = o.inputs,
                                         .shard = o.shard,
                                         .jobs = o.jobs,
                                         .monte_carlo = o.monte_carlo,
                                         .seed = o.seed,
                                         .report_path = o.report_path,
                                         .html_path = o.html_path,
                                         .progress = isatty(STDERR_FILENO) != 0 && !o.json};
  batch::Evaluation evaluation;
  if (!batch::LoadEvaluation(request, evaluation, io.err)) return kExitBadInput;
  if (const std::string e = report::HtmlToolsMissing(!o.html_path.empty(), o.html_graph);
      !e.empty()) {
    io.err << "tubeplan evaluate: error: " << e << "\n";
    return kExitBadInput;
  }
  // With --html each judged replay is recorded as it runs (no second replay).
  std::vector<report::ReplayRecorder> recorders(o.html_path.empty() ? 0
                                                                    : evaluation.set.files.size());
  std::function<plan::TickWatcher(std::size_t)> watch;
  if (!recorders.empty())
    watch = [&](std::size_t i) { return plan::TickWatcher(std::ref(recorders[i])); };
  switch (batch::JudgeEvaluation(request, evaluation, watch, io.err)) {
    case batch::JudgedEnd::kChanged:
      return kExitBadInput;
    case batch::JudgedEnd::kInterrupted:
      return kExitInterrupted;
    case batch::JudgedEnd::kAll:
      break;
  }
  const std::vector<batch::Evaluated>& results = evaluation.judged.results;
  const nlohmann::json report = batch::ToJson(results, batch::ScopeOf(evaluation.set));
  std::vector<std::pair<std::string, std::string>> outputs;
  if (!o.report_path.empty()) outputs.emplace_back(o.report_path, report.dump(1) + "\n");
  if (!o.html_path.empty()) {
    std::string command = "tubeplan evaluate";
    for (const std::string& f : o.inputs) command += " " + f;
    command += " --html " + o.html_path + (o.html_graph ? " --html-graph" : "");
    std::string error;
    std::optional<std::string> page = report::FormatEvaluationHtml(
        command, results, evaluation.loaded, evaluation.jobs, o.html_graph, recorders, error);
    if (!page) {
      io.err << "tubeplan evaluate: error: --html-graph: " << error << "\n";
      return kExitBadInput;
    }
    outputs.emplace_back(o.html_path, std::move(*page));
  }
  if (const std::string e = io::WriteFilesTogether(outputs); !e.empty()) {
    io.err << e << "\n";
    return kExitBadInput;
  }
  const bool all_feasible =
      std::all_of(results.begin(), results.end(),
                  [](const batch::Evaluated& e) { return e.judgement.feasible; });
  if (o.json)
    io.out << report.dump(2) << "\n";
  else
    report::PrintEvaluation(io.out, results, evaluation.judged.wall_s, evaluation.jobs,
                            o.report_path, o.html_path, isatty(STDOUT_FILENO) != 0);
  return all_feasible ? kExitOk : kExitNegative;
}

}  // namespace

Command AddEvaluateCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<EvaluateOptions>();
  CLI::App* sub = app.add_subcommand(
      "evaluate",
      "Replay plans through the core and judge every planned transition: feasible, feasible "
      "with a detour, or infeasible with the reason. Exit 0 if all plans are feasible, 1 if not.");
  sub->add_option("plans", options->inputs, "plan files (.yaml) or directories of them")
      ->required();
  sub->add_option("--jobs", options->jobs, "threads (default: the machine's cores)")
      ->check(CLI::Range(1, 256));
  sub->add_flag("--json", options->json, "print the report as one JSON document");
  sub->add_option("--report", options->report_path, "also write the JSON report to FILE");
  sub->add_option("--html", options->html_path,
                  "also write an HTML report to FILE: verdicts, CF timeline, force/friction/"
                  "energy/strain plots and a 3D replay, self-contained (docs/report.md)");
  sub->add_flag("--html-graph", options->html_graph,
                "with --html: also explore each scene's contact-state graph with the core (about "
                "5 s a scene) and draw it with this run's verdicts (Graphviz dot)");
  sub->add_option("--monte-carlo", options->monte_carlo,
                  "also replay each plan N times with perturbed trajectories (offset within 1 mm, "
                  "0.1 mm 8-12 Hz tremor, 0.8-1.25x speed) and report each transition's feasible "
                  "fraction with a 95 % interval")
      ->check(CLI::Range(0, 100000));
  sub->add_option("--seed", options->seed, "seed of the Monte-Carlo perturbations")
      ->capture_default_str();
  sub->add_option("--shard", options->shard,
                  "evaluate only shard I of N (I/N) of the plans in file order; join the shards' "
                  "reports with `tubeplan merge`");
  return {sub, [options, streams] { return RunEvaluate(*options, streams); }};
}

}  // namespace tubeplan::cli
