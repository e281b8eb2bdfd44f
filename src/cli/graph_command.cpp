// `tubeplan graph SCENE [--dot FILE] [--json FILE] [--unpruned] [--seed N] [--random N]
// [--jobs N] [--weights friction=1,energy=1,distance=1] [--tolerance T]`: explores the scene with
// the core, prunes the contact-state graph with the paper's heuristics and writes it as DOT and
// JSON (schema in docs/graph.md). stdout: what was found, the saturation curve, the time taken.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <thread>
#include <tuple>
#include <unistd.h>
#include <variant>

#include <nlohmann/json.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/graph/completeness.hpp>
#include <tubeplan/graph/dot.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/motion.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/graph/verdicts.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/plan/candidates.hpp>
#include <tubeplan/report/graph_json.hpp>
#include <tubeplan/report/graphviz.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "graph_build.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

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
  const scene::Scene& s = b.scene;
  const graph::ContactGraph& g = b.graph;
  const graph::ExploreOptions& explore = b.explore;
  const graph::PruneWeights& weights = b.weights;

  graph::DotOptions dot;
  dot.dropped_arcs = o.unpruned;
  dot.title = "tubeplan: contact-state graph of " + s.name + (o.unpruned ? " (unpruned)" : "");
  const std::string dot_text =
      o.dot_path.empty() && o.svg_path.empty() ? std::string() : graph::FormatDot(g, dot);
  if (!o.dot_path.empty()) {
    if (const std::string e = io::WriteTextFileAtomically(o.dot_path, dot_text); !e.empty()) {
      io.err << o.dot_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  }
  if (!o.svg_path.empty()) {
    const report::SvgFromDot svg = report::RenderDot(dot_text);
    if (!svg.error.empty()) {
      io.err << "tubeplan graph: error: " << svg.error << "\n";
      return kExitBadInput;
    }
    io.err << svg.warnings;
    if (const std::string e = io::WriteTextFileAtomically(o.svg_path, svg.svg); !e.empty()) {
      io.err << o.svg_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  }
  if (!o.json_path.empty()) {
    const nlohmann::json j = report::GraphToJson(g, s, o.scene_path, explore, weights);
    if (const std::string e = io::WriteTextFileAtomically(o.json_path, j.dump(1) + "\n");
        !e.empty()) {
      io.err << o.json_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  }

  const long kept =
      std::count_if(g.arcs.begin(), g.arcs.end(), [](const auto& a) { return a.kept; });
  const long simultaneous =
      std::count_if(g.arcs.begin(), g.arcs.end(), [](const auto& a) { return a.simultaneous; });
  std::map<std::string, int> kinds;
  for (const graph::Motion& m : g.motions) ++kinds[m.kind.substr(0, m.kind.find(' '))];
  std::ostringstream t;
  t << std::setprecision(3);
  t << o.scene_path << ": " << g.nodes.size() << " contact formations, " << g.arcs.size()
    << " transitions (" << kept << " kept by pruning, " << simultaneous << " simultaneous) from "
    << g.motions.size() << " motions (";
  bool first = true;
  for (const auto& [kind, n] : kinds) t << (first ? "" : ", ") << n << " " << kind, first = false;
  t << "), " << g.ticks << " core ticks, " << g.refinements << " steps refined, " << g.held_back
    << " motions ended where the coupling reached the device's force (the tube no longer followed "
       "the hand); "
    << g.seconds << " s on " << explore.jobs << " thread" << (explore.jobs > 1 ? "s" : "") << "\n";
  t << "saturation (motions: nodes/arcs):";
  const std::size_t every = std::max<std::size_t>(1, g.saturation.size() / 12);
  for (std::size_t i = 0; i < g.saturation.size(); ++i) {
    if (i % every != 0 && i + 1 != g.saturation.size()) continue;
    const graph::SaturationPoint& p = g.saturation[i];
    t << " " << p.motions << ": " << p.nodes << "/" << p.arcs;
  }
  if (g.saturated) {
    constexpr int kProbes =
        2 * 3 + 2 * 2;  // graph::Explore's probe set: 3 steps, 2 turns, each way
    t << "  (saturated: every one of the " << g.probed << " states probed from a stay with "
      << kProbes << " small motions (" << explore.probe_step_m * 1e3
      << " mm along and against 3 directions, " << explore.probe_turn_rad * 180.0 / std::numbers::pi
      << " deg about 2 axes), the last round found no new state)\n";
  } else if (g.end == graph::ExploreEnd::kTimeLimit) {
    t << "  (NOT saturated: stopped by the time limit of " << explore.time_limit_s << " s after "
      << g.motions.size() << " motions, with " << g.probed << " of " << g.nodes.size()
      << " states probed)\n";
  } else {
    t << "  (NOT saturated: stopped by the budget of " << explore.max_motions << " motions, with "
      << g.probed << " of " << g.nodes.size() << " states probed)\n";
  }
  t << "start "
    << (g.start >= 0 ? g.nodes[std::size_t(g.start)].cf : "not reached (no motion ended)")
    << "; goal " << states::ToString(s.goal)
    << (g.goal >= 0 ? " reached" : " NEVER reached: no plan can be extracted") << "\n";
  t << "part elements touched: " << g.reached_elements.size()
    << "; never touched: " << g.unreached_elements.size();
  for (std::size_t i = 0; i < g.unreached_elements.size() && i < 8; ++i)
    t << (i == 0 ? " (" : ", ") << g.unreached_elements[i];
  if (!g.unreached_elements.empty()) t << (g.unreached_elements.size() > 8 ? ", ...)" : ")");
  t << "\n";
  if (!o.verdicts_path.empty()) {
    auto count = [&](graph::BatchResult result) {
      return std::count_if(g.arcs.begin(), g.arcs.end(),
                           [&](const auto& a) { return a.batch == result; });
    };
    t << "verdicts from " << o.verdicts_path << ": " << count(graph::BatchResult::kFeasible)
      << " arcs feasible, " << count(graph::BatchResult::kInfeasible) << " infeasible; "
      << std::count_if(g.nodes.begin(), g.nodes.end(), [](const auto& n) { return n.from_replay; })
      << " states and "
      << std::count_if(g.arcs.begin(), g.arcs.end(), [](const auto& a) { return a.from_replay; })
      << " transitions seen only in the replays added\n";
  }
  if (o.check > 0) {
    // Random motions of another seed than the explorer's: motions it did not make.
    const std::vector<graph::Motion> motions =
        graph::RandomMotions(s, o.seed + 1000003, 0, o.check, explore);
    const graph::Completeness c = graph::CheckCompleteness(s, g, motions, explore.dwell_s);
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
  if (!o.dot_path.empty()) t << "DOT written to " << o.dot_path << "\n";
  if (!o.svg_path.empty()) t << "SVG (Graphviz dot) written to " << o.svg_path << "\n";
  if (!o.json_path.empty()) t << "JSON written to " << o.json_path << "\n";
  io.out << t.str();
  return g.goal >= 0 ? kExitOk : kExitNegative;
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
