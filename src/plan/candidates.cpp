#include <algorithm>
#include <iomanip>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include <tubeplan/graph/explore.hpp>
#include <tubeplan/plan/candidates.hpp>

namespace tubeplan::plan {
namespace {

// The graph's node of each state (-1 for one it lacks).
std::vector<int> NodesOf(const graph::ContactGraph& graph, const std::vector<std::string>& states) {
  std::vector<int> nodes;
  for (const std::string& cf : states) nodes.push_back(graph.FindNode(cf));
  return nodes;
}

// Cuts `hand` in the middle of the replay's first stay in `goal` (if another state followed it),
// and not before the goal counts (its entry, the dwell and two steps), so that a plan of those
// poses ends in its goal.
void CutInGoalStay(const Judgement& run, const std::string& goal, double dwell_s,
                   std::vector<trajectories::HandSample>& hand) {
  const auto first = std::find_if(run.observed.begin(), run.observed.end(),
                                  [&](const Observation& o) { return o.cf == goal; });
  if (first == run.observed.end() || first + 1 == run.observed.end() || hand.size() < 2) return;
  const double step_s = hand[1].t_s - hand[0].t_s;
  const double counted_s = std::min(first->t_s + dwell_s + 2.0 * step_s, (first + 1)->t_s);
  const double cut_s = std::max(0.5 * (first->t_s + (first + 1)->t_s), counted_s);
  const auto end =
      std::find_if(hand.begin(), hand.end(), [&](const auto& h) { return h.t_s >= cut_s; });
  hand.erase(end == hand.end() ? end : end + 1, hand.end());
}

}  // namespace

std::vector<Candidate> MakeCandidates(const scene::Scene& scene, const graph::ContactGraph& graph,
                                      std::span<const graph::Path> paths,
                                      const CandidateOptions& options,
                                      const AsWritten& as_written) {
  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    Candidate c;
    c.path = paths[i];
    for (const int n : c.path.nodes) c.plan.states.push_back(graph.nodes[std::size_t(n)].cf);
    c.plan.scene = options.scene_ref;
    c.plan.limits.max_force_N = scene.device.max_force_N;
    c.plan.limits.dwell_s = options.dwell_s;
    // At the asked speed, then each slower one until a replay is feasible: the hand aimed at
    // the witnesses' hand poses, at their held end's poses, at the held end's poses of the
    // stays of least force, and at those with the end brought in along the tube (each aim
    // once: those that coincide with an earlier one are left out), the feasible one of least
    // peak force kept (else the last tried); where none holds, at those with the first reach
    // over the parts.
    trajectories::SynthesisOptions synthesis = options.synthesis;
    synthesis.seed = options.synthesis.seed + i;
    const auto aims = graph::DistinctAims(scene, graph, c.path, graph::kPlanAims);
    int tried = 0;
    // The first try whose replay got to the goal by other states than the path's, and those.
    std::optional<Candidate> reached;
    std::vector<std::string> passed;
    for (std::size_t k = 0; k <= options.slower.size(); ++k) {
      synthesis.peak_speed_m_per_s =
          options.synthesis.peak_speed_m_per_s / (k > 0 ? options.slower[k - 1] : 1.0);
      for (const auto& [aim, waypoints] : aims) {
        // A detour over the parts only where no straighter reach holds at this speed.
        if (aim == graph::Aim::kOver && c.judgement.feasible) continue;
        Candidate t = c;
        t.trajectory = trajectories::SynthesizeTrajectory(waypoints, synthesis);
        t.duration_s = t.trajectory.samples.back().t_s;
        t.peak_speed_m_per_s = synthesis.peak_speed_m_per_s;
        t.aim = aim;
        t.tries = ++tried;
        const std::optional<trajectories::Trajectory> read = as_written(t.trajectory);
        t.judgement = read ? Judge(scene, *read, t.plan.states, t.plan.limits) : Judgement{};
        if (!reached && read) {
          passed = StatesToGoal(t.judgement, c.plan.states.back());
          if (!passed.empty() && passed != c.plan.states) reached = t;
        }
        const bool better =
            t.judgement.feasible &&
            (!c.judgement.feasible || t.judgement.peak_force_N < c.judgement.peak_force_N);
        if (better || !c.judgement.feasible) c = std::move(t);
      }
      if (c.judgement.feasible) break;
    }
    // Where no try holds the path's states, the one that got to the goal is judged on the states
    // its replay passed through: a plan that works, said as it goes.
    if (!c.judgement.feasible && reached) {
      Candidate t = std::move(*reached);
      t.plan.states = std::move(passed);
      t.restated = true;
      CutInGoalStay(t.judgement, t.plan.states.back(), options.dwell_s, t.trajectory.samples);
      t.duration_s = t.trajectory.samples.back().t_s;
      if (const auto read = as_written(t.trajectory))
        t.judgement = Judge(scene, *read, t.plan.states, t.plan.limits);
      if (t.judgement.feasible) {
        t.path.nodes = NodesOf(graph, t.plan.states);
        c = std::move(t);
      }
    }
    candidates.push_back(std::move(c));
  }
  std::stable_partition(candidates.begin(), candidates.end(),
                        [](const Candidate& c) { return c.judgement.feasible; });
  return candidates;
}

