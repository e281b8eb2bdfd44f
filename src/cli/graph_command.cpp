// `tubeplan graph SCENE [--dot FILE] [--json FILE] [--unpruned] [--seed N] [--random N]
// [--closing N] [--jobs N] [--weights friction=1,energy=1,distance=1] [--tolerance T]`: explores
// the scene with the core, prunes the contact-state graph with the paper's heuristics and writes it
// as DOT and JSON (schema in docs/graph.md). stdout: what was found, the saturation curve, the time
// taken.
#include <algorithm>
#include <iomanip>
#include <numbers>
#include <ostream>
#include <sstream>
#include <string>
#include <variant>

#include <nlohmann/json.hpp>

#include <tubeplan/graph/completeness.hpp>
#include <tubeplan/graph/dot.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/summary.hpp>
#include <tubeplan/report/graph_json.hpp>
#include <tubeplan/report/graphviz.hpp>
#include <tubeplan/states/contact_formation.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "graph_build.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

// The files asked for: DOT, its picture by Graphviz, JSON. False after saying why not.
bool WriteGraphFiles(const GraphOptions& o, const Built& b, std::ostream& err) {
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

// What was found: states, transitions, the motions by kind, the work done.
void PrintFound(std::ostream& t, const std::string& scene_path, const Built& b,
                const graph::GraphCounts& counts) {
  const graph::ContactGraph& g = b.graph;
  t << scene_path << ": " << g.nodes.size() << " contact formations, " << g.arcs.size()
    << " transitions (" << counts.kept_arcs << " kept by pruning, " << counts.simultaneous_arcs
    << " simultaneous) from " << g.motions.size() << " motions (";
  bool first = true;
  for (const auto& [kind, n] : counts.motions_by_kind)
    t << (first ? "" : ", ") << n << " " << kind, first = false;
  t << "), " << g.ticks << " core ticks, " << g.refinements << " steps refined, " << g.held_back
    << " motions ended where the coupling reached the device's force (the tube no longer followed "
       "the hand); "
    << g.seconds << " s on " << b.explore.jobs << " thread" << (b.explore.jobs > 1 ? "s" : "")
    << "\n";
}

// The saturation curve (about a dozen points) and whether, or why not, the graph saturated.
void PrintSaturation(std::ostream& t, const Built& b) {
  const graph::ContactGraph& g = b.graph;
  const graph::ExploreOptions& explore = b.explore;
  t << "saturation (motions: nodes/arcs):";
  const std::size_t every = std::max<std::size_t>(1, g.saturation.size() / 12);
  for (std::size_t i = 0; i < g.saturation.size(); ++i) {
    if (i % every != 0 && i + 1 != g.saturation.size()) continue;
    const graph::SaturationPoint& p = g.saturation[i];
    t << " " << p.motions << ": " << p.nodes << "/" << p.arcs;
  }
  if (g.saturated) {
    t << "  (saturated: every one of the " << g.probed << " states probed from a stay with "
      << graph::kProbesPerNode << " small motions (" << explore.probe_step_m * 1e3
      << " mm along and against 3 directions, " << explore.probe_turn_rad * 180.0 / std::numbers::pi
      << " deg about 2 axes); ";
    if (explore.closing_motions > 0)
      t << "then " << g.closing_rounds << " closing round" << (g.closing_rounds == 1 ? "" : "s")
        << " of " << explore.closing_motions
        << " random motions, the last adding no state and no transition)\n";
    else
      t << "the last round found no new state; no closing rounds)\n";
  } else if (g.end == graph::ExploreEnd::kTimeLimit) {
    t << "  (NOT saturated: stopped by the time limit of " << explore.time_limit_s << " s after "
      << g.motions.size() << " motions, with " << g.probed << " of " << g.nodes.size()
      << " states probed, " << g.closing_rounds << " closing rounds)\n";
  } else {
    t << "  (NOT saturated: stopped by the budget of " << explore.max_motions << " motions, with "
      << g.probed << " of " << g.nodes.size() << " states probed, " << g.closing_rounds
      << " closing rounds)\n";
  }
}

// Start and goal, and the part elements the tube touched and never touched.
void PrintReach(std::ostream& t, const Built& b) {
  const graph::ContactGraph& g = b.graph;
  t << "start "
    << (g.start >= 0 ? g.nodes[std::size_t(g.start)].cf : "not reached (no motion ended)")
    << "; goal " << states::ToString(b.scene.goal)
    << (g.goal >= 0 ? " reached" : " NEVER reached: no plan can be extracted") << "\n";
  t << "part elements touched: " << g.reached_elements.size()
    << "; never touched: " << g.unreached_elements.size();
  for (std::size_t i = 0; i < g.unreached_elements.size() && i < 8; ++i)
    t << (i == 0 ? " (" : ", ") << g.unreached_elements[i];
  if (!g.unreached_elements.empty()) t << (g.unreached_elements.size() > 8 ? ", ...)" : ")");
  t << "\n";
}

// What an evaluate report's verdicts did to the graph (--verdicts).
void PrintVerdictCounts(std::ostream& t, const std::string& verdicts_path,
                        const graph::GraphCounts& counts) {
  t << "verdicts from " << verdicts_path << ": " << counts.feasible_arcs << " arcs feasible, "
    << counts.infeasible_arcs << " infeasible; " << counts.replay_nodes << " states and "
    << counts.replay_arcs << " transitions seen only in the replays added\n";
}

// How many of the independent motions' states and transitions the graph has (--check), and the
// first few it lacks.
void PrintCompleteness(std::ostream& t, const graph::Completeness& c) {
  const auto percent = [](long part, long all) { return all > 0 ? 100.0 * part / all : 100.0; };
  t << "completeness: " << c.motions << " independent random motions counted " << c.states_seen
    << " states, " << c.states_in_graph << " in the graph ("
    << percent(c.states_in_graph, c.states_seen) << " %), and " << c.transitions_seen
    << " transitions, " << c.transitions_in_graph << " in it ("
    << percent(c.transitions_in_graph, c.transitions_seen) << " %); by use, "
    << percent(c.ticks_in_graph, c.ticks) << " % of their ticks and "
    << percent(c.taken_in_graph, c.taken) << " % of the transitions taken\n";
  for (std::size_t i = 0; i < c.missing_states.size() && i < 8; ++i)
    t << "  missing state: " << c.missing_states[i] << "\n";
  for (std::size_t i = 0; i < c.missing_transitions.size() && i < 8; ++i)
    t << "  missing transition: " << c.missing_transitions[i].first.first << " -> "
      << c.missing_transitions[i].first.second << " (taken " << c.missing_transitions[i].second
      << (c.missing_transitions[i].second == 1 ? " time)\n" : " times)\n");
  const std::size_t more = c.missing_states.size() + c.missing_transitions.size() -
                           std::min<std::size_t>(c.missing_states.size(), 8) -
                           std::min<std::size_t>(c.missing_transitions.size(), 8);
  if (more > 0) t << "  and " << more << " more\n";
}

void PrintWritten(std::ostream& t, const GraphOptions& o) {
  if (!o.dot_path.empty()) t << "DOT written to " << o.dot_path << "\n";
  if (!o.svg_path.empty()) t << "SVG (Graphviz dot) written to " << o.svg_path << "\n";
  if (!o.json_path.empty()) t << "JSON written to " << o.json_path << "\n";
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
  std::variant<Built, int> built = BuildGraph(o, io);
  if (const int* code = std::get_if<int>(&built)) return *code;
  const Built& b = std::get<Built>(built);
  if (!WriteGraphFiles(o, b, io.err)) return kExitBadInput;

  const graph::GraphCounts counts = graph::CountGraph(b.graph);
  std::ostringstream t;
  t << std::setprecision(3);
  PrintFound(t, o.scene_path, b, counts);
  PrintSaturation(t, b);
  PrintReach(t, b);
  if (!o.verdicts_path.empty()) PrintVerdictCounts(t, o.verdicts_path, counts);
  if (o.check > 0)
    PrintCompleteness(t, graph::CheckCompleteness(b.scene, b.graph, b.explore, o.check));
  PrintWritten(t, o);
  io.out << t.str();
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
                  "after exploring, run N random guarded motions of another seed and report the "
                  "states and transitions they reach that the graph lacks (docs/graph.md)")
      ->check(CLI::Range(0, 100000));
  AddGraphOptions(sub, *options);
  return {sub, [options, streams] { return RunGraph(*options, streams); }};
}

}  // namespace tubeplan::cli
