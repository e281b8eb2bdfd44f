#include <algorithm>
#include <iomanip>
#include <sstream>
#include <utility>

#include <tubeplan/plan/candidates.hpp>

namespace tubeplan::plan {

std::vector<Candidate> MakeCandidates(const scene::Scene& scene, const graph::ContactGraph& graph,
                                      std::span<const graph::Path> paths,
                                      const CandidateOptions& options,
                                      const AsWritten& as_written) {
  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    Candidate c;
    c.path = &paths[i];
    for (const int n : c.path->nodes) c.plan.states.push_back(graph.nodes[std::size_t(n)].cf);
    c.plan.scene = options.scene_ref;
    c.plan.limits.max_force_N = scene.device.max_force_N;
    c.plan.limits.dwell_s = options.dwell_s;
    // At the asked speed, then each slower one until a replay is feasible: the hand aimed at
    // the witnesses' hand poses, at their held end's poses and at the held end's poses of the
    // stays of least force (each aim once: those that coincide with an earlier one are left
    // out), the feasible one of least peak force kept (else the last tried).
    trajectories::SynthesisOptions synthesis = options.synthesis;
    synthesis.seed = options.synthesis.seed + i;
    const auto aims = graph::DistinctAims(scene, graph, *c.path);
    int tried = 0;
    for (std::size_t k = 0; k <= options.slower.size(); ++k) {
      synthesis.peak_speed_m_per_s =
          options.synthesis.peak_speed_m_per_s / (k > 0 ? options.slower[k - 1] : 1.0);
      for (const auto& [aim, waypoints] : aims) {
        Candidate t = c;
        t.trajectory = trajectories::SynthesizeTrajectory(waypoints, synthesis);
        t.duration_s = t.trajectory.samples.back().t_s;
        t.peak_speed_m_per_s = synthesis.peak_speed_m_per_s;
        t.aim = aim;
        t.tries = ++tried;
        const std::optional<trajectories::Trajectory> read = as_written(t.trajectory);
        t.judgement = read ? Judge(scene, *read, t.plan.states, t.plan.limits) : Judgement{};
        const bool better =
            t.judgement.feasible &&
            (!c.judgement.feasible || t.judgement.peak_force_N < c.judgement.peak_force_N);
        if (better || !c.judgement.feasible) c = std::move(t);
      }
      if (c.judgement.feasible) break;
    }
    candidates.push_back(std::move(c));
  }
  std::stable_partition(candidates.begin(), candidates.end(),
                        [](const Candidate& c) { return c.judgement.feasible; });
  return candidates;
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
  if (c.tries > 1)
    text << " (try " << c.tries << ": "
         << (c.aim == graph::Aim::kHand   ? "the hand's"
             : c.aim == graph::Aim::kHeld ? "the held end's poses"
                                          : "the held end's poses of least force")
         << " at " << c.peak_speed_m_per_s * 1e3 << " mm/s)";
  text << "; peak operator force " << c.judgement.peak_force_N << " N";
  return text.str();
}

}  // namespace tubeplan::plan
