// `tubeplan evaluate PLAN|DIR... [--jobs N] [--json] [--report FILE]`: replays every plan's
// trajectory through the core and gives each planned transition a verdict (docs/evaluate.md).
// All plan files are read and checked first; any problem in any of them is reported and nothing
// is evaluated (exit 2).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/evaluate.hpp>
#include <tubeplan/batch/merge.hpp>
#include <tubeplan/batch/report.hpp>
#include <tubeplan/graph/dot.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/verdicts.hpp>
#include <tubeplan/io/interrupt.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/report/graphviz.hpp>
#include <tubeplan/report/html_report.hpp>
#include <tubeplan/report/text_report.hpp>

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

// The graph section of the HTML report: each scene's pruned contact-state graph, explored with the
// core as `tubeplan graph SCENE` does (same defaults), coloured by this run's verdicts, drawn by
// Graphviz's dot. On failure returns false after saying why on `err`.
bool GraphSections(const std::vector<batch::Evaluated>& results,
                   const std::vector<io::PlanLoadResult>& loaded, int jobs,
                   report::HtmlOptions& html, std::ostream& err) {
  std::map<std::string, std::vector<std::size_t>> by_scene;  // scene path -> plans
  for (std::size_t i = 0; i < results.size(); ++i) {
    std::error_code ec;
    const std::filesystem::path scene =
        std::filesystem::path(results[i].file).parent_path() / loaded[i].plan->scene;
    by_scene[std::filesystem::weakly_canonical(scene, ec).string()].push_back(i);
  }
  for (const auto& [scene_path, members] : by_scene) {
    const scene::Scene& s = *loaded[members.front()].scene;
    graph::ExploreOptions explore;
    explore.jobs = jobs;
    // The picture of the states, as `plans` explores: probing, without the closing rounds.
    explore.closing_motions = 0;
    graph::ContactGraph g = graph::Explore(s, explore);
    graph::Prune(g, {s.heuristics.friction, s.heuristics.energy, s.heuristics.distance,
                     s.heuristics.tolerance});
    std::vector<graph::ReplayedPlan> replayed;
    for (const std::size_t i : members) {
      graph::ReplayedPlan r;
      for (const plan::TransitionVerdict& v : results[i].judgement.transitions)
        if (v.verdict != plan::Verdict::kNotJudged)
          r.transitions.push_back(
              {v.from, v.to, plan::IsFeasible(v.verdict), v.t_start_s, v.t_end_s});
      for (const plan::Observation& ob : results[i].judgement.observed)
        r.observed.push_back({ob.t_s, ob.cf});
      replayed.push_back(std::move(r));
    }
    graph::ApplyVerdicts(g, replayed);
    graph::DotOptions dot;
    dot.dropped_arcs = false;
    dot.title = "tubeplan: contact-state graph of " + s.name + " with this run's verdicts";
    const report::SvgFromDot svg = report::RenderDot(graph::FormatDot(g, dot));
    if (!svg.error.empty()) {
      err << "tubeplan evaluate: error: --html-graph: " << svg.error << "\n";
      return false;
    }
    char what[160];
    std::snprintf(what, sizeof what, " (%zu CFs, %zu transitions, explored in %.1f s)",
                  g.nodes.size(), g.arcs.size(), g.seconds);
    std::error_code ec;
    const std::filesystem::path shown = std::filesystem::relative(scene_path, ec);
    html.graphs.push_back({(ec || shown.empty() ? scene_path : shown.string()) + what, svg.svg});
  }
  return true;
}

