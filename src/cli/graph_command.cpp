// `tubeplan graph SCENE [--dot FILE] [--json FILE] [--unpruned] [--seed N] [--random N]
// [--closing N] [--replays N] [--check N] [--jobs N] [--weights friction=1,energy=1,distance=1]
// [--tolerance T]`: explores
// the scene with the core, prunes the contact-state graph with the paper's heuristics and writes it
// as DOT and JSON (schema in docs/graph.md). stdout: what was found, the saturation curve, the time
// taken (report::PrintGraph).
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/graph/completeness.hpp>
#include <tubeplan/graph/dot.hpp>
#include <tubeplan/report/graph_json.hpp>
#include <tubeplan/report/graph_report.hpp>
#include <tubeplan/report/graphviz.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "graph_options.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

// The files asked for: DOT, its picture by Graphviz, JSON. False after saying why not.
bool WriteGraphFiles(const GraphOptions& o, const batch::BuiltGraph& b, std::ostream& err) {
  graph::DotOptions dot;
  dot.dropped_arcs = o.unpruned;
  dot.title =
      "tubeplan: contact-state graph of " + b.scene.name + (o.unpruned ? " (unpruned)" : "");
  const std::string dot_text =
      o.dot_path.empty() && o.svg_path.empty() ? std::string() : graph::FormatDot(b.graph, dot);
  if (!o.dot_path.empty()) {
    if (const std::string e = io::WriteTextFileAtomically(o.dot_path, dot_text); !e.empty()) {
      err << o.dot_path << ": error: " << e << "\n";
      return false;
    }
  }
  if (!o.svg_path.empty()) {
    const report::SvgFromDot svg = report::RenderDot(dot_text);
    if (!svg.error.empty()) {
      err << "tubeplan graph: error: " << svg.error << "\n";
      return false;
    }
    err << svg.warnings;
    if (const std::string e = io::WriteTextFileAtomically(o.svg_path, svg.svg); !e.empty()) {
      err << o.svg_path << ": error: " << e << "\n";
      return false;
    }
  }
  if (!o.json_path.empty()) {
    const nlohmann::json j =
        report::GraphToJson(b.graph, b.scene, o.scene_path, b.explore, b.weights);
    if (const std::string e = io::WriteTextFileAtomically(o.json_path, j.dump(1) + "\n");
        !e.empty()) {
      err << o.json_path << ": error: " << e << "\n";
      return false;
    }
  }
  return true;
}

int RunGraph(const GraphOptions& o, Streams io) {
  if (!OutputsApart("graph",
                    {{"--dot", o.dot_path}, {"--svg", o.svg_path}, {"--json", o.json_path}},
                    {{"the scene", o.scene_path}, {"--verdicts", o.verdicts_path}}, io.err))
    return kExitBadInput;
  // Graphviz is checked before the exploration: a missing `dot` should not cost one.
  if (!o.svg_path.empty()) {
    if (const report::SvgFromDot probe = report::RenderDot("digraph{}"); !probe.error.empty()) {
      io.err << "tubeplan graph: error: --svg: " << probe.error << "\n";
      return kExitBadInput;
    }
  }
  std::variant<batch::BuiltGraph, int> built = BuildGraph(o, io);
  if (const int* code = std::get_if<int>(&built)) return *code;
  const batch::BuiltGraph& b = std::get<batch::BuiltGraph>(built);
  if (!WriteGraphFiles(o, b, io.err)) return kExitBadInput;

  // With --check, the graph's completeness measured over motions of another seed.
  std::vector<graph::Completeness> completeness;
  if (o.check > 0) completeness = graph::CheckCompleteness(b.scene, b.graph, b.explore, o.check);
  report::PrintGraph(io.out, o.scene_path, b.scene, b.graph, b.explore, o.verdicts_path,
                     completeness, {o.dot_path, o.svg_path, o.json_path});
  return b.graph.goal >= 0 ? kExitOk : kExitNegative;
}

}  // namespace

Command AddGraphCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<GraphOptions>();
  CLI::App* sub = app.add_subcommand(
      "graph",
      "Build the contact-state graph of a scene by exploring it with the core, prune it with the "
      "friction, bending-energy and distance heuristics, and write DOT and JSON.");
  sub->add_option("scene", options->scene_path, "scene file (.yaml)")->required();
  sub->add_option("--dot", options->dot_path, "write the graph in Graphviz DOT to FILE");
  sub->add_option("--svg", options->svg_path,
                  "write the graph's picture (SVG) to FILE, drawn by Graphviz's `dot` program");
  sub->add_option("--json", options->json_path, "write the graph as JSON to FILE (docs/graph.md)");
  sub->add_option("--verdicts", options->verdicts_path,
                  "colour arcs by an evaluate report (feasible green, infeasible red) and add the "
                  "states its replays saw that exploration missed");
  sub->add_flag("--unpruned", options->unpruned,
                "DOT: draw every arc, the dropped ones dashed with their reason (default: the "
                "pruned graph only)");
  sub->add_option("--check", options->check,
                  "after exploring, run N random guarded motions and about N perturbed replays of "
                  "the candidate plans, of another seed, and report the states and transitions "
                  "they reach that the graph lacks (docs/graph.md)")
      ->check(CLI::Range(0, 100000));
  AddGraphOptions(sub, *options);
  return {sub, [options, streams] { return RunGraph(*options, streams); }};
}

}  // namespace tubeplan::cli
