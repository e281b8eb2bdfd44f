// `tubeplan simulate SCENE TRAJECTORY [--out FILE] [--json] [--mesh]`: runs the core over a
// recorded hand trajectory (resampled onto the core's step) and reports what happened
// (batch::RunSimulation, report/simulation_report.hpp). The per-tick series (columns in
// docs/simulate-output.md) goes to --out, CSV or JSON Lines by the file's extension, written as
// it is made to a temporary file and renamed (report::SeriesFile).
#include <memory>
#include <optional>

#include <tubeplan/batch/simulation.hpp>
#include <tubeplan/report/series_format.hpp>
#include <tubeplan/report/simulation_report.hpp>

#include "app.hpp"
#include "commands.hpp"

namespace tubeplan::cli {
namespace {

struct SimulateOptions {
  std::string scene_path;
  std::string trajectory_path;
  std::string out_path;
  bool json = false;
  bool mesh = false;
};

int RunSimulate(const SimulateOptions& o, Streams io) {
  if (!OutputsApart("simulate", {{"--out", o.out_path}},
                    {{"the scene", o.scene_path}, {"the trajectory", o.trajectory_path}}, io.err))
    return kExitBadInput;
  batch::SimulationInput input;
  const bool loaded = batch::LoadSimulation(o.scene_path, o.trajectory_path, input, io.err);
  // --out's format is said after the inputs' problems, and before a replay.
  std::string error;
  const std::optional<report::SeriesFormat> format = report::SeriesFormatOf(o.out_path, error);
  if (!format) {
    io.err << o.out_path << ": error: " << error << "\n";
    return kExitBadInput;
  }
  if (!loaded) return kExitBadInput;
  // A directory that cannot be written to is said before the replay, not after it.
  std::optional<report::SeriesFile> series;
  if (*format != report::SeriesFormat::kNone) {
    series.emplace(o.out_path, *format, o.mesh);
    if (const std::string e = series->OpenError(); !e.empty()) {
      io.err << o.out_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  }
  plan::StepWatcher watch;
  if (series)
    watch = [&series](const core::Core& core, const core::StepOutput& out,
                      const std::string& cf_text) { series->Add(core, out, cf_text); };
  const batch::Simulated simulated = batch::RunSimulation(input, io.err, watch);
  if (series)
    if (const std::string e = series->Commit(); !e.empty()) {
      io.err << o.out_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  if (o.json)
    io.out << report::SimulationJson(input, simulated, o.out_path).dump(2) << "\n";
  else
    report::PrintSimulation(io.out, input, simulated, o.out_path);
  return kExitOk;
}

}  // namespace

Command AddSimulateCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* sub = app.add_subcommand(
      "simulate",
      "Run the core over a recorded hand trajectory: prints the contact formations visited, "
      "peaks and timing; --out writes the per-tick series (.csv or .jsonl).");
  sub->add_option("scene", options->scene_path, "scene file (.yaml)")->required();
  sub->add_option("trajectory", options->trajectory_path, "hand trajectory (.csv)")->required();
  sub->add_option(
      "--out", options->out_path,
      "write the per-tick series to FILE (.csv or .jsonl; see docs/simulate-output.md)");
  sub->add_flag("--json", options->json, "print the summary as one JSON document");
  sub->add_flag("--mesh", options->mesh,
                "add the deformed centreline (21 points) to every tick of the series");
  return {sub, [options, streams] { return RunSimulate(*options, streams); }};
}

}  // namespace tubeplan::cli
