// The contact-state graph's printout.
#include <algorithm>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <string>

#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/summary.hpp>
#include <tubeplan/report/graph_report.hpp>
#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::report {
namespace {

// What was found: states, transitions, the motions by kind, the work done.
void PrintFound(std::ostream& t, const std::string& scene_path, const graph::ContactGraph& g,
                const graph::ExploreOptions& explore, const graph::GraphCounts& counts) {
  t << scene_path << ": " << g.nodes.size() << " contact formations, " << g.arcs.size()
    << " transitions (" << counts.kept_arcs << " kept by pruning, " << counts.simultaneous_arcs
    << " simultaneous) from " << g.motions.size() << " motions (";
  bool first = true;
  for (const auto& [kind, n] : counts.motions_by_kind)
    t << (first ? "" : ", ") << n << " " << kind, first = false;
  t << "), " << g.ticks << " core ticks, " << g.refinements << " steps refined, " << g.held_back
    << " motions ended where the operator force passed the explorer's limit or the tube no "
       "longer followed the hand; "
    << g.seconds << " s on " << explore.jobs << " thread" << (explore.jobs > 1 ? "s" : "") << "\n";
}

// The saturation curve (about a dozen points) and whether, or why not, the graph saturated.
void PrintSaturation(std::ostream& t, const graph::ContactGraph& g,
                     const graph::ExploreOptions& explore) {
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
    if (g.closing_rounds > 0) {
      t << "then " << g.closing_rounds << " closing round" << (g.closing_rounds == 1 ? "" : "s")
        << " of ";
      if (explore.closing_motions > 0) t << explore.closing_motions << " random motions";
      if (explore.closing_motions > 0 && explore.replay_copies > 0) t << " and ";
      if (explore.replay_copies > 0)
        t << explore.replay_copies << " perturbed replays of each candidate plan";
      t << ", the last adding no state and no transition)\n";
    } else {
      t << "every state probed; no closing rounds)\n";
    }
  } else if (g.end == graph::ExploreEnd::kTimeLimit) {
    const bool goal_held = g.goal >= 0 && g.nodes[std::size_t(g.goal)].ticks > 0;
    t << "  (NOT saturated: stopped by the time limit of " << explore.time_limit_s << " s"
      << (goal_held ? ""
                    : " and the " + std::to_string(int(graph::kGoalSearch_s)) +
                          " s more it allows while the goal has no stay")
      << " after " << g.motions.size() << " motions, with " << g.probed << " of " << g.nodes.size()
      << " states probed, " << g.closing_rounds
      << " closing rounds; a larger --time-limit, or 0, explores on to the budget)\n";
  } else {
    t << "  (NOT saturated: stopped by the budget of " << explore.max_motions << " motions, with "
      << g.probed << " of " << g.nodes.size() << " states probed, " << g.closing_rounds
      << " closing rounds)\n";
  }
}

// Start and goal, and the part elements the tube touched and never touched.
void PrintReach(std::ostream& t, const graph::ContactGraph& g, const scene::Scene& scene) {
  t << "start "
    << (g.start >= 0 ? g.nodes[std::size_t(g.start)].cf : "not reached (no motion ended)")
    << "; goal " << states::ToString(scene.goal)
    << (g.goal < 0 ? " NEVER reached: no plan can be extracted"
        : g.nodes[std::size_t(g.goal)].ticks == 0
            ? " reached only in passing (no stay of it lasted the dwell)"
            : " reached")
    << "\n";
  const std::string near = g.goal < 0 ? graph::NearGoalText(g, scene.goal, 4) : "";
  if (!near.empty()) t << "  nearest states reached (least operator force): " << near << "\n";
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
  t << "completeness: " << c.motions << " independent " << c.motions_of << " counted "
    << c.states_seen << " states, " << c.states_in_graph << " in the graph ("
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

// The files written, each on its line.
void PrintWritten(std::ostream& t, const GraphFiles& written) {
  if (!written.dot_path.empty()) t << "DOT written to " << written.dot_path << "\n";
  if (!written.svg_path.empty()) t << "SVG (Graphviz dot) written to " << written.svg_path << "\n";
  if (!written.json_path.empty()) t << "JSON written to " << written.json_path << "\n";
}

}  // namespace

void PrintGraph(std::ostream& out, const std::string& scene_path, const scene::Scene& scene,
                const graph::ContactGraph& graph, const graph::ExploreOptions& explore,
                const std::string& verdicts_path, std::span<const graph::Completeness> completeness,
                const GraphFiles& written) {
  const graph::GraphCounts counts = graph::CountGraph(graph);
  std::ostringstream t;
  t << std::setprecision(3);
  PrintFound(t, scene_path, graph, explore, counts);
  PrintSaturation(t, graph, explore);
  PrintReach(t, graph, scene);
  if (!verdicts_path.empty()) PrintVerdictCounts(t, verdicts_path, counts);
  for (const graph::Completeness& c : completeness) PrintCompleteness(t, c);
  PrintWritten(t, written);
  out << t.str();
}

}  // namespace tubeplan::report
