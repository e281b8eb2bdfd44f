// An evaluation's text and HTML reports.
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <map>
#include <sstream>

#include <tubeplan/graph/dot.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/verdicts.hpp>
#include <tubeplan/report/evaluation_report.hpp>
#include <tubeplan/report/graphviz.hpp>
#include <tubeplan/report/text_report.hpp>

namespace tubeplan::report {
namespace {

// The graph section of the HTML report: each scene's pruned contact-state graph, explored with the
// core as `tubeplan graph SCENE --closing 0 --replays 0 --time-limit 0` does, coloured by this
// run's verdicts, drawn by Graphviz's dot. On failure returns false with `error`.
bool GraphSections(const std::vector<batch::Evaluated>& results,
                   const std::vector<io::PlanLoadResult>& loaded, int jobs, HtmlOptions& html,
                   std::string& error) {
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
    // The picture of the states: probing alone, without replays or closing rounds.
    explore.closing_motions = 0;
    explore.replay_copies = 0;
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
    const SvgFromDot svg = RenderDot(graph::FormatDot(g, dot));
    if (!svg.error.empty()) {
      error = svg.error;
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

}  // namespace

std::string HtmlToolsMissing(bool html, bool html_graph) {
  if (html && !HtmlReportAvailable())
    return "--html: this tubeplan was built without the HTML report (node was not found when it "
           "was configured, or TUBEPLAN_HTML_REPORT was off); install nodejs and npm "
           "(tools/setup does) and build again";
  if (html_graph) {
    if (!html) return "--html-graph needs --html FILE";
    if (const SvgFromDot probe = RenderDot("digraph{}"); !probe.error.empty())
      return "--html-graph: " + probe.error;
  }
  return std::string();
}

std::optional<std::string> FormatEvaluationHtml(const std::string& command,
                                                const std::vector<batch::Evaluated>& results,
                                                const std::vector<io::PlanLoadResult>& loaded,
                                                int jobs, bool html_graph,
                                                std::vector<ReplayRecorder>& recorders,
                                                std::string& error) {
  HtmlOptions html;
  html.command = command;
  if (html_graph) {
    if (!GraphSections(results, loaded, jobs, html, error)) return std::nullopt;
  } else {
    html.graph_note =
        "Not included: add --html-graph to explore each scene's contact-state graph with the "
        "core (its default exploration: minutes a scene) and draw it here with this run's "
        "verdicts.";
  }
  std::vector<HtmlPlan> pages;
  for (std::size_t i = 0; i < results.size(); ++i)
    pages.push_back({&results[i], &*loaded[i].scene, loaded[i].plan->scene, recorders[i].Finish()});
  return FormatHtmlReport(pages, html);
}

void PrintEvaluation(std::ostream& out, const std::vector<batch::Evaluated>& results, double wall_s,
                     int jobs, const std::string& report_path, const std::string& html_path,
                     bool colour) {
  std::ostringstream t;
  t << std::setprecision(3);
  double replayed_s = 0.0, run_s = 0.0;
  long feasible = 0, not_judged = 0;
  for (const batch::Evaluated& e : results) {
    replayed_s += e.replayed_s;
    run_s += e.run_s;
    feasible += e.judgement.feasible;
    not_judged += plan::Overall(e.judgement) == plan::Verdict::kNotJudged;
    PrintVerdicts(t, e, colour);
  }
  t << "summary: " << results.size() << " plan" << (results.size() == 1 ? "" : "s") << ", "
    << feasible << " feasible, " << long(results.size()) - feasible - not_judged << " infeasible"
    << (not_judged > 0 ? ", " + std::to_string(not_judged) + " not judged" : std::string()) << "; "
    << replayed_s << " s of trajectories replayed in " << wall_s << " s on " << jobs << " thread"
    << (jobs == 1 ? "" : "s") << " (" << (run_s > 0 ? replayed_s / run_s : 0.0)
    << "x real time per core)\n";
  if (!report_path.empty()) t << "report written to " << report_path << "\n";
  if (!html_path.empty()) t << "HTML report written to " << html_path << "\n";
  out << t.str();
}

}  // namespace tubeplan::report
