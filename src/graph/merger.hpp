#pragma once
// Merging the explorer's motion results into the graph: a node per CF with its witness and the
// stay its probe starts from, an arc per change. Internal to the explorer
// (src/graph/explore.cpp).

#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/scene/scene.hpp>

#include "graph/run_motion.hpp"

namespace tubeplan::graph::explorer {

class Merger {
 public:
  // `witness_limit_N`: a stay with a larger operator force is a witness only where the node has
  // no stay within it.
  Merger(ContactGraph& graph, double witness_limit_N)
      : graph_(graph), witness_limit_N_(witness_limit_N) {}

  // Returns whether the result added a node or an arc.
  bool Add(const MotionResult& r);

  // A run point of node i's probe motion at or before its prefix's end (null: replay it whole).
  // Handed over once: the merger keeps no snapshots of probed nodes.
  RunPointPtr TakeProbePoint(int i) { return std::move(entry_[std::size_t(i)].point); }

  // Whether a stay of `cf` (refined or not, at `ticks` of its motion) would become the place its
  // probe starts from, as Add chooses it, if no stay merged after now beat it; `probed` says which
  // nodes have had their probe.
  bool MayEnter(const std::string& cf, bool refined, int ticks, std::span<const char> probed) const;

  // Node i's probe motion: the prefix of the motion of its quickest stay to replay, then the
  // neighbour probes from the hand pose there.
  Motion ProbeMotion(int i, const scene::Scene& scene, const ExploreOptions& o) const;

 private:
  struct Best {
    long length = -1;
    bool refined = true;
    bool within = false;  // its operator force within the witness limit
  };
  struct Entry {     // where probes start from (a stay of the node)
    int ticks = -1;  // ticks of its motion up to there
    bool refined = true;
    int motion = 0, move = 0, move_tick = 0;
    Eigen::Isometry3d X_W_hand = Eigen::Isometry3d::Identity();
    RunPointPtr point;
  };
  int NodeOf(const std::string& cf);
  ContactGraph& graph_;
  double witness_limit_N_;
  std::map<std::string, int> node_of_;
  std::map<std::pair<int, int>, int> arc_of_;
  std::vector<Best> best_;
  std::vector<Entry> entry_;
};

}  // namespace tubeplan::graph::explorer
