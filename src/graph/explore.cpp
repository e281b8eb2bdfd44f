// The explorer (Explore): sweeps, aims, random motions, probes and closing rounds, in that order,
// and the candidate plans it replays between groups of probes and in closing rounds; PcChanges and
// the force limit its motions keep to. Its motions are made in explorer_motions.cpp, run through
// the core in run_motion.cpp and merged into the graph in merger.cpp.

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <utility>

#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/trajectories/perturb.hpp>
#include <tubeplan/trajectories/synthesize.hpp>

#include "graph/explorer_motions.hpp"
#include "graph/merger.hpp"
#include "graph/run_motion.hpp"

namespace tubeplan::graph {

namespace {

using explorer::Box;
using explorer::Clock;
using explorer::Deadline;
using explorer::Merger;
using explorer::MotionResult;
using explorer::RunPointPtr;

// A replayed trajectory moves the hand along chords of this many ticks (20 ms: within 0.05 mm of
// the quickest minimum-jerk reach at 80 mm/s sped up 1.25 times, and about 0.03 mm of its tremor;
// at a sharp turn of the explorer's own motion a chord cuts the corner by up to about 1 mm).
constexpr int kReplayTicksPerMove = 20;

// Nodes probed in one group, after which the candidate plans are replayed: about as many motions
// each (four copies of four to seven candidates).
constexpr int kProbeGroup = 16;

std::set<std::string> ReachedElements(const ContactGraph& graph) {
  std::set<std::string> reached;
  for (const Node& n : graph.nodes) {
    const states::ParseResult parsed = states::ParseContactFormation(n.cf);
    if (!parsed.cf) continue;
    for (const states::PrincipalContact& pc : parsed.cf->contacts) reached.insert(pc.part_element);
  }
  return reached;
}

}  // namespace

int PcChanges(const states::ContactFormation& a, const states::ContactFormation& b) {
  std::vector<const states::PrincipalContact*> removed, added;
  int changes = 0;
  for (const states::PrincipalContact& pa : a.contacts) {
    const auto same = std::find_if(b.contacts.begin(), b.contacts.end(), [&](const auto& pb) {
      return pb.tube == pa.tube && pb.part_element == pa.part_element;
    });
    if (same == b.contacts.end()) {
      removed.push_back(&pa);
    } else if (same->marker != pa.marker) {
      ++changes;
    }
  }
  for (const states::PrincipalContact& pb : b.contacts) {
    const bool kept = std::any_of(a.contacts.begin(), a.contacts.end(), [&](const auto& pa) {
      return pb.tube == pa.tube && pb.part_element == pa.part_element;
    });
    if (!kept) added.push_back(&pb);
  }
  // Pair each removed PC with an added one that shares an element: one change between them.
  std::vector<bool> used(added.size(), false);
  for (const states::PrincipalContact* r : removed) {
    ++changes;
    for (std::size_t i = 0; i < added.size(); ++i) {
      if (!used[i] && (added[i]->tube == r->tube || added[i]->part_element == r->part_element)) {
        used[i] = true;
        break;
      }
    }
  }
  changes += static_cast<int>(std::count(used.begin(), used.end(), false));
  return changes;
}

namespace {

// Marks the start and goal nodes and each node's distance to the goal.
void MarkStartAndGoal(const scene::Scene& scene, ContactGraph& graph) {
  graph.goal = graph.FindNode(states::ToString(scene.goal));
  if (graph.start >= 0) graph.nodes[std::size_t(graph.start)].start = true;
  if (graph.goal >= 0) {
    Node& goal = graph.nodes[std::size_t(graph.goal)];
    goal.goal = true;
    const double half_length = 0.5 * scene.tube.length_m;
    for (Node& n : graph.nodes) {
      n.distance_m =
          (n.X_WH.translation() - goal.X_WH.translation()).norm() +
          half_length * Eigen::AngleAxisd(goal.X_WH.linear().transpose() * n.X_WH.linear()).angle();
    }
  }
}

// MarkStartAndGoal, and the part elements reached.
void MarkStartGoalAndReach(const scene::Scene& scene, const core::Core& probe,
                           ContactGraph& graph) {
  MarkStartAndGoal(scene, graph);
  const std::set<std::string> reached = ReachedElements(graph);
  graph.reached_elements.assign(reached.begin(), reached.end());
  const auto& elements = probe.elements();
  for (std::size_t e = 0; e < elements.size(); ++e)
    if (!reached.contains(elements[e].name) && !explorer::Covered(scene, probe, int(e)))
      graph.unreached_elements.push_back(elements[e].name);
}

}  // namespace

namespace {

// The candidate paths of a graph: its explored states (a state seen only in an evaluate report
// has no witness to aim at), pruned as `plans` prunes them, and the cheapest start -> goal paths
// through what is kept; `explored_node` maps the pruned graph's nodes back to the graph's.
struct CandidatePaths {
  ContactGraph pruned;
  std::vector<int> explored_node;
  std::vector<Path> paths;
};

CandidatePaths FindCandidatePaths(const scene::Scene& scene, const ContactGraph& graph,
                                  const ExploreOptions& options) {
  CandidatePaths c;
  ContactGraph& marked = c.pruned;
  std::vector<int> index(graph.nodes.size(), -1);
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    if (graph.nodes[i].from_replay) continue;
    index[i] = static_cast<int>(marked.nodes.size());
    c.explored_node.push_back(static_cast<int>(i));
    marked.nodes.push_back(graph.nodes[i]);
  }
  for (const Arc& a : graph.arcs) {
    if (a.from_replay || index[std::size_t(a.from)] < 0 || index[std::size_t(a.to)] < 0) continue;
    marked.arcs.push_back(a);
    marked.arcs.back().from = index[std::size_t(a.from)];
    marked.arcs.back().to = index[std::size_t(a.to)];
  }
  marked.start = graph.start >= 0 ? index[std::size_t(graph.start)] : -1;
  MarkStartAndGoal(scene, marked);
  if (marked.start < 0 || marked.goal < 0 || marked.goal == marked.start) return c;
  const PruneWeights weights =
      options.weights.value_or(PruneWeights{scene.heuristics.friction, scene.heuristics.energy,
                                            scene.heuristics.distance, scene.heuristics.tolerance});
  Prune(marked, weights);
  c.paths = KShortestPaths(marked, ArcCosts(marked, weights), options.replay_paths);
  return c;
}

// The nodes not yet probed, in the order they are to be: those on the candidate paths (cheapest
// path first, start to goal), then those witnessed in a perturbed replay of a candidate, then the
// rest as they were found. What an operator following a plan a little off its line meets is so
// probed first.
std::vector<int> ProbeOrder(const scene::Scene& scene, const ContactGraph& graph,
                            const ExploreOptions& options, std::span<const char> probed) {
  std::vector<char> queued(probed.begin(), probed.end());
  std::vector<int> order;
  const auto add = [&](int n) {
    if (queued[std::size_t(n)]) return;
    queued[std::size_t(n)] = 1;
    order.push_back(n);
  };
  const CandidatePaths c = FindCandidatePaths(scene, graph, options);
  for (const Path& path : c.paths)
    for (const int n : path.nodes) add(c.explored_node[std::size_t(n)]);
  for (std::size_t n = 0; n < graph.nodes.size(); ++n) {
    const int motion = graph.nodes[n].witness.motion;
    if (motion >= 0 && graph.motions[std::size_t(motion)].kind == "replay")
      add(static_cast<int>(n));
  }
  for (std::size_t n = 0; n < graph.nodes.size(); ++n) add(static_cast<int>(n));
  return order;
}

}  // namespace

