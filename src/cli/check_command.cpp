// `tubeplan check FILE...`: validates scene and trajectory files and prints a one-line summary of
// each valid one. Every problem in every file is reported before the exit code says so.
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/check.hpp>

#include "app.hpp"
#include "commands.hpp"

namespace tubeplan::cli {
namespace {

struct CheckOptions {
  std::vector<std::string> files;
  bool json = false;
  bool elements = false;
};

int RunCheck(const CheckOptions& o, Streams io) {
  bool all_valid = true;
  nlohmann::json files = nlohmann::json::array();
  for (const std::string& file : o.files) {
    const batch::CheckedFile checked = batch::CheckFile(file);
    io.err << checked.diagnostics.FormatAll();
    const bool valid = checked.summary.has_value();
    all_valid = all_valid && valid;
    if (o.json) {
      nlohmann::json diagnostics = nlohmann::json::array();
      for (const io::Diagnostic& d : checked.diagnostics.all())
        diagnostics.push_back(
            {{"line", d.line},
             {"column", d.column},
             {"severity", d.severity == io::Severity::kError ? "error" : "warning"},
             {"message", d.message}});
      nlohmann::json entry = {
          {"file", file}, {"kind", checked.kind}, {"valid", valid}, {"diagnostics", diagnostics}};
      if (valid) entry["summary"] = *checked.summary;
      if (o.elements) {
        entry["elements"] = nlohmann::json::array();
        for (std::size_t i = 0; i < checked.elements.size(); ++i) {
          const scene::PartElement& e = checked.elements[i];
          nlohmann::json element = {{"name", e.name}, {"kind", batch::ToString(e.kind)}};
          if (checked.convex[i]) element["convex"] = *checked.convex[i];
          entry["elements"].push_back(element);
        }
      }
      files.push_back(entry);
    } else if (valid) {
      io.out << file << ": ok: " << *checked.summary << "\n";
      if (o.elements)
        for (std::size_t i = 0; i < checked.elements.size(); ++i) {
          const scene::PartElement& e = checked.elements[i];
          io.out << "  " << batch::ToString(e.kind) << " " << e.name;
          if (checked.convex[i]) io.out << (*checked.convex[i] ? " (convex)" : " (concave)");
          io.out << "\n";
        }
    }
  }
  if (o.json) io.out << nlohmann::json{{"files", files}}.dump(2) << "\n";
  return all_valid ? kExitOk : kExitBadInput;
}

}  // namespace

Command AddCheckCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<CheckOptions>();
  CLI::App* sub = app.add_subcommand(
      "check",
      "Validate scene and plan files (.yaml) and trajectories (.csv): every problem is reported as "
      "file:line:col (exit 2), and each valid file gets a one-line summary.");
  sub->add_option("files", options->files, "scene files (.yaml) and trajectory files (.csv)")
      ->required();
  sub->add_flag("--json", options->json, "print one JSON document");
  sub->add_flag("--elements", options->elements,
                "list each scene's part elements (faces, edges, vertices) by the names goals and "
                "plans use");
  return {sub, [options, streams] { return RunCheck(*options, streams); }};
}

}  // namespace tubeplan::cli
