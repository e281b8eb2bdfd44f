#include "report.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <sstream>

#include <tubeplan/plan/perturb.hpp>

namespace tubeplan::cli {

// A report's plans in file order, what it covers and its summary: what both `evaluate` and
// `merge` write, so a merge of shard reports is the report of the unsharded run.
nlohmann::json Report(nlohmann::json plans, const ReportScope& scope) {
  std::stable_sort(plans.begin(), plans.end(),
                   [](const nlohmann::json& a, const nlohmann::json& b) {
                     return a["file"].get<std::string>() < b["file"].get<std::string>();
                   });
  long feasible = 0, not_judged = 0;
  for (const nlohmann::json& p : plans) {
    feasible += p["feasible"].get<bool>();
    not_judged += p.value("outcome", std::string()) == "not judged";
  }
  const long count = static_cast<long>(plans.size());
  return {{"tubeplan_evaluate", kEvaluateJsonVersion},
          {"plan_set", {{"id", scope.plan_set_id}, {"plans", scope.plan_set_plans}}},
          {"shard", {{"index", scope.shard_index}, {"count", scope.shard_count}}},
          {"plans", plans},
          {"summary",
           {{"plans", count},
            {"feasible", feasible},
            {"infeasible", count - feasible - not_judged},
            {"not_judged", not_judged}}}};
}

namespace {

// One span's verdict and figures: a planned transition, or the stretch after the goal. A span the
// replay never got to has null times and figures.
nlohmann::json SpanJson(const plan::TransitionVerdict& v) {
  const auto figure = [&](double value) {
    return v.started ? nlohmann::json(value) : nlohmann::json(nullptr);
  };
  nlohmann::json j = {{"from", v.from},
                      {"to", v.to},
                      {"verdict", plan::ToString(v.verdict)},
                      {"reason", v.reason},
                      {"detour", v.detour},
                      {"t_start_s", figure(v.t_start_s)},
                      {"t_end_s", figure(v.t_end_s)},
                      {"peak_force_N", figure(v.peak_force_N)},
                      {"friction_work_J", figure(v.friction_work_J)},
                      {"energy_entry_J", figure(v.energy_entry_J)},
                      {"energy_exit_J", figure(v.energy_exit_J)}};
  for (std::size_t i = 0; i < plan::kWarnedFlags.size(); ++i)
    j[plan::kWarnedFlags[i].key] = figure(v.flagged_s[i]);
  return j;
}

}  // namespace

nlohmann::json ToJson(const std::vector<Evaluated>& results, const ReportScope& scope) {
  nlohmann::json plans = nlohmann::json::array();
  for (const Evaluated& e : results) {
    const plan::Judgement& j = e.judgement;
    nlohmann::json transitions = nlohmann::json::array();
    for (std::size_t k = 0; k < j.transitions.size(); ++k) {
      transitions.push_back(SpanJson(j.transitions[k]));
      if (e.runs > 0) {
        const plan::Interval ci = plan::WilsonInterval(e.robust[k], e.runs);
        transitions.back()["monte_carlo"] = {{"runs", e.runs},
                                             {"feasible", e.robust[k]},
                                             {"fraction", double(e.robust[k]) / e.runs},
                                             {"ci95", {ci.low, ci.high}}};
      }
    }
    nlohmann::json observed = nlohmann::json::array();
    for (const plan::Observation& o : j.observed) observed.push_back({{"t", o.t_s}, {"cf", o.cf}});
    nlohmann::json warnings = nlohmann::json::array();
    if (!j.strain_warning.empty()) warnings.push_back(j.strain_warning);
    plans.push_back({{"plan", e.plan.name},
                     {"file", e.file},
                     {"feasible", j.feasible},
                     {"outcome", plan::ToString(plan::Overall(j))},
                     {"stopped_early", j.stopped_early.empty() ? nlohmann::json(nullptr)
                                                               : nlohmann::json(j.stopped_early)},
                     {"transitions", transitions},
                     {"after_goal", j.after_goal.started ? SpanJson(j.after_goal) : nullptr},
                     {"observed", observed},
                     {"peak_force_N", j.peak_force_N},
                     {"peak_force_t_s", j.peak_force_t_s},
                     {"peak_strain", j.peak_strain},
                     {"peak_strain_t_s", j.peak_strain_t_s},
                     {"warnings", warnings},
                     {"ticks", j.ticks},
                     {"replayed_s", j.replayed_s}});
  }
  return Report(std::move(plans), scope);
}

namespace {

// A span's lines: its verdict (and why), then its figures and its warnings.
void PrintSpan(std::ostream& t, const std::string& title, const plan::TransitionVerdict& v,
               const std::string& robust,
               const std::function<std::string(plan::Verdict, const std::string&)>& paint) {
  t << "  " << title << ": " << paint(v.verdict, plan::ToString(v.verdict));
  if (!v.detour.empty()) {
    t << " via";
    for (const std::string& d : v.detour) t << " " << d;
  }
  if (!v.reason.empty()) t << " (" << v.reason << ")";
  t << robust;
  if (!v.started) {
    t << "\n";
    return;  // no span, no figures: the replay never got there
  }
  t << "\n      t " << v.t_start_s << " .. " << v.t_end_s << " s, peak force " << v.peak_force_N
    << " N, friction work " << v.friction_work_J << " J, bending energy " << v.energy_entry_J
    << " -> " << v.energy_exit_J << " J\n";
  for (std::size_t i = 0; i < plan::kWarnedFlags.size(); ++i)
    if (v.flagged_s[i] > 0.0)
      t << "      warning: " << plan::FlagWarning(i, v.flagged_s[i]) << "\n";
}

}  // namespace

std::string Headline(plan::Verdict overall) {
  std::string text = plan::ToString(overall);
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return char(std::toupper(c)); });
  return text;
}

