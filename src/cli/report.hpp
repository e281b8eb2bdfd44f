#pragma once
// Private to the cli library: the evaluation report (text and JSON, docs/evaluate.md) that
// `evaluate`, `merge` and `live` all write, so their verdicts read the same.

#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/plan/judge.hpp>
#include <tubeplan/plan/plan.hpp>

namespace tubeplan::cli {

inline constexpr int kEvaluateJsonVersion = 1;

/// One judged plan.
struct Evaluated {
  std::string file;
  plan::Plan plan;
  plan::Judgement judgement;
  int runs = 0;             // Monte-Carlo replicates
  std::vector<int> robust;  // per transition: replicates in which it was feasible
  double replayed_s = 0.0;  // trajectory time replayed, replicates included
  double run_s = 0.0;       // wall time of those replays
};

/// A report's plans in file order and its summary.
nlohmann::json Report(nlohmann::json plans);
/// The report of judged plans.
nlohmann::json ToJson(const std::vector<Evaluated>& results);
/// One plan's verdicts as text: its line, then each transition with its figures.
void PrintVerdicts(std::ostream& out, const Evaluated& e, bool colour);

}  // namespace tubeplan::cli
