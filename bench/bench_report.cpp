// The bench's table and JSON (tubeplan bench; bench/bench_report.hpp).
#include "bench_report.hpp"

#include <iomanip>
#include <sstream>
#include <utility>

#include <tubeplan/model/tube.hpp>

namespace tubeplan::bench {
namespace {

// The median is judged on the first core's wall clock; the p99.9 on the tick's own cost (the
// least of the replicas' times), the machine's interruptions being no part of the core.
bool MedianMet(const Scenario& scenario, const Figures& f) {
  return f.median_s < scenario.target_s;
}
bool P999Met(const Scenario& scenario, const Figures& f) {
  return f.own_p999_s < scenario.target_p999_s;
}

}  // namespace

std::string HumanTime(double seconds) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(seconds < 1e-6 ? 1 : 2);
  if (seconds < 1e-6) {
    s << seconds * 1e9 << " ns";
  } else if (seconds < 1e-3) {
    s << seconds * 1e6 << " us";
  } else {
    s << seconds * 1e3 << " ms";
  }
  return s.str();
}

void PrintHeader(std::ostream& out) {
  out << std::left << std::setw(28) << "scenario" << std::right << std::setw(11) << "median"
      << std::setw(11) << "p99" << std::setw(11) << "p99.9" << std::setw(11) << "max"
      << std::setw(11) << "own p99.9" << std::setw(11) << "own max"
      << "   target\n";
}

void PrintRow(std::ostream& out, const Scenario& scenario, const Figures& f) {
  out << std::left << std::setw(28) << scenario.name << std::right << std::setw(11)
      << HumanTime(f.median_s) << std::setw(11) << HumanTime(f.p99_s) << std::setw(11)
      << HumanTime(f.p999_s) << std::setw(11) << HumanTime(f.max_s);
  if (scenario.replicas > 1) {
    out << std::setw(11) << HumanTime(f.own_p999_s) << std::setw(11) << HumanTime(f.own_max_s);
  } else {
    out << std::setw(11) << "-" << std::setw(11) << "-";
  }
  out << "   ";
  if (scenario.target_s > 0.0) {
    out << (MedianMet(scenario, f) ? "< " : "MISSED < ") << HumanTime(scenario.target_s);
  } else {
    out << "-";
  }
  if (scenario.target_p999_s > 0.0) {
    out << (P999Met(scenario, f) ? ", own p99.9 < " : ", own p99.9 MISSED < ")
        << HumanTime(scenario.target_p999_s);
  }
  if (scenario.state) {
    const nlohmann::json state = scenario.state();
    out << "   " << state["cf"].get<std::string>() << " (" << state["elements"].get<int>()
        << " elements, " << state["iterations"].get<int>() << " iterations)";
  }
  out << "\n";
}

void PrintFooter(std::ostream& out, const model::TubeSpec& tube, int samples, bool core_scenarios) {
  out << "(per call; " << samples << " samples each; ";
  if (core_scenarios)
    out << "own: the least of " << kReplicas
        << " cores' times for the same tick, without the machine's interruptions; ";
  out << "tube alpha at 1 N = " << model::LoadParameter(tube, 1.0) << ")\n";
}

nlohmann::json ScenarioJson(const Scenario& scenario, const Figures& f, int samples) {
  // Times in microseconds; ticks_per_s means calls per second at the median.
  nlohmann::json entry = {{"name", scenario.name},
                          {"what", scenario.what},
                          {"calls_per_sample", scenario.calls_per_sample},
                          {"samples", samples},
                          {"median_us", f.median_s * 1e6},
                          {"p99_us", f.p99_s * 1e6},
                          {"p999_us", f.p999_s * 1e6},
                          {"max_us", f.max_s * 1e6},
                          {"ticks_per_s", 1.0 / f.median_s}};
  if (scenario.replicas > 1) {
    entry["replicas"] = scenario.replicas;
    entry["own"] = {{"median_us", f.own_median_s * 1e6},
                    {"p99_us", f.own_p99_s * 1e6},
                    {"p999_us", f.own_p999_s * 1e6},
                    {"max_us", f.own_max_s * 1e6}};
  }
  if (scenario.target_s > 0.0) {
    entry["target_median_us"] = scenario.target_s * 1e6;
    entry["target_met"] = MedianMet(scenario, f);
  }
  if (scenario.target_p999_s > 0.0) {
    entry["target_p999_us"] = scenario.target_p999_s * 1e6;
    entry["target_p999_judged_on"] = "own.p999_us";
    entry["target_met"] = MedianMet(scenario, f) && P999Met(scenario, f);
  }
  if (scenario.state) entry["state"] = scenario.state();
  return entry;
}

nlohmann::json BenchJson(const model::TubeSpec& tube, nlohmann::json scenarios) {
  return {{"tube_alpha_at_1N", model::LoadParameter(tube, 1.0)},
          {"scenarios", std::move(scenarios)}};
}

}  // namespace tubeplan::bench