std::vector<std::vector<Eigen::Isometry3d>> CandidateWaypoints(const scene::Scene& scene,
                                                               const ContactGraph& graph,
                                                               const ExploreOptions& options) {
  const CandidatePaths c = FindCandidatePaths(scene, graph, options);
  std::vector<std::vector<Eigen::Isometry3d>> waypoint_lists;
  for (const Path& path : c.paths)
    for (auto& aimed : DistinctAims(scene, c.pruned, path, kReplayAims))
      if (std::none_of(waypoint_lists.begin(), waypoint_lists.end(),
                       [&](const auto& a) { return SamePoses(a, aimed.second); }))
        waypoint_lists.push_back(std::move(aimed.second));
  return waypoint_lists;
}

std::vector<trajectories::HandSample> GoalMotionPath(const scene::Scene& scene,
                                                     const ContactGraph& graph) {
  const int goal = graph.FindNode(states::ToString(scene.goal));
  if (goal < 0 || goal == graph.start) return {};
  const Node& node = graph.nodes[std::size_t(goal)];
  if (node.from_replay || node.witness.motion < 0 ||
      std::size_t(node.witness.motion) >= graph.motions.size())
    return {};
  core::Core core(scene);
  return HandPath(core, graph.motions[std::size_t(node.witness.motion)], node.witness.tick);
}

