#pragma once
// Builds the contact-state graph of a scene by exploring it with the core (docs/graph.md):
//  1. sweeps: the tube, level and tipped down, lowered into the parts at a row of lateral
//     offsets until it pushes back, slid sideways both ways, pushed along its axis, lifted;
//  2. aims: for each element of a reachable part that no PC has touched yet, motions that bring
//     the tube's tip and then its side against that element (elements whose outside is covered
//     by another part are not aimed at);
//  3. `random_motions` random guarded motions from a seed;
//  4. neighbour probes: from a stay of each node (its motion resumed there), small moves
//     of the hand along and against three directions and small turns, each held and undone;
//     nodes are probed in groups of 16, those on the candidate plans' paths first, then those
//     witnessed in their replays, then the rest as found; after each group, perturbed replays of
//     the candidate plans' trajectories (CandidateTrajectories) of the graph as it then stands;
//     until every node has been probed;
//  5. closing rounds: more random motions and perturbed replays of the candidate plans'
//     trajectories of the graph as it then stands, each round's new nodes probed as in 4,
//     until a round adds no node and no arc
//     (saturated), or until the budget of motions or the time limit is spent.
// A step that changes more than one PC is re-run from the tick before with the hand's step split
// into sub-ticks; what the sub-ticks produce is recorded, and a change that stays multiple is
// flagged simultaneous. Motions run in parallel on `jobs` threads, each with its own core, and
// are merged in motion order, so the graph depends on the seed only, not on `jobs`.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/graph/motion.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::graph {

/// Where an exploration is, for a progress display.
struct ExploreStatus {
  std::string phase;  ///< "sweeps", "aims", "random motions", "probes", "replays", "closing rounds"
  int motions_done = 0;     ///< motions run to their end so far
  int motions_started = 0;  ///< motions handed to the threads so far (done ones included)
  int nodes = 0, arcs = 0;  ///< the graph as merged so far (it grows after each group)
  double seconds = 0.0;     ///< wall time since the exploration began
};

struct ExploreOptions {
  std::uint64_t seed = 1;
  /// Random guarded motions from `seed` run after the sweeps and aims, before probing.
  int random_motions = 120;
  /// Once every node is probed, closing rounds of this many more random motions (the same seed's
  /// sequence, continued) run, each followed by probing the nodes it found, until a round adds
  /// no node and no arc (0: none).
  int closing_motions = 30;
  /// After each group of probes, and in each closing round, this many perturbed copies (0: none)
  /// of each candidate plan's trajectory of the graph as it then stands run: the `replay_paths`
  /// cheapest start -> goal paths of the graph pruned with `weights`, the hand aimed at each
  /// distinct aim of graph::kReplayAims (CandidateWaypoints) at `speed_m_per_s`, and the explorer's
  /// motion to the goal (CandidateTrajectories), each moved as a whole by up to
  /// `replay_offset_m`, with 0.1 mm tremor and 0.8-1.25x the speed (trajectories::Perturb). What
  /// an operator following a plan meets is then in the graph. None run before the goal is
  /// reached.
  int replay_copies = 4;
  int replay_paths = 3;
  double replay_offset_m = 0.004;
  /// The heuristics' weights of the candidate paths (nothing: the scene's).
  std::optional<PruneWeights> weights;
  /// At most this many motions run, whatever happens (sweeps, aims, random motions, then probes
  /// and replays, together: a group is cut where the budget ends). A motion is one entry
  /// of ContactGraph::motions: one list of guarded moves from the start pose (a probe motion is one
  /// node's ten probes after its prefix). The graph says whether it saturated within it.
  int max_motions = 3000;
  /// Wall time bound [s] from the start (0: none), holding once the goal has a stay: until then
  /// the exploration may go on kGoalSearch_s longer. Once passed, no motion starts and those
  /// under way stop within 64 ticks and are dropped with every motion after the first of them:
  /// the graph is the one `max_motions` set to the motions kept would give, on any number of
  /// threads.
  double time_limit_s = 0.0;
  /// Called on the calling thread about every `status_interval_s` while motions run, and once
  /// after each group (may be empty; --jobs does not change what is explored).
  std::function<void(const ExploreStatus&)> status;
  double status_interval_s = 1.0;
  int jobs = 1;
  double push_N = 2.0;  ///< guard force of the probing moves
  /// An exploring motion ends where the operator force passes this [N] (0: half the device's
  /// maximum force, 4.25 N for the PHANToM Premium), so every witness is a state an operator
  /// reaches well within the device (ExploreForceLimit).
  double witness_force_N = 0.0;
  /// Hand speed of sweeps, aims and replays (a calm human motion; `plans`'s default).
  double speed_m_per_s = 0.08;
  int substeps = 16;  ///< sub-ticks per tick when refining a multi-PC change
  /// A CF counts once the core has kept it this long (the plan judge's dwell); briefer states
  /// are flicker, not nodes, unless they bridge a two-PC change.
  double dwell_s = 0.020;
  /// Neighbour probes from each node's witness: the hand moves this far along and against the
  /// start frame's three directions and turns this much about two axes, and back.
  double probe_step_m = 0.006;
  double probe_turn_rad = 5.0 * 3.14159265358979323846 / 180.0;
  /// A run keeps a core snapshot every 64 ticks; a probe goes on from the one at or before its
  /// start stay and a refinement from the one before its tick, instead of replaying the motion
  /// up to there (the same bits, so the same graph, in ~half the ticks). false: every prefix is
  /// replayed (the check that snapshots change nothing).
  bool resume_runs = true;
};

