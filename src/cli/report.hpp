#pragma once
// Private to the cli library: the evaluation report's text (docs/evaluate.md) that `evaluate`
// and `live` print, so their verdicts read the same; its JSON is batch::ToJson.

#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/evaluate.hpp>
#include <tubeplan/batch/report.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/plan/plan.hpp>

namespace tubeplan::cli {

/// One judged plan (batch::Evaluated) and what a report covers (batch::ReportScope).
using batch::Evaluated;
using batch::ReportScope;

/// One plan's verdicts as text: its line, then each transition with its figures.
void PrintVerdicts(std::ostream& out, const Evaluated& e, bool colour);
/// A plan's verdict (plan::Overall) as its headline: "FEASIBLE", "INFEASIBLE", "NOT JUDGED".
std::string Headline(plan::Verdict overall);

}  // namespace tubeplan::cli