namespace {

// CandidateTrajectories, with the explorer's motion to the goal given (GoalMotionPath's).
std::vector<trajectories::Trajectory> CandidateTrajectoriesWith(
    const scene::Scene& scene, const ContactGraph& graph, const ExploreOptions& options,
    std::span<const trajectories::HandSample> goal_path) {
  trajectories::SynthesisOptions synthesis;
  synthesis.peak_speed_m_per_s = options.speed_m_per_s;
  std::vector<trajectories::Trajectory> nominals;
  for (const std::vector<Eigen::Isometry3d>& aim : CandidateWaypoints(scene, graph, options))
    nominals.push_back(trajectories::SynthesizeTrajectory(aim, synthesis));
  if (nominals.empty()) return nominals;
  // The explorer's own motion to the goal, retimed as `plans` retimes it: on the scene's step.
  synthesis.rate_Hz = 1.0 / scene.model.time_step_s;
  if (goal_path.size() >= 2) nominals.push_back(trajectories::RetimeHandPath(goal_path, synthesis));
  return nominals;
}

}  // namespace

std::vector<trajectories::Trajectory> CandidateTrajectories(const scene::Scene& scene,
                                                            const ContactGraph& graph,
                                                            const ExploreOptions& options) {
  return CandidateTrajectoriesWith(scene, graph, options, GoalMotionPath(scene, graph));
}

std::vector<Motion> PerturbedReplays(const scene::Scene& scene,
                                     std::span<const trajectories::Trajectory> nominals,
                                     const ExploreOptions& options, std::uint64_t seed,
                                     int first_replicate, int copies) {
  trajectories::Perturbation perturbation;
  perturbation.offset_m = options.replay_offset_m;
  std::vector<Motion> motions;
  int replicate = first_replicate;
  for (const trajectories::Trajectory& nominal : nominals)
    for (int c = 0; c < copies; ++c)
      motions.push_back(MotionAlong(trajectories::Perturb(nominal, perturbation, seed, replicate++),
                                    scene.model.time_step_s, kReplayTicksPerMove,
                                    options.speed_m_per_s, "replay"));
  return motions;
}

namespace {

// A closing round's motions: `closing_motions` random motions of the seed from `next_random`, then
// `replay_copies` perturbed replays from `next_replicate` of each of `nominals`, the candidate
// trajectories of the graph as it stands. Advances both counters.
std::vector<Motion> ClosingRound(const scene::Scene& scene, const Box& box,
                                 std::span<const trajectories::Trajectory> nominals,
                                 const ExploreOptions& o, int& next_random, int& next_replicate) {
  std::vector<Motion> round =
      explorer::RandomMotionsIn(scene, box, o.seed, next_random, o.closing_motions, o);
  next_random += o.closing_motions;
  std::vector<Motion> replays =
      PerturbedReplays(scene, nominals, o, o.seed, next_replicate, o.replay_copies);
  next_replicate += static_cast<int>(replays.size());
  round.insert(round.end(), std::make_move_iterator(replays.begin()),
               std::make_move_iterator(replays.end()));
  return round;
}

}  // namespace

double ExploreForceLimit(const scene::Scene& scene, const ExploreOptions& options) {
  return options.witness_force_N > 0.0 ? options.witness_force_N : 0.5 * scene.device.max_force_N;
}

