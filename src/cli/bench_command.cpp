// `tubeplan bench`: speed figures of the beam models and of the core's tick, printed (the
// harness and how it measures: bench/bench.hpp; the table and JSON: bench/bench_report.hpp). A
// benchmark is a command that prints numbers; nothing here passes or fails a build (tests never
// time anything).
#include <algorithm>
#include <bench/bench.hpp>
#include <bench/bench_report.hpp>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/io/scene_yaml.hpp>

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

using bench::Figures;
using bench::Scenario;

// The scenarios whose names start with one of `prefixes` (all of them when there are none); an
// empty list, said on `err`, when none does.
std::vector<Scenario> Select(std::vector<Scenario> scenarios,
                             const std::vector<std::string>& prefixes, std::ostream& err) {
  if (prefixes.empty()) return scenarios;
  const auto wanted = [&](const Scenario& s) {
    return std::any_of(prefixes.begin(), prefixes.end(),
                       [&](const std::string& p) { return s.name.starts_with(p); });
  };
  std::vector<Scenario> kept;
  for (Scenario& s : scenarios)
    if (wanted(s)) kept.push_back(std::move(s));
  if (kept.empty()) {
    err << "tubeplan bench: error: no scenario's name starts with";
    for (const std::string& p : prefixes) err << " '" << p << "'";
    err << ", and one was expected; the scenarios are:";
    for (const Scenario& s : scenarios) err << " " << s.name;
    err << "\n";
  }
  return kept;
}

int RunBench(const BenchOptions& o, Streams io) {
  // The default tube is the shipped groove scene's (scenes/groove.yaml), so figures are comparable
  // without a file.
  const io::SceneLoadResult loaded = io::LoadSceneFile(o.scene_path);
  io.err << loaded.diagnostics.FormatAll();
  if (!loaded.scene) return kExitBadInput;
  const model::TubeSpec spec = loaded.scene->tube;
  std::vector<Scenario> all = bench::MakeScenarios(spec);
  if (!o.beam_only) {
    std::vector<Scenario> core_scenarios = bench::MakeCoreScenarios(*loaded.scene);
    all.insert(all.end(), core_scenarios.begin(), core_scenarios.end());
  }
  const std::vector<Scenario> scenarios = Select(std::move(all), o.only, io.err);
  if (scenarios.empty()) return kExitBadInput;
  double sink = 0.0;
  nlohmann::json results = nlohmann::json::array();
  if (!o.json) bench::PrintHeader(io.out);
  int mismatched = 0;
  for (const Scenario& scenario : scenarios) {
    const Figures f = bench::Measure(scenario, o.samples, sink);
    if (f.replica_mismatches > 0) {
      io.err << "tubeplan bench: error: " << scenario.name << ": " << f.replica_mismatches
             << " ticks gave another result on a replica core with the same history, where the "
                "same bits were expected (the core is not deterministic)\n";
      ++mismatched;
    }
    if (o.json)
      results.push_back(bench::ScenarioJson(scenario, f, o.samples));
    else
      bench::PrintRow(io.out, scenario, f);
  }
  if (o.json)
    io.out << bench::BenchJson(spec, std::move(results)).dump(2) << "\n";
  else
    bench::PrintFooter(io.out, spec, o.samples, !o.beam_only);
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
