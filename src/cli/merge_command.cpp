// `tubeplan merge REPORT... [--json] [--report FILE]`: the JSON reports of `evaluate --shard`
// runs joined into the report one unsharded run gives (docs/evaluate.md).
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/merge.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

struct MergeOptions {
  std::vector<std::string> reports;
  bool json = false;
  std::string report_path;
};

int RunMerge(const MergeOptions& o, Streams io) {
  std::vector<std::string> errors;
  const std::optional<nlohmann::json> report = batch::MergeShardReports(o.reports, errors);
  for (const std::string& e : errors) io.err << e << "\n";
  if (!report) return kExitBadInput;
  std::vector<io::RolePath> inputs;
  for (const std::string& path : o.reports) inputs.push_back({"the report", path});
  if (!OutputsApart("merge", {{"--report", o.report_path}}, inputs, io.err)) return kExitBadInput;
  const nlohmann::json& merged = *report;
  if (!o.report_path.empty()) {
    if (const std::string e = io::WriteTextFileAtomically(o.report_path, merged.dump(1) + "\n");
        !e.empty()) {
      io.err << o.report_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  }
  const bool all_feasible = merged["summary"]["infeasible"] == 0;
  if (o.json) {
    io.out << merged.dump(2) << "\n";
  } else {
    for (const nlohmann::json& p : merged["plans"])
      io.out << p["file"].get<std::string>() << ": "
             << (p["feasible"].get<bool>() ? "FEASIBLE" : "INFEASIBLE") << "\n";
    io.out << "summary: " << merged["summary"]["plans"] << " plans, "
           << merged["summary"]["feasible"] << " feasible, " << merged["summary"]["infeasible"]
           << " infeasible (merged from " << o.reports.size()
           << (o.reports.size() == 1 ? " report)\n" : " reports)\n");
  }
  return all_feasible ? kExitOk : kExitNegative;
}

}  // namespace

Command AddMergeCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<MergeOptions>();
  CLI::App* sub = app.add_subcommand(
      "merge",
      "Join the JSON reports of `tubeplan evaluate --shard` runs into the report one unsharded "
      "run gives.");
  sub->add_option("reports", options->reports, "report files (JSON)")->required();
  sub->add_flag("--json", options->json, "print the merged report as one JSON document");
  sub->add_option("--report", options->report_path, "write the merged report to FILE");
  return {sub, [options, streams] { return RunMerge(*options, streams); }};
}

}  // namespace tubeplan::cli
