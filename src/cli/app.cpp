#include "app.hpp"

#include <algorithm>
#include <exception>

#include <tubeplan/io/interrupt.hpp>
#include <tubeplan/io/trajectory_csv.hpp>

#include "commands.hpp"

namespace tubeplan::cli {

std::optional<std::vector<double>> ParseQuantityList(std::string_view option, std::string_view text,
                                                     std::size_t min_count, std::size_t max_count,
                                                     io::Dimension dimension, std::string& error) {
  std::vector<double> values;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string_view item = text.substr(
        start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    const io::QuantityResult parsed = io::ParseQuantityAs(item, dimension);
    if (!parsed.quantity) {
      error = std::string(option) + ": \"" + std::string(item) + "\": " + parsed.error->message;
      return std::nullopt;
    }
    values.push_back(parsed.quantity->value_si);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (values.size() < min_count || values.size() > max_count) {
    error =
        std::string(option) + ": expected " +
        (min_count == max_count ? std::to_string(min_count)
                                : std::to_string(min_count) + " to " + std::to_string(max_count)) +
        " comma-separated values, got " + std::to_string(values.size());
    return std::nullopt;
  }
  return values;
}

bool OutputsApart(std::string_view command, const std::vector<io::RolePath>& outputs,
                  const std::vector<io::RolePath>& inputs, std::ostream& err) {
  const std::string problem = io::CheckOutputsApart(outputs, inputs);
  if (!problem.empty()) err << "tubeplan " << command << ": error: " << problem << "\n";
  return problem.empty();
}

int Run(std::span<const std::string> args, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "tubeplan: feasibility of assembly motion plans for an elastic tube going into a rigid "
      "groove.",
      "tubeplan"};
  app.set_version_flag("--version", "tubeplan 0.1.0");
  app.require_subcommand(1);
  const Streams streams{out, err};
  const std::vector<Command> commands = {
      AddCheckCommand(app, streams),    AddBeamCommand(app, streams),
      AddBenchCommand(app, streams),    AddSimulateCommand(app, streams),
      AddGraphCommand(app, streams),    AddPlansCommand(app, streams),
      AddEvaluateCommand(app, streams), AddMergeCommand(app, streams),
      AddLiveCommand(app, streams),     AddAccuracyCommand(app, streams),
      AddStabilityCommand(app, streams)};

  // A word where the command belongs that names none: said with the list (CLI11's own words
  // are "A subcommand is required" for both this and a missing command).
  const std::vector<CLI::App*> known = app.get_subcommands([](CLI::App*) { return true; });
  const bool first_is_word = !args.empty() && !args.front().empty() && args.front()[0] != '-';
  if (args.empty() ||
      (first_is_word && std::none_of(known.begin(), known.end(), [&](const CLI::App* c) {
         return c->get_name() == args.front();
       }))) {
    std::string names;
    for (const CLI::App* c : known) names += (names.empty() ? "" : ", ") + c->get_name();
    err << "tubeplan: error: "
        << (args.empty() ? std::string("no command given")
                         : "unknown command '" + args.front() + "'")
        << "; the commands are " << names << " (tubeplan --help says what each does)\n";
    return kExitBadInput;
  }
  // CLI11 wants argv order reversed when given a vector.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e, out, err);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e, out, err);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e, out, err);
  } catch (const CLI::ParseError& e) {
    app.exit(e, out, err);
    return kExitBadInput;
  }
  try {
    for (const Command& command : commands) {
      if (!command.app->parsed()) continue;
      io::SetInterruptMessage("tubeplan " + command.app->get_name() +
                              ": interrupted; outputs not finished were not written (their "
                              "temporary files are removed)");
      return command.run();
    }
  } catch (const io::InputChanged& e) {
    // A trajectory rewritten between its check and its replay: bad input, not a bug.
    err << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "tubeplan: internal error: " << e.what() << "\n";
    return kExitInternal;
  }
  return kExitBadInput;
}

}  // namespace tubeplan::cli