// Reads every plan of the set `o.inputs` names (this shard of it), and checks that no output
// replaces an input. False after printing every problem found (nothing is evaluated then).
bool LoadPlans(const EvaluateOptions& o, std::ostream& err, batch::PlanSet& set,
               std::vector<io::PlanLoadResult>& loaded) {
  std::vector<std::string> errors;
  set = batch::CollectPlanSet(o.inputs, errors);
  for (const std::string& e : errors) err << e << "\n";
  bool ok = errors.empty();
  if (!o.shard.empty()) {
    std::string error;
    if (!batch::SelectShard(o.shard, set, error)) {
      err << "tubeplan evaluate: error: " << error << "\n";
      return false;
    }
  }
  const std::vector<std::string>& files = set.files;
  // Every plan named is an input an output must not replace, in this shard or another.
  std::vector<io::RolePath> inputs;
  for (const std::string& f : files) inputs.push_back({"the plan", f});
  for (const std::string& f : files) {
    // Monte Carlo perturbs the trajectory and needs its samples; otherwise the trajectory is
    // checked streamed and replayed from its file row by row (docs/hardening.md).
    loaded.push_back(io::LoadPlanFile(f, {.trajectory_in_memory = o.monte_carlo > 0}));
    err << loaded.back().diagnostics.FormatAll();
    ok = ok && loaded.back().plan.has_value();
  }
  if (!ok) return false;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::filesystem::path directory = std::filesystem::path(files[i]).parent_path();
    inputs.push_back({"the scene of " + files[i], directory / loaded[i].plan->scene});
    inputs.push_back({"the trajectory of " + files[i], directory / loaded[i].plan->trajectory});
  }
  return OutputsApart("evaluate", {{"--report", o.report_path}, {"--html", o.html_path}}, inputs,
                      err);
}

// The HTML report's tools, checked before the replays: a missing `dot` should not cost a batch.
// False after saying what is missing.
bool HtmlToolsPresent(const EvaluateOptions& o, std::ostream& err) {
  if (!o.html_path.empty() && !report::HtmlReportAvailable()) {
    err << "tubeplan evaluate: error: --html: this tubeplan was built without the HTML report "
           "(node was not found when it was configured, or TUBEPLAN_HTML_REPORT was off); "
           "install nodejs and npm (tools/setup does) and build again\n";
    return false;
  }
  if (o.html_graph) {
    if (o.html_path.empty()) {
      err << "tubeplan evaluate: error: --html-graph needs --html FILE\n";
      return false;
    }
    if (const report::SvgFromDot probe = report::RenderDot("digraph{}"); !probe.error.empty()) {
      err << "tubeplan evaluate: error: --html-graph: " << probe.error << "\n";
      return false;
    }
  }
  return true;
}

// Judges every plan on `jobs` threads, each judged replay into its recorder when there are
// recorders (--html); one short line per plan on a terminal only (a log stays clean).
batch::BatchResult JudgePlans(const EvaluateOptions& o, const std::vector<std::string>& files,
                              const std::vector<io::PlanLoadResult>& loaded, int jobs,
                              std::vector<report::ReplayRecorder>& recorders, std::ostream& err) {
  const bool progress = isatty(STDERR_FILENO) != 0 && !o.json;
  batch::BatchOptions batch_options;
  batch_options.jobs = jobs;
  batch_options.monte_carlo = o.monte_carlo;
  batch_options.seed = o.seed;
  if (!recorders.empty())
    batch_options.watch = [&](std::size_t i) { return plan::TickWatcher(std::ref(recorders[i])); };
  if (progress)
    batch_options.judged = [&](std::size_t done) {
      err << "\r[" + std::to_string(done) + "/" + std::to_string(files.size()) + "]" << std::flush;
    };
  batch::BatchResult judged = batch::JudgeBatch(files, loaded, batch_options);
  if (progress) err << "\r";
  return judged;
}

// kExitOk when every plan was judged; else, after saying why no report is written, the exit code.
int CheckAllJudged(const EvaluateOptions& o, const batch::BatchResult& judged,
                   std::size_t plan_count, std::ostream& err) {
  if (!judged.changed.empty()) {
    for (const std::string& e : judged.changed) err << e << "\n";
    err << "tubeplan evaluate: no report written"
        << (o.report_path.empty() ? std::string() : " (" + o.report_path + " is left as it was)")
        << "\n";
    return kExitBadInput;
  }
  if (judged.judged < plan_count || io::Interrupted()) {
    err << "tubeplan evaluate: interrupted after " << judged.judged << " of " << plan_count
        << " plans; no report written"
        << (o.report_path.empty() ? std::string() : " (" + o.report_path + " is left as it was)")
        << "\n";
    return kExitInterrupted;
  }
  return kExitOk;
}

// " (REPORT and HTML are left as they were)" for the outputs asked for, or empty.
std::string OutputsLeftAsTheyWere(const EvaluateOptions& o) {
  if (o.report_path.empty() && o.html_path.empty()) return std::string();
  return " (" +
         (o.report_path.empty() ? o.html_path
          : o.html_path.empty() ? o.report_path
                                : o.report_path + " and " + o.html_path) +
         (o.report_path.empty() || o.html_path.empty() ? " is left as it was)"
                                                       : " are left as they were)");
}

