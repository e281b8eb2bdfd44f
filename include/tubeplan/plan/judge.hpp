#pragma once
// The feasibility judge: replays a plan's trajectory through the core and gives each planned
// transition a verdict (docs/evaluate.md). A state counts once the core has kept it for the
// plan's dwell; the counted sequence is matched against the plan.

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <tubeplan/core/core.hpp>
#include <tubeplan/model/tube.hpp>
#include <tubeplan/plan/plan.hpp>
#include <tubeplan/scene/scene.hpp>
#include <tubeplan/states/contact_formation.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::plan {

/// kNotJudged: a live run stopped (a fault, Ctrl-C) before the replay finished the span.
enum class Verdict { kFeasible, kFeasibleWithDetour, kInfeasible, kNotJudged };
/// "feasible", "feasible-with-detour", "infeasible", "not judged"
const char* ToString(Verdict verdict);
inline bool IsFeasible(Verdict v) {
  return v == Verdict::kFeasible || v == Verdict::kFeasibleWithDetour;
}

/// The core's flags a verdict warns about, in one place (the core may rename its flags; this
/// table is the one mapping from them): per transition the time spent in ticks carrying each is
/// summed (TransitionVerdict::flagged_s, in this order), reported under `key` in the JSON report
/// and as a warning in the text and the HTML (FlagWarning).
struct WarnedFlag {
  std::uint32_t flag;   ///< a core::StepFlag bit
  const char* key;      ///< the report's field [s], e.g. "fault_s"
  const char* meaning;  ///< what those ticks mean for the verdict (after "for X s ")
};
inline constexpr std::array<WarnedFlag, 3> kWarnedFlags = {{
    {core::kSolverFault, "fault_s",
     "the core could not solve the tick (flag fault: the hand's pose was not finite, or the solve "
     "was): it held the tube still and sent no force, and the judge kept the state of the ticks "
     "before: the verdict rests on ticks the core did not resolve"},
    {core::kBeyondLinearRange, "beyond_linear_s",
     "the linear model drew the tube beyond its range (tip deflection above l/3): the verdict "
     "rests on a shape the tube cannot take"},
    {core::kNotConverged, "unconverged_s",
     "the core's solve stopped short of its tolerance (flag unconverged): the tube was snapping "
     "through, or the hand jumped, and was between equilibria there"},
}};
/// "for 0.012 s the core held the tube back ...": the warning for kWarnedFlags[i].
std::string FlagWarning(std::size_t i, double seconds);

/// The warning for a strain beyond the tube material's elastic range (ElasticStrainLimit), or ""
/// when `strain` is within it: what `simulate` and `evaluate` print.
std::string StrainWarning(const model::TubeSpec& tube, double strain, double t_s);
/// The largest strain the tube's material bends elastically to, as far as bending theory goes:
/// 0.5 % for a material of E >= 10 GPa (metals and hard plastics yield near it), 50 % below
/// (elastomers stay elastic far beyond, but small-strain bending theory degrades past it).
double ElasticStrainLimit(const model::TubeSpec& tube);

/// A planned transition a -> b, or the stretch after the goal (Judgement::after_goal), with what
/// the replay did in its span: ticks from entering a (t_start_s) up to entering b (t_end_s, or
/// the trajectory's last tick); a state is entered when the core first shows it, the tick it
/// counts from. A transition the replay never got to has no span and no figures (started false).
struct TransitionVerdict {
  std::string from, to;  ///< planned CFs
  Verdict verdict = Verdict::kInfeasible;
  std::string reason;               ///< empty when feasible
  std::vector<std::string> detour;  ///< unplanned states passed between from and to
  bool started = false;             ///< the replay got to it: t_start_s .. t_end_s and figures hold
  double t_start_s = 0.0, t_end_s = 0.0;  ///< entering `from` .. entering `to` (or the end)
  double t_failed_s = 0.0;  ///< when it was judged infeasible (the limit's tick, a state's entry)
  double peak_force_N = 0.0;
  double friction_work_J = 0.0;  ///< sum over sliding PCs of |F_f| times the slip
  double energy_entry_J = 0.0, energy_exit_J = 0.0;  ///< at t_start_s and at t_end_s
  /// Time in ticks carrying each flag of kWarnedFlags (same order) [s].
  std::array<double, kWarnedFlags.size()> flagged_s{};
  /// The time for one flag of kWarnedFlags (0 for a flag not in it).
  double FlaggedSeconds(std::uint32_t flag) const;
};

/// " via S1 S2 ...": the unplanned states a span passed (empty for none), as reports print them
/// after its verdict.
std::string DetourText(const TransitionVerdict& v);

struct Observation {
  double t_s = 0.0;  ///< when the core entered it (it counted `dwell` later)
  std::string cf;
};

