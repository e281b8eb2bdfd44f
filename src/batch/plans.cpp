#include <algorithm>
#include <sstream>

#include <tubeplan/batch/plans.hpp>
#include <tubeplan/graph/motion.hpp>
#include <tubeplan/graph/summary.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/states/contact_formation.hpp>

#include "io/text_file.hpp"

namespace tubeplan::batch {
namespace {

namespace fs = std::filesystem;

std::string CandidateName(const std::string& scene_name, int number) {
  return scene_name + "-candidate-" + std::to_string(number);
}

void SayNothingToPlan(const PlansRequest& request, const scene::Scene& scene,
                      const std::string& start, std::ostream& err) {
  err << request.scene_path << ": nothing to plan: the goal " << states::ToString(scene.goal)
      << " is the state the tube starts in (" << start
      << " at the scene's start pose), so a plan would be that one state and no move; no "
         "plan written. Give the scene a goal the tube has to be moved to\n";
}

// Names candidate `number` and writes its plan file and trajectory into `out_dir`, the plan's
// comment saying how it was made; an empty string on success, else the message.
std::string WriteCandidate(plan::Candidate& c, int number, const PlansRequest& request,
                           const std::string& scene_name, const fs::path& out_dir) {
  const std::string name = CandidateName(scene_name, number);
  c.plan.name = name;
  c.plan.trajectory = name + ".csv";
  std::ostringstream comment;
  comment << "Candidate " << number << " made by `tubeplan plans " << request.scene_path
          << "` (seed " << request.seed << "), ";
  if (c.from_motion)
    comment << "the explorer's own motion to the goal: the hand moves as it did, its clock "
               "stretched if it moved faster than the asked speed.";
  else
    comment << "cost " << c.path.cost
            << (c.restated ? ": the hand moves by minimum jerk through the witnesses of the "
                             "searched path's states, and its states are those it passed."
                           : ": the hand moves by minimum jerk through the witnesses of its "
                             "states.");
  comment << " Replayed when made: " << plan::VerdictText(c) << ".";
  c.plan.comment = comment.str();
  for (const auto& [file, text] :
       {std::pair{out_dir / (name + ".yaml"), io::FormatPlanYaml(c.plan)},
        std::pair{out_dir / c.plan.trajectory, io::FormatTrajectoryCsv(c.trajectory)}}) {
    if (const std::string e = io::WriteTextFileAtomically(file, text); !e.empty())
      return file.string() + ": error: " + e;
  }
  return {};
}

// Fewer feasible candidates than asked: the explorer's own motion to the goal is one more, after
// the feasible ones if it is feasible, else last; not when a feasible one plans its states.
void AddMotionCandidate(const PlansRequest& request, const scene::Scene& scene,
                        const graph::ContactGraph& graph, const plan::CandidateOptions& options,
                        Plans& plans) {
  const auto feasible = [](const plan::Candidate& c) { return c.judgement.feasible; };
  if (std::count_if(plans.candidates.begin(), plans.candidates.end(), feasible) >= request.k)
    return;
  // Its own tremor, as each path's has (MakeCandidates offsets the seed by the path's rank).
  plan::CandidateOptions own = options;
  own.synthesis.seed += plans.paths.size();
  std::optional<plan::Candidate> c =
      plan::MotionCandidate(scene, graph, own, io::TrajectoryAsWritten);
  // Not again what a feasible candidate already plans.
  if (!c || std::any_of(plans.candidates.begin(), plans.candidates.end(), [&](const auto& o) {
        return o.judgement.feasible && o.plan.states == c->plan.states;
      }))
    return;
  const auto at = c->judgement.feasible
                      ? std::find_if_not(plans.candidates.begin(), plans.candidates.end(), feasible)
                      : plans.candidates.end();
  plans.candidates.insert(at, std::move(*c));
}

}  // namespace

fs::path PlansDir(const PlansRequest& request, const std::string& scene_name) {
  return request.out_dir.empty() ? fs::path(scene_name + "-plans") : fs::path(request.out_dir);
}

bool PlanFilesApart(const PlansRequest& request, std::ostream& err) {
  const io::SceneLoadResult scene = io::LoadSceneFile(request.scene_path);
  if (!scene.scene) return true;
  const fs::path dir = PlansDir(request, scene.scene->name);
  std::vector<io::RolePath> outputs;
  // k paths and, with --all, the explorer's motion after them.
  for (int i = 1; i <= request.k + 1; ++i) {
    const std::string name = CandidateName(scene.scene->name, i);
    outputs.push_back({"the plan file", dir / (name + ".yaml")});
    outputs.push_back({"the plan's trajectory", dir / (name + ".csv")});
  }
  const std::string problem = io::CheckOutputsApart(outputs, {{"the scene", request.scene_path}});
  if (!problem.empty()) err << "tubeplan plans: error: " << problem << "\n";
  return problem.empty();
}

bool StartsInGoal(const PlansRequest& request, const scene::Scene& scene, std::ostream& err) {
  const std::string start = graph::RestingFormation(scene);
  if (start != states::ToString(scene.goal)) return false;
  SayNothingToPlan(request, scene, start, err);
  return true;
}

std::string ExploreMoreHint(const graph::ContactGraph& graph) {
  switch (graph.end) {
    case graph::ExploreEnd::kTimeLimit:
      return "a larger --time-limit (the exploration stopped at its time limit with " +
             std::to_string(graph.probed) + " of " + std::to_string(graph.nodes.size()) +
             " states probed)";
    case graph::ExploreEnd::kBudget:
      return "a larger --budget";
    case graph::ExploreEnd::kSaturated:
      break;
  }
  return "";
}

PlansEnd MakePlans(const PlansRequest& request, const scene::Scene& scene,
                   const graph::ContactGraph& graph, double dwell_s,
                   const graph::PruneWeights& weights, Plans& plans, std::ostream& err) {
  // The explorer's start state can differ from a tick at rest (its first tick moves the hand).
  if (graph.goal >= 0 && graph.goal == graph.start) {
    SayNothingToPlan(request, scene, graph.nodes[std::size_t(graph.start)].cf, err);
    return PlansEnd::kNothingToPlan;
  }
  if (graph.goal < 0) {
    const std::string near = graph::NearGoalText(graph, scene.goal, 4);
    const std::string more = ExploreMoreHint(graph);
    err << request.scene_path << ": error: exploration never reached the goal "
        << states::ToString(scene.goal) << ", so there is no plan to extract; expected a "
        << "goal the tube can reach";
    if (!more.empty() || !near.empty())
      err << " (try " << more << (more.empty() || near.empty() ? "" : ", or ")
          << (near.empty() ? "" : "one of the nearest states reached: " + near) << ")";
    err << "\n";
    return PlansEnd::kGoalNotReached;
  }
  plans.paths = graph::KShortestPaths(graph, graph::ArcCosts(graph, weights), request.k);
  plans.out_dir = PlansDir(request, scene.name);
  std::error_code ec;
  fs::create_directories(plans.out_dir, ec);
  if (ec) {
    err << plans.out_dir.string() << ": error: cannot create the directory (" << ec.message()
        << "), expected a writable place for the plans\n";
    return PlansEnd::kNotWritten;
  }
  plan::CandidateOptions options;
  options.synthesis = request.synthesis;
  options.dwell_s = dwell_s;
  options.scene_ref =
      fs::relative(fs::absolute(request.scene_path), fs::absolute(plans.out_dir), ec)
          .generic_string();
  // Each replayed as its file will read: what `evaluate` on the written plan sees.
  plans.candidates =
      plan::MakeCandidates(scene, graph, plans.paths, options, io::TrajectoryAsWritten);
  AddMotionCandidate(request, scene, graph, options, plans);
  plans.feasible = std::count_if(plans.candidates.begin(), plans.candidates.end(),
                                 [](const plan::Candidate& c) { return c.judgement.feasible; });
  int written = 0;
  for (plan::Candidate& c : plans.candidates) {
    if (!c.judgement.feasible && !request.all) continue;
    if (const std::string e = WriteCandidate(c, ++written, request, scene.name, plans.out_dir);
        !e.empty()) {
      err << e << "\n";
      return PlansEnd::kNotWritten;
    }
  }
  return PlansEnd::kWritten;
}

}  // namespace tubeplan::batch
