#include <map>

#include <tubeplan/graph/verdicts.hpp>

namespace tubeplan::graph {

int ApplyVerdicts(ContactGraph& graph, const std::vector<ReplayedPlan>& plans) {
  std::map<std::string, int> node_of;
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) node_of[graph.nodes[i].cf] = int(i);
  std::map<std::pair<int, int>, std::size_t> arc_of;
  for (std::size_t i = 0; i < graph.arcs.size(); ++i)
    arc_of[{graph.arcs[i].from, graph.arcs[i].to}] = i;
  int added = 0;
  auto node = [&](const std::string& cf) {
    const auto [it, inserted] = node_of.try_emplace(cf, int(graph.nodes.size()));
    if (inserted) {
      Node n;
      n.cf = cf;
      n.from_replay = true;
      graph.nodes.push_back(n);
      ++added;
    }
    return it->second;
  };
  auto arc = [&](int from, int to) -> Arc& {
    const auto [it, inserted] = arc_of.try_emplace({from, to}, graph.arcs.size());
    if (inserted) {
      Arc a;
      a.from = from, a.to = to;
      a.kept = false;
      a.reason = "seen in a batch replay only";
      a.from_replay = true;
      graph.arcs.push_back(a);
    }
    return graph.arcs[it->second];
  };
  auto mark = [](Arc& a, bool feasible) {
    if (feasible) {
      a.batch = BatchResult::kFeasible;
    } else if (a.batch != BatchResult::kFeasible) {
      a.batch = BatchResult::kInfeasible;
    }
  };
  for (const ReplayedPlan& p : plans) {
    for (std::size_t k = 0; k + 1 < p.observed.size(); ++k) {
      Arc& a = arc(node(p.observed[k].second), node(p.observed[k + 1].second));
      ++a.count;
      // Which planned transition was under way when the replay took this step.
      const double t = p.observed[k + 1].first;
      for (const ReplayedPlan::Transition& tr : p.transitions) {
        if (t > tr.t_start_s && t <= tr.t_end_s) mark(a, tr.feasible);
      }
    }
    for (const ReplayedPlan::Transition& tr : p.transitions) {
      const auto f = node_of.find(tr.from), to = node_of.find(tr.to);
      if (f == node_of.end() || to == node_of.end()) continue;
      if (const auto it = arc_of.find({f->second, to->second}); it != arc_of.end())
        mark(graph.arcs[it->second], tr.feasible);
    }
  }
  return added;
}

}  // namespace tubeplan::graph
