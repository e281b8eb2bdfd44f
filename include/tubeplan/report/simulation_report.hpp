#pragma once
// A simulation's summary as people and programs read it (docs/simulate-output.md): the contact
// formations visited, the peaks, the ticks flagged and the core's run time, as text or as one
// JSON document.

#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/simulation.hpp>

namespace tubeplan::report {

/// The summary as one JSON document; `out_path`: the series' file, empty for none.
nlohmann::json SimulationJson(const batch::SimulationInput& input,
                              const batch::Simulated& simulated, const std::string& out_path);

/// The summary as text (the first 40 visits); `out_path` as SimulationJson's.
void PrintSimulation(std::ostream& out, const batch::SimulationInput& input,
                     const batch::Simulated& simulated, const std::string& out_path);

}  // namespace tubeplan::report
