#include <algorithm>
#include <set>
#include <sstream>
#include <utility>

#include <tubeplan/graph/summary.hpp>

namespace tubeplan::graph {
namespace {

using Pairs = std::set<std::pair<states::TubeElement, std::string>>;

Pairs ElementPairs(const states::ContactFormation& cf) {
  Pairs pairs;
  for (const states::PrincipalContact& pc : cf.contacts) pairs.insert({pc.tube, pc.part_element});
  return pairs;
}

std::set<std::string> PartElements(const states::ContactFormation& cf) {
  std::set<std::string> elements;
  for (const states::PrincipalContact& pc : cf.contacts) elements.insert(pc.part_element);
  return elements;
}

}  // namespace

GraphCounts CountGraph(const ContactGraph& graph) {
  GraphCounts c;
  for (const Arc& a : graph.arcs) {
    c.kept_arcs += a.kept;
    c.simultaneous_arcs += a.simultaneous;
    c.feasible_arcs += a.batch == BatchResult::kFeasible;
    c.infeasible_arcs += a.batch == BatchResult::kInfeasible;
    c.replay_arcs += a.from_replay;
  }
  for (const Node& n : graph.nodes) c.replay_nodes += n.from_replay;
  for (const Motion& m : graph.motions) ++c.motions_by_kind[m.kind.substr(0, m.kind.find(' '))];
  return c;
}

std::vector<int> NearGoal(const ContactGraph& graph, const states::ContactFormation& goal,
                          std::size_t most) {
  const Pairs goal_pairs = ElementPairs(goal);
  const std::set<std::string> goal_elements = PartElements(goal);
  std::vector<int> same_pairs, touching;
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    const states::ParseResult parsed = states::ParseContactFormation(graph.nodes[i].cf);
    if (!parsed.cf || parsed.cf->contacts.empty()) continue;
    if (ElementPairs(*parsed.cf) == goal_pairs) same_pairs.push_back(int(i));
    const std::set<std::string> elements = PartElements(*parsed.cf);
    if (std::includes(elements.begin(), elements.end(), goal_elements.begin(), goal_elements.end()))
      touching.push_back(int(i));
  }
  std::vector<int> near = same_pairs.empty() ? touching : same_pairs;
  std::stable_sort(near.begin(), near.end(), [&](int a, int b) {
    return graph.nodes[std::size_t(a)].min_force_N < graph.nodes[std::size_t(b)].min_force_N;
  });
  if (near.size() > most) near.resize(most);
  return near;
}

std::string NearGoalText(const ContactGraph& graph, const states::ContactFormation& goal,
                         std::size_t most) {
  std::ostringstream t;
  t.precision(3);
  for (const int i : NearGoal(graph, goal, most)) {
    const Node& n = graph.nodes[std::size_t(i)];
    t << (t.tellp() > 0 ? ", " : "") << n.cf << " (" << n.min_force_N << " N)";
  }
  return t.str();
}

}  // namespace tubeplan::graph
