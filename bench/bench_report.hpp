#pragma once
// The bench's figures as `tubeplan bench` prints them (docs/core.md): a table with a row per
// scenario and a closing line, or each scenario as a JSON entry of one document (times in
// microseconds).

#include <bench/bench.hpp>
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include <tubeplan/model/tube.hpp>

namespace tubeplan::bench {

/// A time [s] to three or four significant figures in ns, us or ms, e.g. "12.34 us".
std::string HumanTime(double seconds);

/// The table's header line.
void PrintHeader(std::ostream& out);

/// The table's row of `scenario`: its figures over the samples, its targets met or missed, and
/// what the core was doing (core scenarios).
void PrintRow(std::ostream& out, const Scenario& scenario, const Figures& figures);

/// The closing line: samples, what "own" means (`core_scenarios`), the tube's alpha at 1 N.
void PrintFooter(std::ostream& out, const model::TubeSpec& tube, int samples, bool core_scenarios);

/// The JSON entry of `scenario`: its figures in microseconds, its targets and their verdict, and
/// what the core was doing (core scenarios).
nlohmann::json ScenarioJson(const Scenario& scenario, const Figures& figures, int samples);

/// The JSON document: the tube's alpha at 1 N and the scenarios' entries.
nlohmann::json BenchJson(const model::TubeSpec& tube, nlohmann::json scenarios);

}  // namespace tubeplan::bench
