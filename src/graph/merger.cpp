#include "graph/merger.hpp"

#include "graph/explorer_motions.hpp"

namespace tubeplan::graph::explorer {

bool Merger::Add(const MotionResult& r) {
  const std::size_t nodes = graph_.nodes.size(), arcs = graph_.arcs.size();
  for (std::size_t j = 0; j < r.stays.size(); ++j) {
    const Stay& s = r.stays[j];
    const int i = NodeOf(s.cf);
    Node& n = graph_.nodes[std::size_t(i)];
    if (!s.refined) n.ticks += s.length;
    // The stay of least force, with its poses: another witness to aim at (a brief bridge's
    // too: every aim is replayed and judged, and one that does not hold the state is not kept).
    if (s.sample.force_N < n.min_force_N) {
      n.min_force_N = s.sample.force_N;
      n.X_W_hand_least = s.sample.X_W_hand;
      n.X_WH_least = s.sample.X_WH;
    }
    // The witness: a stay within the force limit before any beyond it, then a settled stay
    // before a refined one, then the longest.
    Best& best = best_[std::size_t(i)];
    const bool within = s.sample.force_N <= witness_limit_N_;
    const bool better =
        best.length < 0 || (within && !best.within) ||
        (within == best.within &&
         ((best.refined && !s.refined) || (best.refined == s.refined && s.length > best.length)));
    // Probes start from the settled stay that is quickest to replay (any stay if none is).
    const int ticks = s.witness.substeps > 0 ? s.witness.tick - 1 : s.witness.tick;
    Entry& entry = entry_[std::size_t(i)];
    if (entry.ticks < 0 || (entry.refined && !s.refined) ||
        (entry.refined == s.refined && ticks < entry.ticks)) {
      entry = {ticks,
               s.refined,
               s.witness.motion,
               s.sample.move,
               s.sample.move_tick,
               s.sample.X_W_hand,
               s.witness.substeps == 0 ? r.stay_points[j] : nullptr};
    }
    if (better) {
      best = {s.length, s.refined, within};
      n.pcs = s.pcs;
      n.witness = s.witness;
      n.X_W_hand = s.sample.X_W_hand;
      n.X_WH = s.sample.X_WH;
      n.energy_J = s.sample.energy_J;
      n.friction_N = s.sample.friction_N;
      n.friction_limit_N = s.sample.friction_limit_N;
      n.force_N = s.sample.force_N;
    }
  }
  for (const Change& c : r.changes) {
    const int from = NodeOf(c.from), to = NodeOf(c.to);
    const auto [it, inserted] = arc_of_.try_emplace({from, to}, int(graph_.arcs.size()));
    if (inserted) {
      Arc a;
      a.from = from, a.to = to, a.simultaneous = c.simultaneous, a.witness = c.at;
      graph_.arcs.push_back(a);
    }
    Arc& a = graph_.arcs[std::size_t(it->second)];
    ++a.count;
    // Simultaneous only if it was never produced as a single change.
    a.simultaneous = a.simultaneous && c.simultaneous;
  }
  graph_.ticks += r.ticks;
  graph_.refinements += r.refinements;
  graph_.held_back += r.held_back ? 1 : 0;
  graph_.saturation.push_back({static_cast<int>(graph_.saturation.size()) + 1,
                               static_cast<int>(graph_.nodes.size()),
                               static_cast<int>(graph_.arcs.size())});
  return graph_.nodes.size() > nodes || graph_.arcs.size() > arcs;
}

bool Merger::MayEnter(const std::string& cf, bool refined, int ticks,
                      std::span<const char> probed) const {
  const auto it = node_of_.find(cf);
  if (it == node_of_.end()) return true;
  if (std::size_t(it->second) < probed.size() && probed[std::size_t(it->second)]) return false;
  const Entry& entry = entry_[std::size_t(it->second)];
  return entry.ticks < 0 || (entry.refined && !refined) ||
         (entry.refined == refined && ticks < entry.ticks);
}

Motion Merger::ProbeMotion(int i, const scene::Scene& scene, const ExploreOptions& o) const {
  const Entry& e = entry_[std::size_t(i)];
  Motion m;
  m.kind = "probe " + graph_.nodes[std::size_t(i)].cf;
  m.moves = Prefix(graph_.motions[std::size_t(e.motion)], e.move, e.move_tick);
  m.prefix_ticks = e.ticks;
  const std::vector<Move> probes = Probes(scene, e.X_W_hand, o);
  m.moves.insert(m.moves.end(), probes.begin(), probes.end());
  return m;
}

int Merger::NodeOf(const std::string& cf) {
  const auto [it, inserted] = node_of_.try_emplace(cf, int(graph_.nodes.size()));
  if (inserted) {
    Node n;
    n.cf = cf;
    graph_.nodes.push_back(std::move(n));
    best_.push_back({});
    entry_.push_back({});
  }
  return it->second;
}

}  // namespace tubeplan::graph::explorer
