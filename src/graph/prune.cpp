#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/breadth_first_search.hpp>
#include <boost/graph/reverse_graph.hpp>

#include <tubeplan/graph/contact_graph.hpp>

namespace tubeplan::graph {

namespace {

struct Scales {
  double friction_N = 1.0, energy_J = 1.0, distance_m = 1.0;
};

Scales ScalesOf(const ContactGraph& graph) {
  Scales s{0.0, 0.0, 0.0};
  for (const Node& n : graph.nodes) {
    s.friction_N = std::max(s.friction_N, std::abs(n.friction_limit_N));
    s.energy_J = std::max(s.energy_J, std::abs(n.energy_J));
    s.distance_m = std::max(s.distance_m, std::abs(n.distance_m));
  }
  // A criterion that is zero everywhere (a frictionless scene) scores zero, not 0/0.
  if (s.friction_N <= 0.0) s.friction_N = 1.0;
  if (s.energy_J <= 0.0) s.energy_J = 1.0;
  if (s.distance_m <= 0.0) s.distance_m = 1.0;
  return s;
}

// Transitions from each node to the goal (breadth-first search from the goal over reversed
// arcs), along every arc or along the kept ones only; -1 where there is no path.
enum class Along { kEveryArc, kKeptArcs };
std::vector<int> HopsToGoal(const ContactGraph& graph, Along along) {
  using G = boost::adjacency_list<boost::vecS, boost::vecS, boost::bidirectionalS>;
  G g(graph.nodes.size());
  for (const Arc& a : graph.arcs)
    if (a.from != a.to && (along == Along::kEveryArc || a.kept))
      boost::add_edge(std::size_t(a.from), std::size_t(a.to), g);
  std::vector<int> hops(graph.nodes.size(), -1);
  if (graph.goal < 0) return hops;
  hops[std::size_t(graph.goal)] = 0;
  const auto reversed = boost::make_reverse_graph(g);
  struct Recorder : boost::default_bfs_visitor {
    std::vector<int>* hops;
    void tree_edge(boost::graph_traits<decltype(reversed)>::edge_descriptor e,
                   const decltype(reversed)& rg) const {
      (*hops)[boost::target(e, rg)] = (*hops)[boost::source(e, rg)] + 1;
    }
  };
  Recorder recorder;
  recorder.hops = &hops;
  boost::breadth_first_search(reversed, std::size_t(graph.goal), boost::visitor(recorder));
  return hops;
}

// Each heuristic decides at one node, and together they can cut every way to the goal (arcs
// nearer by distance lead into a part of the graph whose kept arcs lead back). A node with a way
// to the goal but none along the kept arcs keeps back its arcs one transition nearer the goal
// (none back into the start, which no shortest way from the start needs: its nodes are all
// nearer than the start): by induction on the transitions left, the start then reaches the goal
// along kept arcs whenever it does at all.
void KeepAWayToTheGoal(ContactGraph& graph, const std::vector<int>& hops) {
  const std::vector<int> kept_hops = HopsToGoal(graph, Along::kKeptArcs);
  for (Arc& a : graph.arcs) {
    const int hu = hops[std::size_t(a.from)], hv = hops[std::size_t(a.to)];
    if (a.kept || a.from == graph.goal || a.to == graph.start) continue;
    if (hu < 0 || kept_hops[std::size_t(a.from)] >= 0 || hv != hu - 1) continue;
    a.kept = true;
    a.reason.clear();
  }
}

// "a <= b unit", three significant digits.
std::string NoWorse(double a, double b, const char* unit) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "%.3g <= %.3g %s", a, b, unit);
  return buffer;
}

}  // namespace

int ContactGraph::FindNode(const std::string& cf) const {
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].cf == cf) return static_cast<int>(i);
  return -1;
}

double ArcScore(const ContactGraph& graph, const Arc& arc, const PruneWeights& weights) {
  const Scales s = ScalesOf(graph);
  const Node& u = graph.nodes[std::size_t(arc.from)];
  const Node& v = graph.nodes[std::size_t(arc.to)];
  return weights.friction * v.friction_limit_N / s.friction_N +
         weights.energy * (v.energy_J - u.energy_J) / s.energy_J +
         weights.distance * std::max(v.distance_m, 0.0) / s.distance_m;
}

