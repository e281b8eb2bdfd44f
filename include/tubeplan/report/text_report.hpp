#pragma once
// The evaluation report's text (docs/evaluate.md) that `evaluate` and `live` print, so their
// verdicts read the same; its JSON is batch::ToJson.

#include <ostream>
#include <string>

#include <tubeplan/batch/evaluate.hpp>
#include <tubeplan/plan/judge.hpp>

namespace tubeplan::report {

/// One judged plan's verdicts as text: its line, then each transition with its figures.
void PrintVerdicts(std::ostream& out, const batch::Evaluated& e, bool colour);
/// A plan's verdict (plan::Overall) as its headline: "FEASIBLE", "INFEASIBLE", "NOT JUDGED".
std::string Headline(plan::Verdict overall);

}  // namespace tubeplan::report