ContactGraph Explore(const scene::Scene& scene, const ExploreOptions& o,
                     const std::function<void(const SaturationPoint&)>& progress) {
  const auto clock_start = Clock::now();
  ContactGraph graph;
  // The time limit counts from the start and holds once the goal has a stay; until then the
  // exploration may go on kGoalSearch_s longer.
  const auto after = [&](double seconds) {
    return clock_start +
           std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  };
  Deadline deadline;
  if (o.time_limit_s > 0.0) deadline.at = after(o.time_limit_s + kGoalSearch_s);
  bool goal_held = false;
  const std::string goal_cf = states::ToString(scene.goal);
  const auto arm_deadline = [&] {
    if (!(o.time_limit_s > 0.0) || goal_held) return;
    const int goal = graph.FindNode(goal_cf);
    goal_held = goal >= 0 && graph.nodes[std::size_t(goal)].ticks > 0;
    if (goal_held) deadline.at = after(o.time_limit_s);
  };
  Merger merger(graph, ExploreForceLimit(scene, o));
  std::vector<std::unique_ptr<core::Core>> cores;
  cores.push_back(std::make_unique<core::Core>(scene));
  core::Core& probe = *cores.front();
  const Box box = explorer::PartsBox(scene, probe.reachable_parts());
  std::vector<char> probed;  // per node: whether it has had its probe motion
  std::size_t probed_count = 0;
  // Read by the threads of a group, while the merger stands still.
  const explorer::MayEnter may_enter = [&](const std::string& cf, bool refined, int ticks) {
    return merger.MayEnter(cf, refined, ticks, probed);
  };
  std::optional<ExploreEnd> stopped;  // the budget or the time limit, whichever came first
  const auto stop = [&](ExploreEnd why) {
    if (!stopped) stopped = why;
  };
  const auto room = [&] {
    return std::max(0, o.max_motions - static_cast<int>(graph.motions.size()));
  };
  std::string phase;
  const auto status = [&](int done, int started) {
    if (!o.status) return;
    o.status({phase, done, started, static_cast<int>(graph.nodes.size()),
              static_cast<int>(graph.arcs.size()),
              std::chrono::duration<double>(Clock::now() - clock_start).count()});
  };
  // Runs a group of motions whole, or as much of it as the budget leaves, and merges the results
  // in motion order up to the first the time limit stopped (that one and those after it are
  // dropped, and so is the rest of the exploration); arms the limit once the goal has a stay.
  // Returns how many were merged.
  const auto run = [&](std::vector<Motion> group, const std::vector<RunPointPtr>& resumes) {
    if (stopped == ExploreEnd::kTimeLimit) return 0;
    if (static_cast<int>(group.size()) > room()) {
      group.resize(std::size_t(room()));
      stop(ExploreEnd::kBudget);
    }
    const int first = static_cast<int>(graph.motions.size());
    const int count = static_cast<int>(group.size());
    if (count == 0) return 0;
    for (Motion& m : group) graph.motions.push_back(std::move(m));
    const std::function<void(int, int)> waiting =
        o.status ? std::function<void(int, int)>(
                       [&](int done, int started) { status(first + done, first + started); })
                 : nullptr;
    const std::vector<MotionResult> results = explorer::RunAll(
        scene, graph.motions, first, count, resumes, may_enter, o, cores, deadline, waiting);
    int merged = 0;
    for (const MotionResult& r : results) {
      if (r.timed_out) break;
      merger.Add(r);
      ++merged;
      if (progress) progress(graph.saturation.back());
    }
    if (merged < count) {
      graph.motions.resize(std::size_t(first + merged));
      stop(ExploreEnd::kTimeLimit);
    }
    arm_deadline();
    status(first + merged, first + merged);
    return merged;
  };

  // Sweeps and aims run whole unless a limit cuts them, merged in order.
  phase = "sweeps";
  run(explorer::Sweeps(scene, box, o), {});
  graph.start = graph.nodes.empty() ? -1 : 0;  // the first stay of the first motion: the start
  if (!stopped) {
    // Aim at the goal's contacts together first, then at the goal's elements, then at those no PC
    // has touched yet.
    const std::set<std::string> reached = ReachedElements(graph);
    std::set<std::string> in_goal;
    for (const states::PrincipalContact& pc : scene.goal.contacts) in_goal.insert(pc.part_element);
    std::vector<int> unseen;
    for (std::size_t e = 0; e < probe.elements().size(); ++e)
      if (in_goal.contains(probe.elements()[e].name)) unseen.push_back(static_cast<int>(e));
    for (std::size_t e = 0; e < probe.elements().size(); ++e)
      if (!reached.contains(probe.elements()[e].name) &&
          !in_goal.contains(probe.elements()[e].name))
        unseen.push_back(static_cast<int>(e));
    phase = "aims";
    std::vector<Motion> aims = explorer::GoalAims(scene, probe, o);
    for (Motion& m : explorer::Aims(scene, probe, unseen, o)) aims.push_back(std::move(m));
    run(std::move(aims), {});
  }
  // Random motions from the seed, all merged (they reach pressed, tipped and wedged states the
  // sweeps and aims do not).
  if (!stopped && o.random_motions > 0) {
    phase = "random motions";
    run(explorer::RandomMotionsIn(scene, box, o.seed, 0, o.random_motions, o), {});
  }
  // The candidate plans' trajectories of the graph as it stands (none before the goal is
  // reached). The explorer's motion to the goal is replayed through the core once per witness of
  // the goal.
  TickRef goal_witness{-1, 0, 0, 0};
  std::vector<trajectories::HandSample> goal_path;
  const auto candidates = [&] {
    const int goal = graph.FindNode(goal_cf);
    const TickRef w = goal >= 0 ? graph.nodes[std::size_t(goal)].witness : TickRef{-1, 0, 0, 0};
    if (w.motion != goal_witness.motion || w.tick != goal_witness.tick) {
      goal_path = GoalMotionPath(scene, graph);
      goal_witness = w;
    }
    return CandidateTrajectoriesWith(scene, graph, o, goal_path);
  };
  // Perturbed replays of the candidate plans, `replay_copies` of each.
  int next_replicate = 0;
  const auto replay_candidates = [&] {
    if (stopped || o.replay_copies <= 0) return;
    std::vector<Motion> replays =
        PerturbedReplays(scene, candidates(), o, o.seed, next_replicate, o.replay_copies);
    next_replicate += static_cast<int>(replays.size());
    phase = "replays";
    run(std::move(replays), {});
  };
  // Neighbour probing in groups of kProbeGroup nodes in ProbeOrder, each followed by replays of
  // the candidate plans, until every node is probed. Probing a node again from the same stay
  // replays the same motion (the core is deterministic), which finds nothing new.
  const auto probe_new_nodes = [&] {
    while (!stopped && probed_count < graph.nodes.size()) {
      if (room() == 0) {
        stop(ExploreEnd::kBudget);
        break;
      }
      probed.resize(graph.nodes.size(), 0);
      const std::vector<int> order = ProbeOrder(scene, graph, o, probed);
      const int wanted = std::min(kProbeGroup, static_cast<int>(order.size()));
      const int count = std::min(wanted, room());
      if (count < wanted) stop(ExploreEnd::kBudget);
      // Each goes on from the run point kept at its start stay, if there is one: the same bits
      // as replaying its prefix.
      std::vector<Motion> group;
      std::vector<RunPointPtr> resumes;
      for (int i = 0; i < count; ++i) {
        const int node = order[std::size_t(i)];
        group.push_back(merger.ProbeMotion(node, scene, o));
        resumes.push_back(merger.TakeProbePoint(node));
        probed[std::size_t(node)] = 1;
      }
      phase = "probes";
      const int merged = run(std::move(group), resumes);
      for (int i = merged; i < count; ++i) probed[std::size_t(order[std::size_t(i)])] = 0;
      probed_count += std::size_t(merged);
      replay_candidates();
    }
  };
  probe_new_nodes();
  // Closing rounds: more random motions of the same seed and perturbed replays of the candidate
  // plans of the graph as the round starts, each round merged and its new nodes probed, until a
  // round adds no node and no arc (saturated), or a limit ends it.
  int next_random = o.random_motions;
  while (!stopped && (o.closing_motions > 0 || o.replay_copies > 0)) {
    const std::size_t nodes_before = graph.nodes.size(), arcs_before = graph.arcs.size();
    phase = "closing rounds";
    const std::vector<trajectories::Trajectory> nominals =
        o.replay_copies > 0 ? candidates() : std::vector<trajectories::Trajectory>{};
    std::vector<Motion> round = ClosingRound(scene, box, nominals, o, next_random, next_replicate);
    // Nothing to run (no random motions, and no plan before the goal is reached): no round.
    if (round.empty()) break;
    run(std::move(round), {});
    ++graph.closing_rounds;
    probe_new_nodes();
    if (graph.nodes.size() == nodes_before && graph.arcs.size() == arcs_before) break;
  }
  graph.probed = static_cast<int>(probed_count);
  graph.end = stopped.value_or(ExploreEnd::kSaturated);
  graph.saturated = !stopped && probed_count == graph.nodes.size();

  MarkStartGoalAndReach(scene, probe, graph);
  graph.seconds = std::chrono::duration<double>(Clock::now() - clock_start).count();
  return graph;
}

}  // namespace tubeplan::graph