struct Judgement {
  /// Every transition feasible, and the trajectory kept the goal within the limits after it.
  bool feasible = false;
  std::vector<TransitionVerdict> transitions;
  /// From entering the goal to the trajectory's end (from = to = the goal), started only when
  /// every transition was feasible: limits hold over the whole trajectory, and leaving the goal
  /// (another state counting) makes it infeasible, with the reason "after the goal: ...".
  TransitionVerdict after_goal;
  std::vector<Observation> observed;  ///< counted states, in order
  /// The replay's largest operator force and strain over every tick, and when.
  double peak_force_N = 0.0, peak_force_t_s = 0.0;
  double peak_strain = 0.0, peak_strain_t_s = 0.0;
  /// StrainWarning of the peak strain ("" within the material's elastic range, or when the judge
  /// was not given the tube).
  std::string strain_warning;
  long ticks = 0;
  double replayed_s = 0.0;  ///< trajectory time replayed
  double run_s = 0.0;       ///< wall time of the replay
  /// Why and when the run that made the trajectory stopped before its end ("interrupted at t =
  /// 2.310 s"); empty when the trajectory is whole. What it did not finish is kNotJudged.
  std::string stopped_early;
};

/// The plan's verdict: kFeasible (Judgement::feasible), kInfeasible (a span judged infeasible,
/// or a whole trajectory that did not get to the goal), or kNotJudged (none infeasible, but the
/// run stopped before the replay judged them all).
Verdict Overall(const Judgement& judgement);

/// The judge, tick by tick: batch replay (Judge below) and the live servo loop feed it the core's
/// output of every tick, so both give the same verdicts for the same ticks.
class Judging {
 public:
  /// `states`: planned CFs (canonical, at least two); `step_s`: the core's step; `tube`: the
  /// replayed tube, for the warning on strains beyond its material's elastic range.
  Judging(std::vector<std::string> states, const Limits& limits, double step_s,
          std::optional<model::TubeSpec> tube = std::nullopt);

  /// One tick at t_s. `cf_text` gives the CF's canonical text (core::Core::FormationText()); it is
  /// called only on a tick whose formation key differs from the last one's.
  void Tick(double t_s, const core::StepOutput& out, const std::function<std::string()>& cf_text);
  /// Closes the judgement after the last tick (nothing is judged without a tick).
  /// `stopped_early`: why and when the run stopped before the trajectory's end (Judgement's), or
  /// empty; the spans it cut short are then not judged, rather than judged never reached.
  Judgement Finish(const std::string& stopped_early = {});

  // The judgement so far (live display).
  const std::vector<TransitionVerdict>& transitions() const { return j_.transitions; }
  const TransitionVerdict& after_goal() const { return j_.after_goal; }
  const std::vector<Observation>& observed() const { return j_.observed; }
  /// Index of the planned transition under way; states().size() - 1 once all are done.
  std::size_t at() const { return at_; }
  bool failed() const { return failed_; }
  const std::vector<std::string>& states() const { return states_; }
  const std::string& counted() const { return stable_; }  ///< the last state that counted
  const std::string& current() const { return raw_; }     ///< the core's state now
  long ticks() const { return j_.ticks; }

 private:
  // What ticks not yet given to a span showed: those since the core entered the state it is in
  // now (raw_), which belong to the span that state opens if it counts, else to the one under
  // way.
  struct Figures {
    double peak_force_N = 0.0, friction_work_J = 0.0;
    std::array<double, kWarnedFlags.size()> flagged_s{};
    std::string failure;  // the first limit exceeded, with its time
    double t_failure_s = 0.0;
  };
  void Start(double t_s, const core::StepOutput& out, const std::string& cf);
  void Measure(double t_s, const core::StepOutput& out);
  void Flush();  // pending_ into the span under way (or dropped once the plan failed)
  void Counted();
  void NotJudged(double t_end);
  TransitionVerdict* UnderWay();
  void Fail(TransitionVerdict& v, const std::string& reason, double t_s);

  std::vector<std::string> states_;
  Limits limits_;
  double step_s_;
  std::optional<model::TubeSpec> tube_;
  int dwell_;
  Judgement j_;
  std::size_t n_ = 0, at_ = 0;
  bool failed_ = false;
  std::string stable_, raw_;
  core::FormationKey raw_key_{};
  int raw_held_ = 0;
  double raw_since_ = 0.0, raw_energy_ = 0.0, t_first_ = 0.0, t_last_ = 0.0, energy_last_ = 0.0;
  std::vector<std::string> passed_;
  long stuck_ticks_ = 0;
  Figures pending_;
  std::string left_goal_for_;  // the first state counted after the goal, and when
  double left_goal_at_s_ = 0.0;
};

/// Sees every tick of a replay after the core's step: the tick's time and the core (its last()
/// output, its Centreline on demand). Read only; reports record from it (evaluate --html), so
/// that what they draw is the judged replay itself, not a second one.
using TickWatcher = std::function<void(double t_s, const core::Core& core)>;

/// Replays `trajectory` (resampled onto the scene's step) from its first pose and judges
/// `states` (planned CFs, canonical) under `limits`; `watch` (may be empty) sees every tick. A
/// recording of a run that stopped early (Trajectory::stopped_early) is judged as that run was.
Judgement Judge(const scene::Scene& scene, const trajectories::Trajectory& trajectory,
                const std::vector<std::string>& states, const Limits& limits,
                const TickWatcher& watch = {});
/// The same from ticks that come one at a time (a trajectory file replayed row by row,
/// SampleTicks); `ticks` must be on the scene's step. The same ticks give the same judgement.
/// `stopped_early` as Judging::Finish's.
Judgement Judge(const scene::Scene& scene, trajectories::TickSource& ticks,
                const std::vector<std::string>& states, const Limits& limits,
                const TickWatcher& watch = {}, const std::string& stopped_early = {});

}  // namespace tubeplan::plan
