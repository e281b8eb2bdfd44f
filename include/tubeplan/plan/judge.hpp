#pragma once
// The feasibility judge: replays a plan's trajectory through the core and gives each planned
// transition a verdict (architecture.md, docs/evaluate.md). A state counts once the core has
// kept it for the plan's dwell; the counted sequence is matched against the plan.

#include <string>
#include <vector>

#include <tubeplan/plan/plan.hpp>
#include <tubeplan/plan/trajectory.hpp>
#include <tubeplan/scene/scene.hpp>
#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::plan {

enum class Verdict { kFeasible, kFeasibleWithDetour, kInfeasible };
const char* ToString(Verdict verdict);  ///< "feasible", "feasible-with-detour", "infeasible"

struct TransitionVerdict {
  std::string from, to;  ///< planned CFs
  Verdict verdict = Verdict::kInfeasible;
  std::string reason;                     ///< empty when feasible
  std::vector<std::string> detour;        ///< unplanned states passed between from and to
  double t_start_s = 0.0, t_end_s = 0.0;  ///< entering `from` .. entering `to` (or the end)
  double peak_force_N = 0.0;
  double friction_work_J = 0.0;  ///< sum over sliding PCs of |F_f| times the slip
  double energy_entry_J = 0.0, energy_exit_J = 0.0;
};

struct Observation {
  double t_s = 0.0;  ///< when the core entered it (it counted `dwell` later)
  std::string cf;
};

struct Judgement {
  bool feasible = false;
  std::vector<TransitionVerdict> transitions;
  std::vector<Observation> observed;  ///< counted states, in order
  long ticks = 0;
  double replayed_s = 0.0;  ///< trajectory time replayed
  double run_s = 0.0;       ///< wall time of the replay
};

/// Replays `trajectory` (resampled onto the scene's step) from its first pose and judges
/// `states` (planned CFs, canonical) under `limits`.
Judgement Judge(const scene::Scene& scene, const Trajectory& trajectory,
                const std::vector<std::string>& states, const Limits& limits);

}  // namespace tubeplan::plan
