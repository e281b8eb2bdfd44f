// A live run's display and reports, and the host check's.
#include <cmath>
#include <iomanip>
#include <sstream>

#include <tubeplan/batch/report.hpp>
#include <tubeplan/report/live_report.hpp>
#include <tubeplan/report/text_report.hpp>

namespace tubeplan::report {

void LiveDisplay::Draw(const plan::Judging& judging, const device::ServoStatus& s,
                       double max_force_N, bool force_line) {
  const std::size_t n = judging.states().size() - 1;
  const std::size_t at = judging.at();
  long feasible = 0, infeasible = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const plan::TransitionVerdict& v = judging.transitions()[i];
    if (i < at && v.verdict != plan::Verdict::kInfeasible) ++feasible;
    if (v.verdict == plan::Verdict::kInfeasible && !v.reason.empty()) ++infeasible;
  }
  // After the goal: a limit exceeded or the goal left there is a verdict too.
  const plan::TransitionVerdict& after = judging.after_goal();
  const bool failed_after = after.started && after.verdict == plan::Verdict::kInfeasible;
  infeasible += failed_after;
  std::ostringstream line;
  line << std::fixed << std::setprecision(2);
  line << "t " << std::setw(6) << s.t_s << " s  CF " << judging.current() << "  next "
       << (at < n         ? judging.states()[at + 1]
           : failed_after ? std::string("(goal reached, then infeasible)")
                          : std::string("(goal reached)"))
       << "\n";
  line << "  progress " << at << "/" << n << "  force " << std::setw(5) << s.force_N << " N of "
       << max_force_N << " N  verdicts: " << feasible << " feasible, " << infeasible
       << " infeasible\n";
  line << "  servo " << std::setprecision(0) << s.rate_hz << " Hz, worst tick " << s.worst_us
       << " us, overruns " << s.overruns << "\n";
  const std::string text = line.str();
  if (terminal_) {
    // Cursor up over the last block, then redraw it (each line cleared to its end).
    if (drawn_) out_ << "\033[3F";
    std::istringstream lines(text);
    for (std::string l; std::getline(lines, l);) out_ << l << "\033[K\n";
    out_ << std::flush;
    drawn_ = true;
  } else if (force_line) {
    out_ << text << std::flush;
  }
}

nlohmann::json LiveJson(const live::LiveRun& run) {
  const batch::Evaluated& e = run.evaluated;
  const device::ServoStats& stats = run.stats;
  // A live run's report covers its one plan: the plan set of that file, shard 1 of 1.
  batch::ReportScope scope;
  scope.plan_set_id = batch::PlanSetId({batch::CanonicalPlanPath(e.file)});
  scope.plan_set_plans = 1;
  nlohmann::json report = batch::ToJson({e}, scope);
  report["servo"] = {{"ticks", stats.ticks},
                     {"overruns", stats.overruns},
                     {"median_us", stats.median_us},
                     {"p999_us", stats.p999_us},
                     {"max_us", stats.max_us},
                     {"rate_hz", stats.rate_hz},
                     {"max_latency_us", stats.max_latency_us},
                     {"max_jitter_us", stats.max_jitter_us},
                     {"dropped", stats.dropped},
                     {"stalls", stats.stalls},
                     {"ticks_lost", stats.ticks_lost},
                     {"longest_stall_ms", stats.longest_stall_ms},
                     {"stop", device::ToString(stats.stop)},
                     {"realtime", stats.realtime_note.empty()},
                     {"device", run.device_name},
                     {"clock", run.stepped ? "stepped" : "monotonic"}};
  return report;
}

