// `tubeplan accuracy [SCENE]`: the error of every model and setting against exact or converged
// references, and its run time (method in docs/accuracy.md; its text, JSON and SVG:
// report/accuracy_report.hpp). Times are printed, never judged.
#include <memory>

#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/report/accuracy_report.hpp>
#include <tubeplan/study/accuracy.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

struct AccuracyOptions {
  std::string scene_path = "scenes/groove.yaml";
  bool json = false;
  bool quick = false;
  std::string svg_path;
};

int RunAccuracy(const AccuracyOptions& o, Streams io) {
  if (!OutputsApart("accuracy", {{"--svg", o.svg_path}}, {{"the scene", o.scene_path}}, io.err))
    return kExitBadInput;
  const io::SceneLoadResult loaded = io::LoadSceneFile(o.scene_path);
  io.err << loaded.diagnostics.FormatAll();
  if (!loaded.scene) return kExitBadInput;
  study::AccuracyOptions options;
  options.quick = o.quick;
  const study::AccuracyReport result = study::RunAccuracy(*loaded.scene, options);
  if (!o.svg_path.empty()) {
    const std::string problem =
        io::WriteTextFileAtomically(o.svg_path, report::AccuracySvg(result));
    if (!problem.empty()) {
      io.err << o.svg_path << ": error: " << problem << "\n";
      return kExitBadInput;
    }
  }
  if (o.json)
    io.out << report::AccuracyJson(result).dump(2) << "\n";
  else
    report::PrintAccuracy(io.out, result);
  return kExitOk;
}

}  // namespace

Command AddAccuracyCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<AccuracyOptions>();
  CLI::App* sub = app.add_subcommand(
      "accuracy",
      "Error of every model and setting (rod or linear, element count, time step, contact "
      "stiffness and threshold) against the exact elastica and a converged reference rod, with "
      "the run time of each (docs/accuracy.md).");
  sub->add_option("scene", options->scene_path,
                  "the scene whose tube, contact law and device are studied (default "
                  "scenes/groove.yaml)")
      ->check(CLI::ExistingFile);
  sub->add_flag("--json", options->json, "print one JSON document: rows, references, convergence");
  sub->add_option("--svg", options->svg_path, "write the error-vs-time plot (SVG) to this file");
  sub->add_flag("--quick", options->quick, "fewer load steps, coarser reference (seconds)");
  return {sub, [options, streams] { return RunAccuracy(*options, streams); }};
}

}  // namespace tubeplan::cli
