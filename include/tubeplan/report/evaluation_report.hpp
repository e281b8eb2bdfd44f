#pragma once
// An evaluation's reports (docs/evaluate.md, docs/report.md): the text of its verdicts and
// summary, and its HTML page with, when asked, each scene's contact-state graph.
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <tubeplan/batch/evaluate.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/report/html_report.hpp>

namespace tubeplan::report {

/// Why the HTML page cannot be made ("--html: this tubeplan was built without ..."), checked
/// before the replays (a missing `dot` should not cost a batch); empty when it can.
std::string HtmlToolsMissing(bool html, bool html_graph);

/// The HTML page of an evaluation (`command`: how it was made; `recorders`: each plan's judged
/// replay). With `html_graph` each scene's pruned contact-state graph, explored with the core as
/// `tubeplan graph SCENE` does (on `jobs` threads), coloured by the verdicts and drawn by
/// Graphviz's dot. Nullopt with `error` when dot failed.
std::optional<std::string> FormatEvaluationHtml(const std::string& command,
                                                const std::vector<batch::Evaluated>& results,
                                                const std::vector<io::PlanLoadResult>& loaded,
                                                int jobs, bool html_graph,
                                                std::vector<ReplayRecorder>& recorders,
                                                std::string& error);

/// Each plan's verdicts, then a summary of the batch: counts, trajectory time and speed, and
/// the files written (`report_path`, `html_path`; empty for none).
void PrintEvaluation(std::ostream& out, const std::vector<batch::Evaluated>& results, double wall_s,
                     int jobs, const std::string& report_path, const std::string& html_path,
                     bool colour);

}  // namespace tubeplan::report
