#pragma once
// Private to the cli library: each subcommand registers itself on the app and hands back the
// action to run when it was the one parsed.

#include <functional>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include <tubeplan/io/units.hpp>

#include "io/text_file.hpp"

namespace tubeplan::study {
struct StabilityResult;
}

namespace tubeplan::cli {

struct Streams {
  std::ostream& out;  ///< results (one JSON document with --json)
  std::ostream& err;  ///< diagnostics, logs
};

/// A registered subcommand and what to run when it is the one parsed (returns the exit code).
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command AddCheckCommand(CLI::App& app, Streams streams);
Command AddBeamCommand(CLI::App& app, Streams streams);
Command AddBenchCommand(CLI::App& app, Streams streams);
Command AddSimulateCommand(CLI::App& app, Streams streams);
Command AddGraphCommand(CLI::App& app, Streams streams);
Command AddPlansCommand(CLI::App& app, Streams streams);
Command AddEvaluateCommand(CLI::App& app, Streams streams);
Command AddMergeCommand(CLI::App& app, Streams streams);
Command AddLiveCommand(CLI::App& app, Streams streams);
Command AddAccuracyCommand(CLI::App& app, Streams streams);
Command AddStabilityCommand(CLI::App& app, Streams streams);

/// `tubeplan stability`'s report of its results: the pass/fail matrix, a line per failure and the
/// warnings (or, with json, one document); returns 1 if any case failed, else 0.
int ReportStability(std::span<const study::StabilityResult> results, bool json, Streams io);

/// False after saying "tubeplan COMMAND: error: ..." on `err` when an output is the very file of
/// an input or of another output (io::CheckOutputsApart); every command that writes files asks
/// before it writes anything.
bool OutputsApart(std::string_view command, const std::vector<io::RolePath>& outputs,
                  const std::vector<io::RolePath>& inputs, std::ostream& err);

/// Parses "a,b,c" of quantities of one dimension (each a plain SI number or with a unit) with
/// between min_count and max_count items. On failure returns nullopt and sets `error` to a
/// sentence naming the option.
std::optional<std::vector<double>> ParseQuantityList(std::string_view option, std::string_view text,
                                                     std::size_t min_count, std::size_t max_count,
                                                     io::Dimension dimension, std::string& error);

}  // namespace tubeplan::cli