void Prune(ContactGraph& graph, const PruneWeights& weights) {
  const std::vector<int> hops = HopsToGoal(graph, Along::kEveryArc);
  auto distance = [&](int node) { return graph.nodes[std::size_t(node)].distance_m; };
  // Towards the goal: nearer to it by distance (the paper's distance heuristic). A node none of
  // whose arcs gets nearer keeps those that are one transition nearer, so it is no dead end.
  std::vector<bool> has_nearer(graph.nodes.size(), false);
  for (const Arc& a : graph.arcs) {
    if (a.from != graph.goal && a.to != graph.start && hops[std::size_t(a.to)] >= 0 &&
        (a.to == graph.goal || distance(a.to) < distance(a.from)))
      has_nearer[std::size_t(a.from)] = true;
  }
  for (Arc& a : graph.arcs) {
    a.kept = true;
    a.reason.clear();
    const int hu = hops[std::size_t(a.from)], hv = hops[std::size_t(a.to)];
    const bool nearer = a.to == graph.goal || distance(a.to) < distance(a.from);
    if (graph.goal < 0) {
      a.kept = false, a.reason = "the goal was never reached";
    } else if (a.from == graph.goal) {
      a.kept = false, a.reason = "leaves the goal";
    } else if (a.to == graph.start) {
      a.kept = false, a.reason = "returns to the start";
    } else if (hv < 0) {
      a.kept = false, a.reason = "no path from its target to the goal";
    } else if (has_nearer[std::size_t(a.from)] ? !nearer : !(hv < hu)) {
      char buffer[160];
      std::snprintf(buffer, sizeof buffer,
                    "leads away from the goal (%.1f mm and %d transitions from it, the source "
                    "%.1f mm and %d)",
                    distance(a.to) * 1e3, hv, distance(a.from) * 1e3, hu);
      a.kept = false, a.reason = buffer;
    }
  }
  // Criteria of an arc u -> v, lower is better: the friction the new state can resist with, the
  // change of bending energy, the remaining distance to the goal.
  auto criteria = [&](const Arc& a) {
    const Node& u = graph.nodes[std::size_t(a.from)];
    const Node& v = graph.nodes[std::size_t(a.to)];
    return std::array<double, 3>{v.friction_limit_N, v.energy_J - u.energy_J,
                                 std::max(v.distance_m, 0.0)};
  };
  for (std::size_t u = 0; u < graph.nodes.size(); ++u) {
    std::vector<std::size_t> candidates;
    for (std::size_t i = 0; i < graph.arcs.size(); ++i)
      if (graph.arcs[i].kept && std::size_t(graph.arcs[i].from) == u) candidates.push_back(i);
    // Dominance is decided on all candidates at once, before any is dropped, so the result does
    // not depend on the order of the arcs.
    std::vector<std::string> reasons(candidates.size());
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const auto ci = criteria(graph.arcs[candidates[i]]);
      for (std::size_t j = 0; j < candidates.size() && reasons[i].empty(); ++j) {
        if (i == j) continue;
        const auto cj = criteria(graph.arcs[candidates[j]]);
        bool no_worse = true, better = false;
        for (int k = 0; k < 3; ++k) {
          no_worse = no_worse && cj[std::size_t(k)] <= ci[std::size_t(k)];
          better = better || cj[std::size_t(k)] < ci[std::size_t(k)];
        }
        if (no_worse && better) {
          const Node& w = graph.nodes[std::size_t(graph.arcs[candidates[j]].to)];
          reasons[i] = "dominated by -> " + w.cf + ": friction " + NoWorse(cj[0], ci[0], "N") +
                       ", energy change " + NoWorse(cj[1], ci[1], "J") + ", distance " +
                       NoWorse(cj[2], ci[2], "m");
        }
      }
    }
    // The best score among the candidates (a dominated arc never scores below the arc that
    // dominates it when all weights are positive, but weights may be zero).
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_arc = 0;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const double score = ArcScore(graph, graph.arcs[candidates[i]], weights);
      if (score < best) best = score, best_arc = candidates[i];
    }
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (reasons[i].empty()) continue;  // on the Pareto front: kept whatever its score
      Arc& a = graph.arcs[candidates[i]];
      const double score = ArcScore(graph, a, weights);
      if (score <= best + weights.tolerance) continue;  // dominated, but nearly as good
      char buffer[96];
      std::snprintf(buffer, sizeof buffer, "; score %.3f > best %.3f + tolerance (-> ", score,
                    best);
      a.kept = false;
      a.reason = reasons[i] + buffer + graph.nodes[std::size_t(graph.arcs[best_arc].to)].cf + ")";
    }
  }
  if (graph.goal >= 0) KeepAWayToTheGoal(graph, hops);
}

}  // namespace tubeplan::graph
