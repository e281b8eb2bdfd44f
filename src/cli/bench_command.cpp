// `tubeplan bench`: speed figures of the beam models and of the core's tick, printed (the
// harness and how it measures: bench/bench.hpp). A benchmark is a command that prints numbers;
// nothing here passes or fails a build (tests never time anything).
#include <algorithm>
#include <bench/bench.hpp>
#include <cmath>
#include <iomanip>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/model/linear_beam.hpp>

#include "app.hpp"
#include "commands.hpp"

namespace tubeplan::cli {
namespace {

struct BenchOptions {
  std::string scene_path = "scenes/groove.yaml";
  bool beam_only = false;
  std::vector<std::string> only;  // name prefixes; empty: every scenario
  int samples = 2000;
  bool json = false;
};

std::string Human(double seconds) {
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

using bench::Figures;
using bench::kReplicas;
using bench::Scenario;

int RunBench(const BenchOptions& o, Streams io) {
  // The default tube is the shipped groove scene's (scenes/groove.yaml), so figures are comparable
  // without a file.
  const io::SceneLoadResult loaded = io::LoadSceneFile(o.scene_path);
  io.err << loaded.diagnostics.FormatAll();
  if (!loaded.scene) return kExitBadInput;
  const model::TubeSpec spec = loaded.scene->tube;
  std::vector<Scenario> scenarios = bench::MakeScenarios(spec);
  if (!o.beam_only) {
    std::vector<Scenario> core_scenarios = bench::MakeCoreScenarios(*loaded.scene);
    scenarios.insert(scenarios.end(), core_scenarios.begin(), core_scenarios.end());
  }
  if (!o.only.empty()) {
    const auto wanted = [&](const Scenario& s) {
      return std::any_of(o.only.begin(), o.only.end(),
                         [&](const std::string& p) { return s.name.starts_with(p); });
    };
    std::vector<Scenario> kept;
    for (Scenario& s : scenarios)
      if (wanted(s)) kept.push_back(std::move(s));
    if (kept.empty()) {
      io.err << "tubeplan bench: error: no scenario's name starts with";
      for (const std::string& p : o.only) io.err << " '" << p << "'";
      io.err << ", and one was expected; the scenarios are:";
      for (const Scenario& s : scenarios) io.err << " " << s.name;
      io.err << "\n";
      return kExitBadInput;
    }
    scenarios = std::move(kept);
  }
  double sink = 0.0;
  nlohmann::json results = nlohmann::json::array();
  if (!o.json) {
    io.out << std::left << std::setw(28) << "scenario" << std::right << std::setw(11) << "median"
           << std::setw(11) << "p99" << std::setw(11) << "p99.9" << std::setw(11) << "max"
           << std::setw(11) << "own p99.9" << std::setw(11) << "own max"
           << "   target\n";
  }
  int mismatched = 0;
  for (const Scenario& scenario : scenarios) {
    const Figures f = bench::Measure(scenario, o.samples, sink);
    if (f.replica_mismatches > 0) {
      io.err << "tubeplan bench: error: " << scenario.name << ": " << f.replica_mismatches
             << " ticks gave another result on a replica core with the same history, where the "
                "same bits were expected (the core is not deterministic)\n";
      ++mismatched;
    }
    // The median is judged on the first core's wall clock; the p99.9 on the tick's own cost
    // (the least of the replicas' times), the machine's interruptions being no part of the core.
    const bool median_met = f.median_s < scenario.target_s;
    const bool p999_met = f.own_p999_s < scenario.target_p999_s;
    if (o.json) {
      // Times in microseconds; ticks_per_s means calls per second at the median.
      nlohmann::json entry = {{"name", scenario.name},
                              {"what", scenario.what},
                              {"calls_per_sample", scenario.calls_per_sample},
                              {"samples", o.samples},
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
        entry["target_met"] = median_met;
      }
      if (scenario.target_p999_s > 0.0) {
        entry["target_p999_us"] = scenario.target_p999_s * 1e6;
        entry["target_p999_judged_on"] = "own.p999_us";
        entry["target_met"] = median_met && p999_met;
      }
      if (scenario.state) entry["state"] = scenario.state();
      results.push_back(entry);
    } else {
      io.out << std::left << std::setw(28) << scenario.name << std::right << std::setw(11)
             << Human(f.median_s) << std::setw(11) << Human(f.p99_s) << std::setw(11)
             << Human(f.p999_s) << std::setw(11) << Human(f.max_s);
      if (scenario.replicas > 1) {
        io.out << std::setw(11) << Human(f.own_p999_s) << std::setw(11) << Human(f.own_max_s);
      } else {
        io.out << std::setw(11) << "-" << std::setw(11) << "-";
      }
      io.out << "   ";
      if (scenario.target_s > 0.0) {
        io.out << (median_met ? "< " : "MISSED < ") << Human(scenario.target_s);
      } else {
        io.out << "-";
      }
      if (scenario.target_p999_s > 0.0) {
        io.out << (p999_met ? ", own p99.9 < " : ", own p99.9 MISSED < ")
               << Human(scenario.target_p999_s);
      }
      if (scenario.state) {
        const nlohmann::json state = scenario.state();
        io.out << "   " << state["cf"].get<std::string>() << " (" << state["elements"].get<int>()
               << " elements, " << state["iterations"].get<int>() << " iterations)";
      }
      io.out << "\n";
    }
  }
  if (o.json) {
    io.out << nlohmann::json{{"tube_alpha_at_1N", model::LoadParameter(spec, 1.0)},
                             {"scenarios", results}}
                  .dump(2)
           << "\n";
  } else {
    io.out << "(per call; " << o.samples << " samples each; ";
    if (!o.beam_only)
      io.out << "own: the least of " << kReplicas
             << " cores' times for the same tick, without the machine's interruptions; ";
    io.out << "tube alpha at 1 N = " << model::LoadParameter(spec, 1.0) << ")\n";
  }
  // The sink is never NaN for valid input; printing it only when it is keeps the work observable.
  if (std::isnan(sink)) io.err << "tubeplan bench: a scenario produced NaN\n";
  return mismatched > 0 ? kExitInternal : kExitOk;
}

}  // namespace

Command AddBenchCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* sub = app.add_subcommand(
      "bench",
      "Measure the speed of the beam models and of the core's tick in free motion, one end "
      "contact stuck and sliding, two and three PCs (median, p99, p99.9, max).");
  sub->add_option("--scene", options->scene_path,
                  "the scene of the core scenarios and the tube of the beam ones (default "
                  "scenes/groove.yaml, relative to the working directory)");
  sub->add_flag("--beam-only", options->beam_only, "only the beam models' scenarios");
  sub->add_option("--only", options->only,
                  "only the scenarios whose names start with this (repeatable), e.g. "
                  "--only core.end_stuck");
  sub->add_option("--samples", options->samples, "timed samples per scenario")
      ->check(CLI::Range(10, 10000000));
  sub->add_flag("--json", options->json, "print one JSON document (times in microseconds)");
  return {sub, [options, streams] { return RunBench(*options, streams); }};
}

}  // namespace tubeplan::cli
