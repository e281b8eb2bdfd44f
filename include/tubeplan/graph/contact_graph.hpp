#pragma once
// The extended contact-state graph (paper section V-A, contact-states.md): nodes are contact
// formations the core produced, each with a witness (a tick of an exploration motion that the
// core classifies as that CF, replayable with graph::ReplayTo); arcs are transitions the core
// produced between them. Plain data; built by graph::Explore, pruned by graph::Prune.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/graph/motion.hpp>

namespace tubeplan::graph {

struct Node {
  std::string cf;  ///< canonical text
  int pcs = 0;     ///< number of PCs
  /// The witness: the middle tick of the longest stay in this CF over all motions (the earliest
  /// motion on ties), so it is a settled state rather than the tick of first touch.
  TickRef witness;
  Eigen::Isometry3d X_W_hand = Eigen::Isometry3d::Identity();  ///< hand at the witness
  Eigen::Isometry3d X_WH = Eigen::Isometry3d::Identity();      ///< held end at the witness
  double energy_J = 0.0;                                       ///< bending energy at the witness
  double friction_N = 0.0;        ///< sum of |friction force| over the PCs at the witness
  double friction_limit_N = 0.0;  ///< sum of f_max over the PCs: the friction they can resist with
  double force_N = 0.0;           ///< operator force at the witness
  /// The least operator force of all its stays (each stay's middle tick, or a brief bridge's
  /// sampled tick): what reaching it takes.
  double min_force_N = std::numeric_limits<double>::infinity();
  /// The hand and the held end at that stay: another witness of the same state, the one reached
  /// with the least push (unset while min_force_N is infinite).
  Eigen::Isometry3d X_W_hand_least = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_WH_least = Eigen::Isometry3d::Identity();
  /// Motion of the held end still needed to reach the goal: |p_H - p_H,goal| + (l/2) angle
  /// (R_H, R_H,goal) between the witnesses (the tube's middle moves by about l/2 per radian).
  /// Negative when the goal was never reached.
  double distance_m = -1.0;
  /// Ticks spent in this CF over all motions, in the stays that count (a stay briefer than the
  /// dwell, seen only between two counted states, or between sub-ticks, adds none).
  long ticks = 0;
  bool start = false, goal = false;
  bool from_replay = false;  ///< not found by exploration; seen in a batch replay (ApplyVerdicts)
};

/// What batch replays found for an arc (ApplyVerdicts).
enum class BatchResult : unsigned char { kUntried, kFeasible, kInfeasible };

struct Arc {
  int from = 0, to = 0;  ///< node indices
  long count = 0;        ///< how often the core produced it
  /// The core changed more than one PC in one tick and refining the step (sub-stepping the hand
  /// motion) did not split the change: e.g. a side landing flat on a face at two places at once.
  bool simultaneous = false;
  TickRef witness;  ///< first tick at which it was produced (the tick in the new CF)
  bool kept = true;
  std::string reason;  ///< why pruning dropped it (empty when kept)
  BatchResult batch = BatchResult::kUntried;
  bool from_replay = false;  ///< not found by exploration; produced in a batch replay
};

struct SaturationPoint {
  int motions = 0;
  int nodes = 0;
  int arcs = 0;
};

/// Why an exploration ended.
enum class ExploreEnd : unsigned char {
  kSaturated,  ///< every node probed, the last closing round found no new node or arc
  kBudget,     ///< the budget of motions ran out first
  kTimeLimit,  ///< the time limit passed first
};

struct ContactGraph {
  std::vector<Node> nodes;
  std::vector<Arc> arcs;
  int start = -1;  ///< node of the start pose (-1: no motion ended within the time limit)
  int goal = -1;   ///< node of the scene's goal CF, -1 when exploration never reached it
  std::vector<Motion> motions;  ///< every motion explored, in order (witnesses index it)
  std::vector<SaturationPoint> saturation;    ///< after each motion
  std::vector<std::string> reached_elements;  ///< part elements seen in some PC
  /// Reachable parts' elements never seen, but those covered by another part (nothing can
  /// touch a box's bottom on the floor).
  std::vector<std::string> unreached_elements;
  long ticks = 0;       ///< core ticks run, refinements included
  int refinements = 0;  ///< multi-PC steps that were sub-stepped
  /// Motions ended where the operator force passed the explorer's limit (ExploreForceLimit) or
  /// the coupling reached the device's force (kProxySeparated: the tube no longer followed).
  int held_back = 0;
  double seconds = 0.0;    ///< wall time of the exploration
  int probed = 0;          ///< nodes whose neighbour probes ran (the first `probed` nodes)
  int closing_rounds = 0;  ///< rounds of random motions after probing (the last found nothing new)
  bool saturated = false;  ///< every node probed, nothing cut by the budget or the time limit
  ExploreEnd end = ExploreEnd::kSaturated;

  int FindNode(const std::string& cf) const;
};

/// Weights of the paper's heuristics (V-B), each criterion scaled by its largest magnitude in the
/// graph so that the weights are dimensionless.
struct PruneWeights {
  double friction = 1.0;
  double energy = 1.0;
  double distance = 1.0;
  /// A dominated arc is still kept when its weighted score is at most this above the best arc's
  /// of the same node (0: keep the Pareto front only).
  double tolerance = 0.05;
};

/// Marks every arc kept or dropped (with its reason). For each node u other than the goal, an
/// arc u -> v is kept when
///  1. it leads towards the goal: the goal can be reached from v in the unpruned graph and v is
///     nearer to it than u (distance_m), or, for a node none of whose arcs gets nearer, v is
///     fewer transitions from the goal than u (so no node with a way to the goal is a dead end;
///     plans are loopless paths, see paths.hpp);
///  2. and either no other such arc u -> w dominates it on (friction limit of w, bending energy
///     change, distance of w to the goal), lower being better on each, or its weighted score
///     w_f f/f* + w_e dE/E* + w_d d/d*  is within `tolerance` of the best such arc's.
/// Arcs out of the goal ("leaves the goal") and back into the start ("returns to the start") are
/// dropped. Then a node with a way to the goal in the unpruned graph but none along the kept arcs
/// (1 and 2 decide at each node alone, and together can leave the kept arcs circling) keeps back
/// its arcs one transition nearer the goal: the start reaches the goal along kept arcs whenever
/// it does at all. Without a goal every arc is dropped.
void Prune(ContactGraph& graph, const PruneWeights& weights);

/// The weighted score of an arc (criterion 3 above) under `weights`.
double ArcScore(const ContactGraph& graph, const Arc& arc, const PruneWeights& weights);

}  // namespace tubeplan::graph