batch::ReportScope ScopeOf(const batch::PlanSet& set) {
  batch::ReportScope scope;
  scope.plan_set_id = set.id;
  scope.plan_set_plans = set.size;
  scope.shard_index = set.shard_index;
  scope.shard_count = set.shard_count;
  return scope;
}

// The HTML report's page in `html_text`. False after saying why (--html-graph: dot failed).
bool FormatHtml(const EvaluateOptions& o, const std::vector<batch::Evaluated>& results,
                const std::vector<io::PlanLoadResult>& loaded, int jobs,
                std::vector<report::ReplayRecorder>& recorders, std::string& html_text,
                std::ostream& err) {
  report::HtmlOptions html;
  html.command = "tubeplan evaluate";
  for (const std::string& f : o.inputs) html.command += " " + f;
  html.command += " --html " + o.html_path + (o.html_graph ? " --html-graph" : "");
  if (o.html_graph) {
    if (!GraphSections(results, loaded, jobs, html, err)) return false;
  } else {
    html.graph_note =
        "Not included: add --html-graph to explore each scene's contact-state graph with the "
        "core (its default exploration: minutes a scene) and draw it here with this run's "
        "verdicts.";
  }
  std::vector<report::HtmlPlan> pages;
  for (std::size_t i = 0; i < results.size(); ++i)
    pages.push_back({&results[i], &*loaded[i].scene, loaded[i].plan->scene, recorders[i].Finish()});
  html_text = report::FormatHtmlReport(pages, html);
  return true;
}

// Both files in their temporaries, then renamed one after the other: a signal while they are
// written ends the process with neither; one while they are renamed comes too late to stop
// them (deferred, and then ignored), so there is never one without the other. False after
// saying which failed.
bool WriteOutputs(const EvaluateOptions& o, const nlohmann::json& report,
                  const std::string& html_text, std::ostream& err) {
  std::vector<std::pair<std::string, std::unique_ptr<io::AtomicFile>>> outputs;
  if (!o.report_path.empty()) {
    outputs.emplace_back(o.report_path, std::make_unique<io::AtomicFile>(o.report_path));
    outputs.back().second->Write(report.dump(1) + "\n");
  }
  if (!o.html_path.empty()) {
    outputs.emplace_back(o.html_path, std::make_unique<io::AtomicFile>(o.html_path));
    outputs.back().second->Write(html_text);
  }
  for (const auto& [path, file] : outputs) {
    if (file->error().empty()) continue;
    err << path << ": error: " << file->Commit() << "\n";
    return false;
  }
  const io::DeferInterrupts too_late;
  for (const auto& [path, file] : outputs) {
    if (const std::string e = file->Commit(); !e.empty()) {
      err << path << ": error: " << e << "\n";
      return false;
    }
  }
  return true;
}

// Each plan's verdicts, then a summary of the batch: counts, trajectory time and speed.
void PrintText(const EvaluateOptions& o, const std::vector<batch::Evaluated>& results,
               double wall_s, int jobs, std::ostream& out) {
  const bool colour = isatty(STDOUT_FILENO) != 0;
  std::ostringstream t;
  t << std::setprecision(3);
  double replayed_s = 0.0, run_s = 0.0;
  long feasible = 0, not_judged = 0;
  for (const batch::Evaluated& e : results) {
    replayed_s += e.replayed_s;
    run_s += e.run_s;
    feasible += e.judgement.feasible;
    not_judged += plan::Overall(e.judgement) == plan::Verdict::kNotJudged;
    report::PrintVerdicts(t, e, colour);
  }
  t << "summary: " << results.size() << " plan" << (results.size() == 1 ? "" : "s") << ", "
    << feasible << " feasible, " << long(results.size()) - feasible - not_judged << " infeasible"
    << (not_judged > 0 ? ", " + std::to_string(not_judged) + " not judged" : std::string()) << "; "
    << replayed_s << " s of trajectories replayed in " << wall_s << " s on " << jobs << " thread"
    << (jobs == 1 ? "" : "s") << " (" << (run_s > 0 ? replayed_s / run_s : 0.0)
    << "x real time per core)\n";
  if (!o.report_path.empty()) t << "report written to " << o.report_path << "\n";
  if (!o.html_path.empty()) t << "HTML report written to " << o.html_path << "\n";
  out << t.str();
}

