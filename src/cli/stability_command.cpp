// `tubeplan stability`: the sweep of stiff and extreme cases through the core: a
// pass/fail matrix, the first failing tick of each failure, exit 1 when any case fails.
#include <algorithm>
#include <iomanip>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include <tubeplan/study/stability.hpp>

#include "app.hpp"
#include "commands.hpp"

namespace tubeplan::cli {
namespace {

struct StabilityOptions {
  bool json = false;
  bool quick = false;
  std::string filter;
};

int RunStability(const StabilityOptions& o, Streams io) {
  std::vector<study::StabilityResult> results;
  for (const study::StabilityCase& c : study::StabilityCases(o.quick)) {
    if (!o.filter.empty() && c.name.find(o.filter) == std::string::npos) continue;
    results.push_back(study::RunStabilityCase(c));
  }
  return ReportStability(results, o.json, io);
}

}  // namespace

int ReportStability(std::span<const study::StabilityResult> results, bool json, Streams io) {
  bool all = true;
  for (const study::StabilityResult& r : results) all = all && r.pass;
  if (json) {
    nlohmann::json cases = nlohmann::json::array();
    for (const study::StabilityResult& r : results) {
      nlohmann::json j = {{"name", r.name},
                          {"pass", r.pass},
                          {"detail", r.detail},
                          {"motion", r.motion},
                          {"parameter", r.parameter},
                          {"ticks", r.ticks},
                          {"peak_force_N", r.peak_force_N}};
      j["first_failing_tick"] =
          r.first_failing_tick >= 0 ? nlohmann::json(r.first_failing_tick) : nlohmann::json();
      j["unconverged_ticks"] = r.unconverged_ticks;
      j["first_unconverged_tick"] = r.first_unconverged_tick >= 0
                                        ? nlohmann::json(r.first_unconverged_tick)
                                        : nlohmann::json();
      j["warning"] = r.warning.empty() ? nlohmann::json() : nlohmann::json(r.warning);
      j["outside_validity"] = r.outside;
      cases.push_back(j);
    }
    io.out << nlohmann::json{{"cases", cases}, {"pass", all}}.dump(2) << "\n";
  } else {
    // The matrix: motions across, parameters down.
    std::vector<std::string> motions, parameters;
    std::map<std::pair<std::string, std::string>, const study::StabilityResult*> cell;
    for (const study::StabilityResult& r : results) {
      if (std::find(motions.begin(), motions.end(), r.motion) == motions.end())
        motions.push_back(r.motion);
      if (std::find(parameters.begin(), parameters.end(), r.parameter) == parameters.end())
        parameters.push_back(r.parameter);
      cell[{r.parameter, r.motion}] = &r;
    }
    io.out << std::left << std::setw(16) << "case";
    for (const std::string& m : motions) io.out << std::setw(31) << m;
    io.out << "\n";
    for (const std::string& p : parameters) {
      io.out << std::setw(16) << p;
      for (const std::string& m : motions) {
        const auto it = cell.find({p, m});
        std::string text = "-";
        if (it != cell.end()) {
          const study::StabilityResult& r = *it->second;
          // "outside": beyond the model's validity; "snaps": some ticks' solves stopped short
          // of their tolerance (the tube snapping through, or the hand jumping).
          std::string notes;
          for (const auto& [on, note] :
               {std::pair{r.outside, "outside"}, std::pair{r.unconverged_ticks > 0, "snaps"}})
            if (on) notes += (notes.empty() ? "" : ", ") + std::string(note);
          text = (r.pass ? "pass" : "FAIL @" + std::to_string(r.first_failing_tick)) +
                 (notes.empty() ? "" : " (" + notes + ")");
        }
        io.out << std::setw(31) << text;
      }
      io.out << "\n";
    }
    int failures = 0;
    for (const study::StabilityResult& r : results) {
      if (!r.pass) {
        ++failures;
        io.out << "FAIL " << r.name << ": " << r.detail << "\n";
      }
    }
    for (const study::StabilityResult& r : results)
      if (!r.warning.empty()) io.err << "warning: " << r.name << ": " << r.warning << "\n";
    io.out << results.size() - std::size_t(failures) << " of " << results.size() << " cases pass\n";
  }
  return all ? kExitOk : kExitNegative;
}

Command AddStabilityCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<StabilityOptions>();
  CLI::App* sub = app.add_subcommand(
      "stability",
      "Run stiff and extreme cases through the core (push into a wall, slide, roll over an edge, "
      "squeeze, fast pass) and check finite outputs, force bounds, passivity, no tunnelling and "
      "same bits; exit 1 if any case fails (docs/accuracy.md).");
  sub->add_flag("--json", options->json, "print one JSON document: {\"cases\": [...]}");
  sub->add_flag("--quick", options->quick, "the extremes only");
  sub->add_option("--only", options->filter, "run only the cases whose name contains this text");
  return {sub, [options, streams] { return RunStability(*options, streams); }};
}

}  // namespace tubeplan::cli
