#pragma once
// Candidate plans written as `tubeplan plans` does (docs/graph.md, "Candidate plans"): the k best
// start -> goal paths of a pruned contact-state graph, each made a candidate with a minimum-jerk
// hand trajectory and replayed as `evaluate` would (plan::MakeCandidates), then the feasible ones
// (or all) written as plan files with their trajectories, their comments saying how they were
// made.

#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/plan/candidates.hpp>
#include <tubeplan/scene/scene.hpp>
#include <tubeplan/trajectories/synthesize.hpp>

namespace tubeplan::batch {

/// What the plans are asked.
struct PlansRequest {
  std::string scene_path;  ///< as given: the messages and comments name it, the plans reach it
  std::uint64_t seed = 1;  ///< the exploration's, which the comments name
  int k = 3;               ///< paths asked for
  bool all = false;        ///< also write the candidates that replay infeasible, after the others
  std::string out_dir;     ///< empty: SCENE_NAME-plans
  /// The hand's trajectories (seed offset by the path's rank).
  trajectories::SynthesisOptions synthesis;
};

/// The directory the plans of the scene named `scene_name` go to.
std::filesystem::path PlansDir(const PlansRequest& request, const std::string& scene_name);

/// Before any exploration: false after saying why on `err` when a file the plans may be written
/// to (SCENE_NAME-candidate-I.yaml and .csv, I up to k) is the scene itself. A scene that does
/// not load passes (the exploration reports its problems).
bool PlanFilesApart(const PlansRequest& request, std::ostream& err);

/// Before any exploration: true after saying on `err` that there is nothing to plan when the
/// tube rests at the scene's start pose in the scene's goal.
bool StartsInGoal(const PlansRequest& request, const scene::Scene& scene, std::ostream& err);

/// The paths found and the candidates made of them. Not copied: the candidates point at the
/// paths.
struct Plans {
  Plans() = default;
  Plans(const Plans&) = delete;
  Plans& operator=(const Plans&) = delete;

  std::filesystem::path out_dir;
  std::vector<graph::Path> paths;  ///< the k best, or fewer when the graph holds no more
  /// One for each path, the feasible first; a written one's plan carries its name, trajectory
  /// and comment (an empty name: not written).
  std::vector<plan::Candidate> candidates;
  long feasible = 0;  ///< candidates that replay feasible
};

/// What more exploration would take, for a hint: "a larger --time-limit (...)" where the time
/// limit stopped it unsaturated, "a larger --budget" where the budget did, empty where it
/// saturated (exploring on finds nothing new).
std::string ExploreMoreHint(const graph::ContactGraph& graph);

enum class PlansEnd {
  kWritten,         ///< the candidates made and the feasible (or all) written
  kNothingToPlan,   ///< the explorer's start state is the goal
  kGoalNotReached,  ///< the exploration never reached the goal: no path to take
  kNotWritten,      ///< the directory or a file could not be written
};

/// Makes the candidates of the k best paths of `graph` (explored from `scene` with the dwell
/// `dwell_s` and pruned with `weights`), replays each, and writes the feasible ones (with
/// request.all, all) into PlansDir, named SCENE_NAME-candidate-I in that order. Every end but
/// kWritten is said on `err`.
PlansEnd MakePlans(const PlansRequest& request, const scene::Scene& scene,
                   const graph::ContactGraph& graph, double dwell_s,
                   const graph::PruneWeights& weights, Plans& plans, std::ostream& err);

}  // namespace tubeplan::batch