void PrintVerdicts(std::ostream& t, const Evaluated& e, bool colour) {
  auto paint = [&](plan::Verdict v, const std::string& text) {
    if (!colour) return text;
    const char* code = v == plan::Verdict::kFeasible             ? "\033[32m"
                       : v == plan::Verdict::kFeasibleWithDetour ? "\033[33m"
                       : v == plan::Verdict::kInfeasible         ? "\033[31m"
                                                                 : "\033[2m";
    return std::string(code) + text + "\033[0m";
  };
  const std::streamsize precision = t.precision(3);
  const plan::Judgement& j = e.judgement;
  const plan::Verdict overall = plan::Overall(j);
  t << e.file << " (" << e.plan.name << "): " << paint(overall, Headline(overall)) << ", "
    << j.transitions.size() << (j.transitions.size() == 1 ? " transition, " : " transitions, ")
    << j.replayed_s << " s replayed";
  if (!j.stopped_early.empty()) t << "; the run stopped early: " << j.stopped_early;
  t << "\n";
  if (!j.strain_warning.empty()) t << "  warning: " << j.strain_warning << "\n";
  for (std::size_t k = 0; k < j.transitions.size(); ++k) {
    const plan::TransitionVerdict& v = j.transitions[k];
    std::ostringstream robust;
    if (e.runs > 0) {
      robust.precision(3);
      const plan::Interval ci = plan::WilsonInterval(e.robust[k], e.runs);
      robust << "\n      robust: feasible in " << e.robust[k] << " of " << e.runs
             << " perturbed replays (95 % interval " << ci.low << " .. " << ci.high << ")";
    }
    PrintSpan(t, v.from + " -> " + v.to, v, robust.str(), paint);
  }
  if (j.after_goal.started)
    PrintSpan(t, "after the goal, in " + j.after_goal.to, j.after_goal, "", paint);
  t.precision(precision);
}

}  // namespace tubeplan::cli
