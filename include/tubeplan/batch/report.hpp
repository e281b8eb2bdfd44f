#pragma once
// The evaluation report as JSON (docs/evaluate.md): what `evaluate --json`, `merge` and `live`
// write, one form for all three.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/evaluate.hpp>

namespace tubeplan::batch {

/// Version 3: the plan set and the shard a report covers (`plan_set`, `shard`) and the flag times
/// (`fault_s`, `beyond_linear_s`, `unconverged_s`); version 1 lacks the first two, version 2 the
/// flag times.
inline constexpr int kEvaluateJsonVersion = 3;

/// What a report covers: shard `shard_index` of `shard_count` of one plan set, named by
/// batch::PlanSetId of its plans' canonical paths (`plan_set_plans` plans in the whole set). An
/// unsharded run, a merge and a live run cover shard 1 of 1.
struct ReportScope {
  std::string plan_set_id;
  long plan_set_plans = 0;
  int shard_index = 1;
  int shard_count = 1;
};

/// A report's plans in file order, what it covers and its summary.
nlohmann::json Report(nlohmann::json plans, const ReportScope& scope);
/// The report of judged plans.
nlohmann::json ToJson(const std::vector<Evaluated>& results, const ReportScope& scope);

}  // namespace tubeplan::batch
