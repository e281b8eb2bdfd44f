#pragma once
// Candidate plans from paths through the contact-state graph: the hand moves by minimum jerk
// through the witnesses of each path's states, and every candidate is replayed through the same
// judge as `evaluate`, aimed at the witnesses' hand poses, at their held end's poses, at the
// held end's poses of the stays of least force, and at those with the end brought in along the
// tube, and where none of those holds, with the first reach over the parts (graph::kPlanAims),
// slower while none is feasible; the feasible try of least force is kept; and the explorer's own
// motion into the goal as one more candidate (docs/graph.md, "Plans").

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/plan/plan.hpp>
#include <tubeplan/scene/scene.hpp>
#include <tubeplan/trajectories/synthesize.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::plan {

struct CandidateOptions {
  /// The first try's; its seed is offset by the path's rank.
  trajectories::SynthesisOptions synthesis;
  double dwell_s = 0.0;   ///< the plans' dwell (the explorer's)
  std::string scene_ref;  ///< the scene as the plan files name it
  /// Each repair divides the peak speed by the next of these (a quasi-static reach overshoots
  /// less): the first tries are at the asked speed. At each speed the hand is aimed at the
  /// witnesses' hand poses, at their held end's poses (Node::X_WH), at the held end's poses of
  /// each state's stay of least force (Node::X_WH_least, another witness of the same state), and
  /// at those with the end brought in along the tube (graph::Aim::kAlongAxis): a witness the
  /// explorer reached while the tube held back from the hand (the coupling stretched, the tube
  /// pushed hard, or still moving) is then approached without the push that carried the tube
  /// on, and an end that a slanting reach would land on its rim comes in square. Where none of
  /// those holds, the hand goes over the parts first (graph::Aim::kOver).
  std::vector<double> slower = {2.0, 4.0};
};

struct Candidate {
  /// The searched path; for a motion candidate, its states' nodes (-1: a state the graph lacks)
  /// and no cost; for a restated one, its states' nodes and the searched path's cost.
  graph::Path path;
  /// The explorer's own motion to the goal (MotionCandidate), not a path through the graph.
  bool from_motion = false;
  Plan plan;  ///< name, trajectory and comment left to the writer
  trajectories::Trajectory trajectory;
  double duration_s = 0.0;
  double peak_speed_m_per_s = 0.0;     ///< of the try kept
  graph::Aim aim = graph::Aim::kHand;  ///< where the try kept aims the hand
  int tries = 0;                       ///< which try was kept, in the order tried (from 1)
  /// No try held the path's states: the plan's are those the kept try's replay passed through
  /// on its way to the goal (its path's nodes those states', -1 for one the graph lacks).
  bool restated = false;
  Judgement judgement;
};

/// The trajectory as its file will read it back (rounded as written), or nothing if it would
/// not load: what the verdict is taken on, so that `evaluate` on the written files agrees.
using AsWritten =
    std::function<std::optional<trajectories::Trajectory>(const trajectories::Trajectory&)>;

/// One candidate for each path (in order): of the tries (one per distinct aim) at the fastest
/// speed where one replays feasible, the feasible one of least peak operator force; else the
/// first try that got to the goal by other states, cut in its first stay there and restated
/// (Candidate::restated), where it replays feasible on those; else the last try. The feasible
/// come first, each kind in the paths' order.
std::vector<Candidate> MakeCandidates(const scene::Scene& scene, const graph::ContactGraph& graph,
                                      std::span<const graph::Path> paths,
                                      const CandidateOptions& options, const AsWritten& as_written);

/// The motion the explorer reached the goal's witness with, as a candidate: the hand's poses
/// of that motion as the explorer fed them to the core (graph::HandPath), cut in the middle of
/// the goal's first stay, on the scene's step and retimed so as not to pass the asked peak
/// speed (trajectories::RetimeHandPath); each slower try stretches its clock by the next of
/// `slower`. Its states are StatesToGoal of its replay. Another way into the goal, tried when
/// the searched paths give too few feasible plans: the explorer's guards kept it within their
/// limits, and the judge says whether it holds. Nothing when the graph has no goal, starts in
/// it, or the witness's motion kept no moves.
std::optional<Candidate> MotionCandidate(const scene::Scene& scene,
                                         const graph::ContactGraph& graph,
                                         const CandidateOptions& options,
                                         const AsWritten& as_written);

/// The states `seen` counted from its start up to its first stay in `goal`, each loop cut out
/// (back in a state it had left: the states since are dropped, and are never planned again), so
/// that the judge, on the same run, meets them in order and every other state as a detour.
/// Empty when the goal is not reached or is the first state.
std::vector<std::string> StatesToGoal(const Judgement& seen, const std::string& goal);

/// "FROM -> TO: reason" of the first infeasible transition, or what stopped the judgement.
std::string FirstFailure(const Judgement& judgement);

/// "feasible" (with "-with-detour (FROM -> TO via ...)" for the first transition that passed
/// unplanned states) or "infeasible: " and FirstFailure, the try kept when not the first, that
/// its states are those its replay passed (Candidate::restated), and the peak operator force:
/// what `plans` says of a candidate and its plan file's comment repeats.
std::string VerdictText(const Candidate& candidate);

}  // namespace tubeplan::plan
