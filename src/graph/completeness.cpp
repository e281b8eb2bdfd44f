#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include <tubeplan/core/core.hpp>
#include <tubeplan/graph/completeness.hpp>

namespace tubeplan::graph {

Completeness CheckCompleteness(const scene::Scene& scene, const ContactGraph& graph,
                               std::span<const Motion> motions, double dwell_s,
                               double force_limit_N) {
  std::set<std::string> nodes;
  std::set<std::pair<std::string, std::string>> arcs;
  for (const Node& n : graph.nodes) nodes.insert(n.cf);
  for (const Arc& a : graph.arcs)
    arcs.insert({graph.nodes[std::size_t(a.from)].cf, graph.nodes[std::size_t(a.to)].cf});
  // A two-PC change the graph records through a brief state in between (A -> C -> B).
  const auto in_graph = [&](const std::pair<std::string, std::string>& a) {
    if (arcs.contains(a)) return true;
    return std::any_of(nodes.begin(), nodes.end(), [&](const std::string& c) {
      return arcs.contains({a.first, c}) && arcs.contains({c, a.second});
    });
  };

  const double step_s = scene.model.time_step_s;
  const int dwell = std::max(1, static_cast<int>(std::lround(dwell_s / step_s)));
  std::map<std::string, long> ticks_in;                      // ticks spent per state
  std::map<std::pair<std::string, std::string>, int> taken;  // transitions counted
  std::set<std::string> seen;                                // states counted
  core::Core core(scene);
  for (const Motion& m : motions) {
    core.Reset(scene.X_WH_start);
    MotionRunner runner(m, scene.X_WH_start, step_s);
    std::string counted, current;
    int held = 0;
    for (int k = 1; !runner.Done(); ++k) {
      const core::StepOutput& out = core.Step(k * step_s, runner.Next(core.last()));
      if ((out.flags & core::kProxySeparated) || out.force_W_N.norm() > force_limit_N) break;
      const std::string cf = core.FormationText();
      ++ticks_in[cf];
      held = cf == current ? held + 1 : 1;
      current = cf;
      if (k == 1) counted = cf, seen.insert(cf);
      if (held == dwell && cf != counted) {
        ++taken[{counted, cf}];
        seen.insert(cf);
        counted = cf;
      }
    }
  }

  Completeness c;
  c.motions_of = "motions";
  c.motions = static_cast<int>(motions.size());
  for (const auto& [cf, ticks] : ticks_in) {
    c.ticks += ticks;
    if (nodes.contains(cf)) c.ticks_in_graph += ticks;
  }
  for (const std::string& cf : seen) {
    ++c.states_seen;
    if (nodes.contains(cf))
      ++c.states_in_graph;
    else
      c.missing_states.push_back(cf);
  }
  for (const auto& [a, n] : taken) {
    ++c.transitions_seen;
    c.taken += n;
    if (in_graph(a)) {
      ++c.transitions_in_graph;
      c.taken_in_graph += n;
    } else {
      c.missing_transitions.push_back({a, n});
    }
  }
  return c;
}

std::vector<Completeness> CheckCompleteness(const scene::Scene& scene, const ContactGraph& graph,
                                            const ExploreOptions& explore, int count) {
  const std::uint64_t seed = explore.seed + 1000003;
  const double limit_N = ExploreForceLimit(scene, explore);
  std::vector<Completeness> found;
  found.push_back(CheckCompleteness(scene, graph, RandomMotions(scene, seed, 0, count, explore),
                                    explore.dwell_s, limit_N));
  found.back().motions_of = "random guarded motions";
  const std::vector<trajectories::Trajectory> nominals =
      CandidateTrajectories(scene, graph, explore);
  if (nominals.empty()) return found;
  const int copies =
      (count + static_cast<int>(nominals.size()) - 1) / static_cast<int>(nominals.size());
  found.push_back(CheckCompleteness(scene, graph,
                                    PerturbedReplays(scene, nominals, explore, seed, 0, copies),
                                    explore.dwell_s, limit_N));
  found.back().motions_of = "perturbed candidate replays";
  return found;
}

}  // namespace tubeplan::graph
