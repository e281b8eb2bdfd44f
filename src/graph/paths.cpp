#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/dijkstra_shortest_paths.hpp>
#include <boost/graph/filtered_graph.hpp>

#include <tubeplan/graph/paths.hpp>
#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::graph {

namespace {

using G = boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS, boost::no_property,
                                boost::property<boost::edge_weight_t, double>>;
using Edge = boost::graph_traits<G>::edge_descriptor;
using Vertex = boost::graph_traits<G>::vertex_descriptor;

// Yen's spur searches hide the root path's nodes and some arcs; a filtered view does that
// without copying the graph.
struct Hidden {
  const std::set<std::pair<std::size_t, std::size_t>>* arcs = nullptr;
  const std::vector<bool>* nodes = nullptr;
  const G* g = nullptr;
  bool operator()(const Edge& e) const {
    return !arcs->contains({boost::source(e, *g), boost::target(e, *g)});
  }
  bool operator()(const Vertex& v) const { return !(*nodes)[v]; }
};

// The cheapest path from `from` to `to` in the filtered graph, or an empty path.
Path Cheapest(const G& g, std::size_t from, std::size_t to,
              const std::set<std::pair<std::size_t, std::size_t>>& hidden_arcs,
              const std::vector<bool>& hidden_nodes) {
  const Hidden filter{&hidden_arcs, &hidden_nodes, &g};
  const boost::filtered_graph<G, Hidden, Hidden> view(g, filter, filter);
  const std::size_t n = boost::num_vertices(g);
  std::vector<Vertex> predecessor(n);
  std::vector<double> distance(n, std::numeric_limits<double>::infinity());
  boost::dijkstra_shortest_paths(
      view, from,
      boost::predecessor_map(boost::make_iterator_property_map(predecessor.begin(),
                                                               boost::get(boost::vertex_index, g)))
          .distance_map(boost::make_iterator_property_map(distance.begin(),
                                                          boost::get(boost::vertex_index, g))));
  Path path;
  // Boost's Dijkstra marks what it cannot reach with the largest double, not infinity.
  if (!(distance[to] < std::numeric_limits<double>::max())) return path;
  for (std::size_t v = to; v != from; v = predecessor[v]) path.nodes.push_back(int(v));
  path.nodes.push_back(int(from));
  std::reverse(path.nodes.begin(), path.nodes.end());
  path.cost = distance[to];
  return path;
}

}  // namespace

std::vector<double> ArcCosts(const ContactGraph& graph, const PruneWeights& weights) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const Arc& a : graph.arcs)
    if (a.kept) lowest = std::min(lowest, ArcScore(graph, a, weights));
  std::vector<double> cost;
  for (const Arc& a : graph.arcs) {
    cost.push_back(a.kept ? 1.0 + ArcScore(graph, a, weights) - lowest
                          : std::numeric_limits<double>::infinity());
  }
  return cost;
}

std::vector<Path> KShortestPaths(const ContactGraph& graph, const std::vector<double>& arc_cost,
                                 int k) {
  std::vector<Path> found;
  if (graph.start < 0 || graph.goal < 0 || k <= 0) return found;
  const std::size_t n = graph.nodes.size();
  G g(n);
  std::map<std::pair<int, int>, double> cost_of;
  for (std::size_t i = 0; i < graph.arcs.size(); ++i) {
    const Arc& a = graph.arcs[i];
    if (!std::isfinite(arc_cost[i]) || a.from == a.to) continue;
    boost::add_edge(std::size_t(a.from), std::size_t(a.to), arc_cost[i], g);
    cost_of[{a.from, a.to}] = arc_cost[i];
  }
  const std::size_t s = std::size_t(graph.start), t = std::size_t(graph.goal);
  Path first = Cheapest(g, s, t, {}, std::vector<bool>(n, false));
  if (first.nodes.empty()) return found;
  found.push_back(first);
  // Candidates ordered by cost, then node sequence: deterministic whatever the ties.
  auto order = [](const Path& a, const Path& b) {
    return a.cost != b.cost ? a.cost < b.cost : a.nodes < b.nodes;
  };
  std::set<Path, decltype(order)> candidates(order);
  while (static_cast<int>(found.size()) < k) {
    const Path& last = found.back();
    for (std::size_t i = 0; i + 1 < last.nodes.size(); ++i) {
      const std::vector<int> root(last.nodes.begin(), last.nodes.begin() + long(i) + 1);
      std::set<std::pair<std::size_t, std::size_t>> hidden_arcs;
      for (const Path& p : found) {
        if (p.nodes.size() > i + 1 && std::equal(root.begin(), root.end(), p.nodes.begin()))
          hidden_arcs.insert({std::size_t(p.nodes[i]), std::size_t(p.nodes[i + 1])});
      }
      std::vector<bool> hidden_nodes(n, false);
      for (std::size_t r = 0; r < i; ++r) hidden_nodes[std::size_t(root[r])] = true;
      const Path spur = Cheapest(g, std::size_t(root.back()), t, hidden_arcs, hidden_nodes);
      if (spur.nodes.empty()) continue;
      Path total;
      total.nodes = root;
      total.nodes.insert(total.nodes.end(), spur.nodes.begin() + 1, spur.nodes.end());
      // Recompute the cost by summing in path order, so equal paths have equal bits.
      for (std::size_t j = 0; j + 1 < total.nodes.size(); ++j)
        total.cost += cost_of[{total.nodes[j], total.nodes[j + 1]}];
      const bool known = std::any_of(found.begin(), found.end(),
                                     [&](const Path& p) { return p.nodes == total.nodes; });
      if (!known) candidates.insert(total);
    }
    if (candidates.empty()) break;
    found.push_back(*candidates.begin());
    candidates.erase(candidates.begin());
  }
  // The first path's cost, too, as a sum in path order.
  found.front().cost = 0.0;
  for (std::size_t j = 0; j + 1 < found.front().nodes.size(); ++j)
    found.front().cost += cost_of[{found.front().nodes[j], found.front().nodes[j + 1]}];
  return found;
}