/// The neighbour probes of a node: a step along and against each of three directions and a turn
/// either way about two axes (ExploreOptions::probe_step_m, probe_turn_rad).
inline constexpr int kProbesPerNode = 2 * 3 + 2 * 2;

/// How much longer than its time limit an exploration may go on while the goal has no stay [s].
inline constexpr double kGoalSearch_s = 60.0;

/// Number of PC changes between two CFs: a PC added, removed or re-marked counts one; a PC that
/// keeps one of its elements and changes the other (Ee -> Fe on the same face, a rim sliding
/// from a face onto its edge) counts one.
int PcChanges(const states::ContactFormation& a, const states::ContactFormation& b);

/// The operator force [N] past which an exploring motion ends: options.witness_force_N, else
/// half the scene's device's maximum force.
double ExploreForceLimit(const scene::Scene& scene, const ExploreOptions& options);

/// Explores `scene` and returns the unpruned graph. `progress` (may be empty) is called after
/// each merged motion.
ContactGraph Explore(const scene::Scene& scene, const ExploreOptions& options,
                     const std::function<void(const SaturationPoint&)>& progress = {});

/// The hand's waypoints of the candidate plans of `graph` as `plans` first tries them: for each of
/// the `options.replay_paths` cheapest start -> goal paths of the graph pruned with
/// `options.weights` (its explored states only), one list per distinct aim of
/// graph::kReplayAims. Empty when the graph has no goal or no path to it.
std::vector<std::vector<Eigen::Isometry3d>> CandidateWaypoints(const scene::Scene& scene,
                                                               const ContactGraph& graph,
                                                               const ExploreOptions& options);

/// The hand's path of the motion whose stay witnesses the goal's state, up to the witness's tick,
/// as a run through the core moves it (HandPath): the explorer's own way to the goal. Empty
/// where the graph has no goal, the goal is the start, or its witness is not an explorer
/// motion's. (`plans` cuts this path in the goal's first stay, which may come before the
/// witness's.)
std::vector<trajectories::HandSample> GoalMotionPath(const scene::Scene& scene,
                                                     const ContactGraph& graph);

/// The nominal trajectories of the candidate plans of `graph`, which the explorer and the
/// completeness check replay perturbed: one through each list of CandidateWaypoints (at
/// `options.speed_m_per_s`), then the explorer's motion to the goal (GoalMotionPath, uncut)
/// retimed to that speed by trajectories::RetimeHandPath on the scene's step, as `plans`
/// retimes its cut. Empty when the graph has no path to the goal.
std::vector<trajectories::Trajectory> CandidateTrajectories(const scene::Scene& scene,
                                                            const ContactGraph& graph,
                                                            const ExploreOptions& options);

/// Perturbed replays (ExploreOptions::replay_copies), motions of kind "replay": `copies` of each
/// of `nominals`, Perturb's replicates `first_replicate` on, from `seed`, followed in chords at
/// the explorer's speed.
std::vector<Motion> PerturbedReplays(const scene::Scene& scene,
                                     std::span<const trajectories::Trajectory> nominals,
                                     const ExploreOptions& options, std::uint64_t seed,
                                     int first_replicate, int copies);

/// `count` random motions from `seed` as the explorer makes them (for independent checks).
std::vector<Motion> RandomMotions(const scene::Scene& scene, std::uint64_t seed, int first,
                                  int count, const ExploreOptions& options);

}  // namespace tubeplan::graph