std::vector<std::string> StatesToGoal(const Judgement& seen, const std::string& goal) {
  std::vector<std::string> states;
  std::set<std::string> cut;
  for (const Observation& o : seen.observed) {
    if (cut.contains(o.cf)) continue;
    const auto again = std::find(states.begin(), states.end(), o.cf);
    if (again != states.end()) {
      cut.insert(again + 1, states.end());
      states.erase(again + 1, states.end());
      continue;
    }
    states.push_back(o.cf);
    if (o.cf == goal) break;
  }
  if (states.size() < 2 || states.back() != goal) return {};
  return states;
}

std::optional<Candidate> MotionCandidate(const scene::Scene& scene,
                                         const graph::ContactGraph& graph,
                                         const CandidateOptions& options,
                                         const AsWritten& as_written) {
  if (graph.goal < 0 || graph.start < 0 || graph.goal == graph.start) return std::nullopt;
  const graph::Node& goal = graph.nodes[std::size_t(graph.goal)];
  std::vector<trajectories::HandSample> hand = graph::GoalMotionPath(scene, graph);
  if (hand.size() < 2) return std::nullopt;
  const std::vector<std::string> ends = {graph.nodes[std::size_t(graph.start)].cf, goal.cf};
  Limits limits;
  limits.max_force_N = scene.device.max_force_N;
  limits.dwell_s = options.dwell_s;
  trajectories::Trajectory own;
  own.samples = hand;
  CutInGoalStay(Judge(scene, own, ends, limits), goal.cf, options.dwell_s, hand);
  Candidate c;
  c.from_motion = true;
  c.plan.scene = options.scene_ref;
  c.plan.limits = limits;
  // On the scene's step, as the explorer ran it.
  trajectories::SynthesisOptions synthesis = options.synthesis;
  synthesis.rate_Hz = 1.0 / scene.model.time_step_s;
  for (std::size_t k = 0; k <= options.slower.size(); ++k) {
    Candidate t = c;
    t.trajectory =
        trajectories::RetimeHandPath(hand, synthesis, k > 0 ? options.slower[k - 1] : 1.0);
    t.duration_s = t.trajectory.samples.back().t_s;
    t.peak_speed_m_per_s = trajectories::PeakSpeed(t.trajectory.samples);
    t.tries = int(k) + 1;
    const std::optional<trajectories::Trajectory> read = as_written(t.trajectory);
    if (read) {
      // Replayed once to see which states it passes, then judged on them.
      const Judgement seen = Judge(scene, *read, ends, t.plan.limits);
      t.plan.states = StatesToGoal(seen, goal.cf);
      t.judgement =
          t.plan.states.empty() ? seen : Judge(scene, *read, t.plan.states, t.plan.limits);
    }
    if (t.plan.states.empty()) t.plan.states = ends;
    c = std::move(t);
    if (c.judgement.feasible) break;
  }
  c.path.nodes = NodesOf(graph, c.plan.states);
  return c;
}

std::string FirstFailure(const Judgement& j) {
  for (const TransitionVerdict& v : j.transitions)
    if (v.verdict == Verdict::kInfeasible) return v.from + " -> " + v.to + ": " + v.reason;
  if (j.after_goal.started && j.after_goal.verdict == Verdict::kInfeasible)
    return j.after_goal.reason;
  return j.transitions.empty() ? "the trajectory did not load" : "no transition judged";
}

std::string VerdictText(const Candidate& c) {
  std::ostringstream text;
  text << std::setprecision(3)
       << (c.judgement.feasible ? "feasible" : "infeasible: " + FirstFailure(c.judgement));
  // Evaluate's word, and the first transition that passed unplanned states with them.
  const auto detour = std::find_if(
      c.judgement.transitions.begin(), c.judgement.transitions.end(),
      [](const TransitionVerdict& v) { return v.verdict == Verdict::kFeasibleWithDetour; });
  if (c.judgement.feasible && detour != c.judgement.transitions.end())
    text << "-with-detour (" << detour->from << " -> " << detour->to << DetourText(*detour) << ")";
  if (c.tries > 1)
    text << " (try " << c.tries << ": "
         << (c.from_motion                      ? "the explorer's motion"
             : c.aim == graph::Aim::kHand       ? "the hand's"
             : c.aim == graph::Aim::kHeld       ? "the held end's poses"
             : c.aim == graph::Aim::kLeastForce ? "the held end's poses of least force"
             : c.aim == graph::Aim::kAlongAxis
                 ? "the held end's poses of least force, the end brought in along the tube"
                 : "the held end's poses of least force, over the parts first")
         << " at " << c.peak_speed_m_per_s * 1e3 << " mm/s)";
  if (c.restated) text << ", its states those its replay passed through";
  text << "; peak operator force " << c.judgement.peak_force_N << " N";
  return text.str();
}

}  // namespace tubeplan::plan
