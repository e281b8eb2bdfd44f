// `evaluate`'s plan set read, checked and judged (docs/evaluate.md).
#include <algorithm>
#include <filesystem>
#include <optional>
#include <thread>

#include <tubeplan/batch/evaluation.hpp>
#include <tubeplan/io/interrupt.hpp>

#include "io/text_file.hpp"

namespace tubeplan::batch {
namespace {

// " (REPORT and HTML are left as they were)" for the outputs asked for, or empty.
std::string OutputsLeftAsTheyWere(const EvaluationRequest& r) {
  if (r.report_path.empty() && r.html_path.empty()) return std::string();
  return " (" +
         (r.report_path.empty() ? r.html_path
          : r.html_path.empty() ? r.report_path
                                : r.report_path + " and " + r.html_path) +
         (r.report_path.empty() || r.html_path.empty() ? " is left as it was)"
                                                       : " are left as they were)");
}

// kAll when every plan was judged; else, after saying why no report is written, why not.
JudgedEnd CheckAllJudged(const EvaluationRequest& r, const BatchResult& judged,
                         std::size_t plan_count, std::ostream& err) {
  if (!judged.changed.empty()) {
    for (const std::string& e : judged.changed) err << e << "\n";
    err << "tubeplan evaluate: no report written"
        << (r.report_path.empty() ? std::string() : " (" + r.report_path + " is left as it was)")
        << "\n";
    return JudgedEnd::kChanged;
  }
  if (judged.judged < plan_count || io::Interrupted()) {
    err << "tubeplan evaluate: interrupted after " << judged.judged << " of " << plan_count
        << " plans; no report written"
        << (r.report_path.empty() ? std::string() : " (" + r.report_path + " is left as it was)")
        << "\n";
    return JudgedEnd::kInterrupted;
  }
  return JudgedEnd::kAll;
}

}  // namespace

bool LoadEvaluation(const EvaluationRequest& r, Evaluation& evaluation, std::ostream& err) {
  PlanSet& set = evaluation.set;
  std::vector<io::PlanLoadResult>& loaded = evaluation.loaded;
  std::vector<std::string> errors;
  set = CollectPlanSet(r.inputs, errors);
  for (const std::string& e : errors) err << e << "\n";
  bool ok = errors.empty();
  if (!r.shard.empty()) {
    std::string error;
    if (!SelectShard(r.shard, set, error)) {
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
    loaded.push_back(io::LoadPlanFile(f, {.trajectory_in_memory = r.monte_carlo > 0}));
    err << loaded.back().diagnostics.FormatAll();
    ok = ok && loaded.back().plan.has_value();
  }
  if (!ok) return false;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::filesystem::path directory = std::filesystem::path(files[i]).parent_path();
    inputs.push_back({"the scene of " + files[i], directory / loaded[i].plan->scene});
    inputs.push_back({"the trajectory of " + files[i], directory / loaded[i].plan->trajectory});
  }
  const std::string problem =
      io::CheckOutputsApart({{"--report", r.report_path}, {"--html", r.html_path}}, inputs);
  if (!problem.empty()) {
    err << "tubeplan evaluate: error: " << problem << "\n";
    return false;
  }
  evaluation.jobs = std::clamp(r.jobs > 0 ? r.jobs : int(std::thread::hardware_concurrency()), 1,
                               std::max<int>(1, int(files.size())));
  return true;
}

JudgedEnd JudgeEvaluation(const EvaluationRequest& r, Evaluation& evaluation,
                          const std::function<plan::TickWatcher(std::size_t)>& watch,
                          std::ostream& err) {
  const std::vector<std::string>& files = evaluation.set.files;
  // Ctrl-C (SIGINT) or SIGTERM during the batch: the plans being judged finish, no new one
  // starts, and no report is written (a report is complete or absent, never half of a batch).
  // A second signal ends the process at once (io/interrupt.hpp).
  std::optional<io::DeferInterrupts> defer_interrupts;
  defer_interrupts.emplace();
  BatchOptions options;
  options.jobs = evaluation.jobs;
  options.monte_carlo = r.monte_carlo;
  options.seed = r.seed;
  options.watch = watch;
  // One short line per plan on a terminal only (a log stays clean).
  if (r.progress)
    options.judged = [&](std::size_t done) {
      err << "\r[" + std::to_string(done) + "/" + std::to_string(files.size()) + "]" << std::flush;
    };
  evaluation.judged = JudgeBatch(files, evaluation.loaded, options);
  if (r.progress) err << "\r";
  const JudgedEnd end = CheckAllJudged(r, evaluation.judged, files.size(), err);
  if (end != JudgedEnd::kAll) return end;
  // From here a signal ends the process at once (the page and the graphs take seconds); the
  // outputs are made in memory and written last, so an interruption leaves none of them.
  io::SetInterruptMessage("tubeplan evaluate: interrupted; no report written" +
                          OutputsLeftAsTheyWere(r));
  defer_interrupts.reset();
  return JudgedEnd::kAll;
}

ReportScope ScopeOf(const PlanSet& set) {
  ReportScope scope;
  scope.plan_set_id = set.id;
  scope.plan_set_plans = set.size;
  scope.shard_index = set.shard_index;
  scope.shard_count = set.shard_count;
  return scope;
}

}  // namespace tubeplan::batch