int RunEvaluate(const EvaluateOptions& o, Streams io) {
  batch::PlanSet set;
  std::vector<io::PlanLoadResult> loaded;
  if (!LoadPlans(o, io.err, set, loaded)) return kExitBadInput;
  if (!HtmlToolsPresent(o, io.err)) return kExitBadInput;
  const std::vector<std::string>& files = set.files;
  const int jobs = std::clamp(o.jobs > 0 ? o.jobs : int(std::thread::hardware_concurrency()), 1,
                              std::max<int>(1, int(files.size())));
  // Ctrl-C (SIGINT) or SIGTERM during the batch: the plans being judged finish, no new one
  // starts, and no report is written (a report is complete or absent, never half of a batch).
  // A second signal ends the process at once (io/interrupt.hpp).
  std::optional<io::DeferInterrupts> defer_interrupts;
  defer_interrupts.emplace();
  // With --html each judged replay is recorded as it runs (no second replay).
  std::vector<report::ReplayRecorder> recorders(o.html_path.empty() ? 0 : files.size());
  const batch::BatchResult judged = JudgePlans(o, files, loaded, jobs, recorders, io.err);
  if (const int exit = CheckAllJudged(o, judged, files.size(), io.err); exit != kExitOk)
    return exit;
  const std::vector<batch::Evaluated>& results = judged.results;
  // From here a signal ends the process at once (the page and the graphs take seconds); the
  // outputs are made in memory and written last, so an interruption leaves none of them.
  io::SetInterruptMessage("tubeplan evaluate: interrupted; no report written" +
                          OutputsLeftAsTheyWere(o));
  defer_interrupts.reset();
  const nlohmann::json report = batch::ToJson(results, ScopeOf(set));
  std::string html_text;
  if (!o.html_path.empty() && !FormatHtml(o, results, loaded, jobs, recorders, html_text, io.err))
    return kExitBadInput;
  if (!WriteOutputs(o, report, html_text, io.err)) return kExitBadInput;
  const bool all_feasible =
      std::all_of(results.begin(), results.end(),
                  [](const batch::Evaluated& e) { return e.judgement.feasible; });
  if (o.json)
    io.out << report.dump(2) << "\n";
  else
    PrintText(o, results, judged.wall_s, jobs, io.out);
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

namespace {

struct MergeOptions {
  std::vector<std::string> reports;
  bool json = false;
  std::string report_path;
};

int RunMerge(const MergeOptions& o, Streams io) {
  std::vector<std::string> errors;
  const std::optional<nlohmann::json> report = batch::MergeShardReports(o.reports, errors);
  for (const std::string& e : errors) io.err << e << "\n";
  if (!report) return kExitBadInput;
  std::vector<io::RolePath> inputs;
  for (const std::string& path : o.reports) inputs.push_back({"the report", path});
  if (!OutputsApart("merge", {{"--report", o.report_path}}, inputs, io.err)) return kExitBadInput;
  const nlohmann::json& merged = *report;
  if (!o.report_path.empty()) {
    if (const std::string e = io::WriteTextFileAtomically(o.report_path, merged.dump(1) + "\n");
        !e.empty()) {
      io.err << o.report_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  }
  const bool all_feasible = merged["summary"]["infeasible"] == 0;
  if (o.json) {
    io.out << merged.dump(2) << "\n";
  } else {
    for (const nlohmann::json& p : merged["plans"])
      io.out << p["file"].get<std::string>() << ": "
             << (p["feasible"].get<bool>() ? "FEASIBLE" : "INFEASIBLE") << "\n";
    io.out << "summary: " << merged["summary"]["plans"] << " plans, "
           << merged["summary"]["feasible"] << " feasible, " << merged["summary"]["infeasible"]
           << " infeasible (merged from " << o.reports.size()
           << (o.reports.size() == 1 ? " report)\n" : " reports)\n");
  }
  return all_feasible ? kExitOk : kExitNegative;
}

}  // namespace

Command AddMergeCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<MergeOptions>();
  CLI::App* sub = app.add_subcommand(
      "merge",
      "Join the JSON reports of `tubeplan evaluate --shard` runs into the report one unsharded "
      "run gives.");
  sub->add_option("reports", options->reports, "report files (JSON)")->required();
  sub->add_flag("--json", options->json, "print the merged report as one JSON document");
  sub->add_option("--report", options->report_path, "write the merged report to FILE");
  return {sub, [options, streams] { return RunMerge(*options, streams); }};
}

}  // namespace tubeplan::cli