void PrintLive(std::ostream& out, const live::LiveRun& run, bool colour) {
  const device::ServoStats& stats = run.stats;
  std::ostringstream t;
  PrintVerdicts(t, run.evaluated, colour);
  t << std::fixed << std::setprecision(1) << "servo: " << stats.ticks << " ticks at "
    << stats.rate_hz << " Hz (" << (run.stepped ? "stepped clock" : "real time") << "), "
    << stats.overruns << " overruns; tick median " << stats.median_us << " us, p99.9 "
    << stats.p999_us << " us, worst " << stats.max_us
    << " us; ended: " << device::ToString(stats.stop) << "\n";
  if (stats.stalls > 0)
    t << "servo: " << stats.stalls << (stats.stalls == 1 ? " stall" : " stalls")
      << " (the loop woke more than a tick late; first at t = " << stats.first_stall_s
      << " s, longest " << stats.longest_stall_ms << " ms, " << stats.ticks_lost
      << " periods lost): the force went to zero and ramped back in over 10 ms each time\n";
  if (!run.recording.empty()) t << "recording written to " << run.recording << "\n";
  out << t.str();
}

std::string LiveStopMessage(const live::LiveRun& run) {
  const device::ServoStats& stats = run.stats;
  const device::ServoConfig& config = run.config;
  const std::string& stopped_early = run.stopped_early;
  std::ostringstream err;
  if (stats.stop == device::StopReason::kSignal) {
    err << "tubeplan live: " << stopped_early
        << "; the force was zeroed; the transitions the run did not finish are not judged\n";
  } else if (device::IsFault(stats.stop)) {
    err << "tubeplan live: error: the servo stopped on a fault (" << device::ToString(stats.stop)
        << (stats.stop == device::StopReason::kMissedDeadlines
                ? ": a stall longer than " + std::to_string(std::lround(config.max_stall_s * 1e3)) +
                      " ms or more than " + std::to_string(config.max_stalls_per_s) +
                      " in a second; docs/live.md says what helps"
                : std::string())
        << ") " << stopped_early.substr(stopped_early.find(" at t"))
        << "; the force was zeroed; the transitions the run did not finish are not judged\n";
  }
  return err.str();
}

nlohmann::json HostCheckJson(const device::HostLatency& l, const device::HostVerdict& v,
                             const device::ServoConfig& limits, double period_s) {
  return {{"tubeplan_host_check", 1},
          {"period_us", period_s * 1e6},
          {"duration_s", l.duration_s},
          {"wakes", l.wakes},
          {"median_us", l.median_us},
          {"p99_us", l.p99_us},
          {"p999_us", l.p999_us},
          {"max_us", l.max_us},
          {"stalls", l.stalls},
          {"periods_lost", l.periods_lost},
          {"worst_stalls_per_s", l.worst_stalls_per_s},
          {"realtime", l.realtime_asked && l.realtime_note.empty()},
          {"max_stall_ms", limits.max_stall_s * 1e3},
          {"max_stalls_per_s", limits.max_stalls_per_s},
          {"verdict", device::ToString(v.fitness)},
          {"summary", v.summary},
          {"advice", v.advice}};
}

void PrintHostCheck(std::ostream& out, const device::HostLatency& l, const device::HostVerdict& v,
                    const device::ServoConfig& limits, double period_s) {
  std::ostringstream t;
  t << std::fixed << std::setprecision(1) << "host check: " << l.wakes << " wake-ups every "
    << period_s * 1e3 << " ms over " << l.duration_s << " s, "
    << (!l.realtime_asked         ? "normal priority (--no-realtime)"
        : l.realtime_note.empty() ? "SCHED_FIFO (as the servo thread)"
                                  : "normal priority (SCHED_FIFO not permitted)")
    << "\n";
  t << "lateness: median " << l.median_us << " us, p99 " << l.p99_us << " us, p99.9 " << l.p999_us
    << " us, max " << l.max_us << " us\n";
  t << "stalls (more than a period late): ";
  if (l.stalls == 0)
    t << "none";
  else
    t << l.stalls << ", " << l.periods_lost << " periods lost, at most " << l.worst_stalls_per_s
      << " in one second";
  t << " (a live run stops on one longer than " << std::lround(limits.max_stall_s * 1e3)
    << " ms or more than " << limits.max_stalls_per_s << " in a second)\n";
  t << "verdict: " << v.summary << "\n";
  if (!v.advice.empty()) t << "what would help:\n";
  for (const std::string& a : v.advice) t << "  - " << a << "\n";
  out << t.str();
}

}  // namespace tubeplan::report
