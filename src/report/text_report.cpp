#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <sstream>

#include <tubeplan/report/text_report.hpp>
#include <tubeplan/trajectories/perturb.hpp>

namespace tubeplan::report {

namespace {

// A span's lines: its verdict (and why), then its figures and its warnings.
void PrintSpan(std::ostream& t, const std::string& title, const plan::TransitionVerdict& v,
               const std::string& robust,
               const std::function<std::string(plan::Verdict, const std::string&)>& paint) {
  t << "  " << title << ": " << paint(v.verdict, plan::ToString(v.verdict)) << plan::DetourText(v);
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

void PrintVerdicts(std::ostream& t, const batch::Evaluated& e, bool colour) {
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
      const trajectories::Interval ci = trajectories::WilsonInterval(e.robust[k], e.runs);
      robust << "\n      robust: feasible in " << e.robust[k] << " of " << e.runs
             << " perturbed replays (95 % interval " << ci.low << " .. " << ci.high << ")";
    }
    PrintSpan(t, v.from + " -> " + v.to, v, robust.str(), paint);
  }
  if (j.after_goal.started)
    PrintSpan(t, "after the goal, in " + j.after_goal.to, j.after_goal, "", paint);
  t.precision(precision);
}

}  // namespace tubeplan::report
