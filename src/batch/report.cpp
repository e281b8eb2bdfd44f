#include <algorithm>

#include <tubeplan/batch/report.hpp>
#include <tubeplan/trajectories/perturb.hpp>

namespace tubeplan::batch {

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
        const trajectories::Interval ci = trajectories::WilsonInterval(e.robust[k], e.runs);
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

}  // namespace tubeplan::batch