namespace {

// Whether a CF's text has a PC on any element but the tube's outer side: the end's face or
// rim, or the bore's.
bool EndTouches(const std::string& cf) {
  const states::ParseResult parsed = states::ParseContactFormation(cf);
  if (!parsed.cf) return false;
  return std::any_of(
      parsed.cf->contacts.begin(), parsed.cf->contacts.end(),
      [](const states::PrincipalContact& pc) { return pc.tube != states::TubeElement::kSide; });
}

}  // namespace

std::vector<Eigen::Isometry3d> PathWaypoints(const scene::Scene& scene, const ContactGraph& graph,
                                             const Path& path, Aim aim) {
  std::vector<Eigen::Isometry3d> waypoints = {scene.X_WH_start};
  const double back_m = scene.tube.outer_radius_m + scene.contact.threshold_m;
  for (std::size_t j = 1; j < path.nodes.size(); ++j) {
    const Node& node = graph.nodes[std::size_t(path.nodes[j])];
    const Eigen::Isometry3d& X_WH_least =
        std::isfinite(node.min_force_N) ? node.X_WH_least : node.X_WH;
    switch (aim) {
      case Aim::kHand:
        waypoints.push_back(node.X_W_hand);
        break;
      case Aim::kHeld:
        waypoints.push_back(node.X_WH);
        break;
      case Aim::kLeastForce:
        waypoints.push_back(X_WH_least);
        break;
      case Aim::kOver:
        // From the start over the pose of the path's first state after it, where that is
        // lower than the start, then down (and on as kAlongAxis).
        if (j == 1 && X_WH_least.translation().z() < scene.X_WH_start.translation().z()) {
          Eigen::Isometry3d X_WH_over = X_WH_least;
          X_WH_over.translation().z() = scene.X_WH_start.translation().z();
          if (!X_WH_over.isApprox(scene.X_WH_start)) waypoints.push_back(X_WH_over);
        }
        [[fallthrough]];
      case Aim::kAlongAxis:
        // Where the end comes to touch: first drawn back along the tube, then straight in.
        if (EndTouches(node.cf) && !EndTouches(graph.nodes[std::size_t(path.nodes[j - 1])].cf)) {
          Eigen::Isometry3d X_WH_back = X_WH_least;
          X_WH_back.translation() -= back_m * X_WH_least.linear().col(2);
          waypoints.push_back(X_WH_back);
        }
        waypoints.push_back(X_WH_least);
        break;
    }
  }
  return waypoints;
}

std::vector<std::pair<Aim, std::vector<Eigen::Isometry3d>>> DistinctAims(
    const scene::Scene& scene, const ContactGraph& graph, const Path& path,
    std::span<const Aim> aims) {
  std::vector<std::pair<Aim, std::vector<Eigen::Isometry3d>>> distinct;
  for (const Aim aim : aims) {
    std::vector<Eigen::Isometry3d> w = PathWaypoints(scene, graph, path, aim);
    if (std::none_of(distinct.begin(), distinct.end(),
                     [&](const auto& a) { return SamePoses(a.second, w); }))
      distinct.emplace_back(aim, std::move(w));
  }
  return distinct;
}

bool SamePoses(std::span<const Eigen::Isometry3d> a, std::span<const Eigen::Isometry3d> b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](const Eigen::Isometry3d& x, const Eigen::Isometry3d& y) {
                      return x.matrix() == y.matrix();
                    });
}

}  // namespace tubeplan::graph
