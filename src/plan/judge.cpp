#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string_view>

#include <tubeplan/core/core.hpp>
#include <tubeplan/plan/judge.hpp>

namespace tubeplan::plan {

namespace {

// "strain 0.9263 > 0.2 at t = 1.000 s": the value with as many digits as it takes to differ
// from the limit as written (8.500001 N > 8.5 N, never 8.5 N > 8.5 N), a unit only when there
// is one.
std::string Format(const char* what, double value, const char* unit, double limit, double t_s) {
  const std::string space_unit = *unit != '\0' ? std::string(" ") + unit : std::string();
  char limit_text[32];
  std::snprintf(limit_text, sizeof limit_text, "%.4g", limit);
  char value_text[32];
  for (int digits = 4; digits <= 17; ++digits) {
    std::snprintf(value_text, sizeof value_text, "%.*g", digits, value);
    if (std::string_view(value_text) != limit_text) break;
  }
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "limit exceeded: %s %s%s > %s%s at t = %.3f s", what,
                value_text, space_unit.c_str(), limit_text, space_unit.c_str(), t_s);
  return buffer;
}

Eigen::Isometry3d Pose(const trajectories::HandSample& s) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = s.q_WH.toRotationMatrix();
  X.translation() = s.p_WH_m;
  return X;
}

}  // namespace

const char* ToString(Verdict verdict) {
  switch (verdict) {
    case Verdict::kFeasible:
      return "feasible";
    case Verdict::kFeasibleWithDetour:
      return "feasible-with-detour";
    case Verdict::kInfeasible:
      return "infeasible";
    case Verdict::kNotJudged:
      return "not judged";
  }
  return "infeasible";
}

Verdict Overall(const Judgement& judgement) {
  if (judgement.feasible) return Verdict::kFeasible;
  const auto infeasible = [](const TransitionVerdict& v) {
    return v.verdict == Verdict::kInfeasible;
  };
  const bool any_infeasible =
      std::any_of(judgement.transitions.begin(), judgement.transitions.end(), infeasible) ||
      (judgement.after_goal.started && infeasible(judgement.after_goal));
  return any_infeasible || judgement.stopped_early.empty() ? Verdict::kInfeasible
                                                           : Verdict::kNotJudged;
}

std::string DetourText(const TransitionVerdict& v) {
  std::string text = v.detour.empty() ? "" : " via";
  for (const std::string& d : v.detour) text += " " + d;
  return text;
}

std::string FlagWarning(std::size_t i, double seconds) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "for %.3g s ", seconds);
  return buffer + std::string(kWarnedFlags[i].meaning);
}

double ElasticStrainLimit(const model::TubeSpec& tube) {
  return tube.youngs_modulus_Pa >= 1e10 ? 0.005 : 0.5;
}

std::string StrainWarning(const model::TubeSpec& tube, double strain, double t_s) {
  const double limit = ElasticStrainLimit(tube);
  if (!(strain > limit)) return "";
  char buffer[320];
  std::snprintf(buffer, sizeof buffer,
                "strain %.4g at t = %.3f s is beyond the tube material's elastic range (%.3g for "
                "E %s 10 GPa): the beam models bend an elastic tube with small strains, so the "
                "forces, energies and shapes past it are not the tube's",
                strain, t_s, limit, tube.youngs_modulus_Pa >= 1e10 ? ">=" : "<");
  return buffer;
}

double TransitionVerdict::FlaggedSeconds(std::uint32_t flag) const {
  for (std::size_t i = 0; i < kWarnedFlags.size(); ++i)
    if (kWarnedFlags[i].flag == flag) return flagged_s[i];
  return 0.0;
}

Judging::Judging(std::vector<std::string> states, const Limits& limits, double step_s,
                 std::optional<model::TubeSpec> tube)
    : states_(std::move(states)),
      limits_(limits),
      step_s_(step_s),
      tube_(std::move(tube)),
      dwell_(std::max(1, static_cast<int>(std::lround(limits.dwell_s / step_s)))) {
  if (states_.size() < 2) throw std::invalid_argument("Judging: a plan needs two states");
  // Per planned transition i (states[i] -> states[i+1]).
  n_ = states_.size() - 1;
  j_.transitions.resize(n_);
  for (std::size_t i = 0; i < n_; ++i) {
    j_.transitions[i].from = states_[i];
    j_.transitions[i].to = states_[i + 1];
  }
  j_.after_goal.from = j_.after_goal.to = states_.back();
}

// The span under way: the transition, or the stretch after the goal; none once the plan failed.
TransitionVerdict* Judging::UnderWay() {
  if (failed_) return nullptr;
  if (at_ < n_) return j_.transitions[at_].started ? &j_.transitions[at_] : nullptr;
  return j_.after_goal.started ? &j_.after_goal : nullptr;
}

void Judging::Fail(TransitionVerdict& v, const std::string& reason, double t_s) {
  if (v.verdict == Verdict::kInfeasible && !v.reason.empty()) return;  // the first reason stays
  v.reason = (&v == &j_.after_goal ? "after the goal: " : "") + reason;
  v.verdict = Verdict::kInfeasible;
  v.t_failed_s = t_s;
}

// The first tick: the state the replay starts in opens the first transition, or fails it.
void Judging::Start(double t_s, const core::StepOutput& out, const std::string& cf) {
  t_first_ = t_s;
  raw_key_ = core::KeyOf(out);
  raw_ = stable_ = cf;
  raw_since_ = t_s;
  raw_energy_ = out.energy_J;
  j_.observed.push_back({t_s, cf});
  TransitionVerdict& first = j_.transitions[0];
  if (cf != states_[0]) {
    Fail(first, "the replay starts in " + cf + ", not in the planned " + states_[0], t_s);
    failed_ = true;
    return;
  }
  first.started = true;
  first.t_start_s = t_s;
  first.energy_entry_J = out.energy_J;
}

// One tick's figures and limits, kept apart until it is known which span they belong to.
void Judging::Measure(double t_s, const core::StepOutput& out) {
  Figures& f = pending_;
  const double force_N = out.force_W_N.norm();
  f.peak_force_N = std::max(f.peak_force_N, force_N);
  for (std::size_t i = 0; i < kWarnedFlags.size(); ++i)
    if (out.flags & kWarnedFlags[i].flag) f.flagged_s[i] += step_s_;
  const auto exceeded = [&](const std::string& reason) {
    if (f.failure.empty()) f.failure = reason, f.t_failure_s = t_s;
  };
  // At the device's clamp the force is the most the device renders, which a plan's limit is
  // often set to: the motion asked more, so a clamp at the limit (within the rounding of the
  // clamp's scaling) exceeds it too, and is said so rather than as "8.5 N > 8.5 N".
  const bool at_limit = std::abs(force_N - limits_.max_force_N) <= 1e-12 * limits_.max_force_N;
  if ((out.flags & core::kForceClamped) && at_limit) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "limit exceeded: operator force %.4g N at the device's clamp (the motion asks "
                  "more than it renders), limit %.4g N at t = %.3f s",
                  force_N, limits_.max_force_N, t_s);
    exceeded(text);
  } else if (force_N > limits_.max_force_N) {
    exceeded(Format("operator force", force_N, "N", limits_.max_force_N, t_s));
  }
  if (out.max_strain > limits_.max_strain)
    exceeded(Format("strain", out.max_strain, "", limits_.max_strain, t_s));
  for (const core::ContactState& c : out.Contacts()) {
    if (-c.distance_m > limits_.max_penetration_m)
      exceeded(
          Format("penetration", -c.distance_m * 1e3, "mm", limits_.max_penetration_m * 1e3, t_s));
    f.friction_work_J += c.friction_work_J;
  }
}

void Judging::Flush() {
  if (TransitionVerdict* v = UnderWay()) {
    v->peak_force_N = std::max(v->peak_force_N, pending_.peak_force_N);
    v->friction_work_J += pending_.friction_work_J;
    for (std::size_t i = 0; i < kWarnedFlags.size(); ++i) v->flagged_s[i] += pending_.flagged_s[i];
    if (!pending_.failure.empty()) Fail(*v, pending_.failure, pending_.t_failure_s);
  }
  pending_ = Figures{};
}

void Judging::Tick(double t_s, const core::StepOutput& out,
                   const std::function<std::string()>& cf_text) {
  ++j_.ticks;
  if (j_.ticks == 1) Start(t_s, out, cf_text());
  t_last_ = t_s;
  energy_last_ = out.energy_J;
  if (const double force_N = out.force_W_N.norm(); force_N > j_.peak_force_N || j_.ticks == 1)
    j_.peak_force_N = force_N, j_.peak_force_t_s = t_s;
  if (out.max_strain > j_.peak_strain || j_.ticks == 1)
    j_.peak_strain = out.max_strain, j_.peak_strain_t_s = t_s;
  stuck_ticks_ = (out.flags & core::kProxySeparated) ? stuck_ticks_ + 1 : 0;

  // Debounce: a state counts once held `dwell` ticks. A tick the core flags as a fault shows no
  // state of the tube (it reads {}): it neither changes the state nor counts towards its dwell.
  const bool fault = (out.flags & core::kSolverFault) != 0;
  if (!fault && j_.ticks > 1) {
    const core::FormationKey key = core::KeyOf(out);
    if (key != raw_key_) {
      Flush();  // the ticks of the state left were in the span under way
      raw_key_ = key;
      raw_ = cf_text();  // text only when the state changes
      raw_held_ = 0;
      raw_since_ = t_s;
      raw_energy_ = out.energy_J;
    }
  }
  Measure(t_s, out);
  if (fault) return;
  ++raw_held_;
  if (j_.ticks == 1 || raw_held_ != dwell_ || raw_ == stable_) return;
  stable_ = raw_;
  j_.observed.push_back({raw_since_, raw_});
  Counted();
  Flush();  // the ticks since raw_since_ are in the span the counted state opened, if any
}

// A new state counted (raw_, entered at raw_since_).
void Judging::Counted() {
  if (failed_) return;
  if (at_ == n_) {
    // After the goal: any other state counting leaves it.
    if (left_goal_for_.empty() && raw_ != states_.back()) {
      left_goal_for_ = raw_;
      left_goal_at_s_ = raw_since_;
      char when[48];
      std::snprintf(when, sizeof when, " at t = %.3f s", raw_since_);
      Fail(j_.after_goal, "left the goal for " + raw_ + when, raw_since_);
    }
    return;
  }
  const std::vector<std::string>& states = states_;
  TransitionVerdict& v = j_.transitions[at_];
  if (raw_ == states[at_ + 1]) {
    v.t_end_s = raw_since_;
    v.energy_exit_J = raw_energy_;
    v.detour = passed_;
    passed_.clear();
    ++at_;
    if (v.verdict == Verdict::kInfeasible && !v.reason.empty()) {
      failed_ = true;  // a limit was exceeded on the way: nothing after it is reached
      return;
    }
    v.verdict = v.detour.empty() ? Verdict::kFeasible : Verdict::kFeasibleWithDetour;
    TransitionVerdict& next = at_ < n_ ? j_.transitions[at_] : j_.after_goal;
    next.started = true;
    next.t_start_s = raw_since_;
    next.energy_entry_J = raw_energy_;
    if (at_ == n_) next.verdict = Verdict::kFeasible;
  } else if (std::find(states.begin() + long(at_) + 2, states.end(), raw_) != states.end()) {
    v.t_end_s = raw_since_;
    v.energy_exit_J = raw_energy_;
    v.detour = passed_;
    Fail(v, "another state reached instead: " + raw_ + ", planned later, before " + states[at_ + 1],
         raw_since_);
    failed_ = true;
  } else if (raw_ != states[at_] || !passed_.empty()) {
    // Every state passed on the way, in order, returns to the span's start too (a tube that
    // goes to X, back, and to X again has passed X, the start, X).
    passed_.push_back(raw_);
  }
}

// A run that stopped early: the span under way, unless a limit already failed it, and every
// span after it are not judged; the trajectory did not end, the run did.
void Judging::NotJudged(double t_end) {
  if (failed_) return;
  const std::string why = "the run stopped: " + j_.stopped_early;
  TransitionVerdict* under_way = UnderWay();
  if (under_way && under_way->verdict == Verdict::kInfeasible && !under_way->reason.empty()) {
    failed_ = true;  // judged before the stop; the spans after it are not reached
    return;
  }
  if (under_way) {
    under_way->t_end_s = t_end;
    under_way->energy_exit_J = energy_last_;
    under_way->detour = passed_;
  }
  for (std::size_t i = at_; i < n_; ++i) {
    j_.transitions[i].verdict = Verdict::kNotJudged;
    j_.transitions[i].reason = why;
  }
  j_.after_goal.verdict = Verdict::kNotJudged;
  j_.after_goal.reason = why;
  failed_ = true;
}

Judgement Judging::Finish(const std::string& stopped_early) {
  const std::vector<std::string>& states = states_;
  const double t_end = t_last_;
  const double T = step_s_;
  Flush();
  j_.stopped_early = stopped_early;
  if (!stopped_early.empty()) NotJudged(t_end);
  if (!failed_ && at_ < n_ && j_.transitions[at_].started) {
    TransitionVerdict& v = j_.transitions[at_];
    v.t_end_s = t_end;
    v.energy_exit_J = energy_last_;
    v.detour = passed_;
    if (v.reason.empty()) {
      char buffer[96];
      std::string why;
      if (stuck_ticks_ * T >= limits_.stall_s) {
        std::snprintf(buffer, sizeof buffer,
                      "stalled: the tube was held back from the hand for the last %.2f s",
                      stuck_ticks_ * T);
        why = buffer;
      } else if (stable_ == states[at_]) {
        why = passed_.empty() ? "the trajectory ended still in " + stable_
                              : "went back to " + stable_ + " and the trajectory ended";
      } else {
        why = "another state reached instead: " + stable_ + " (the trajectory ended there)";
      }
      Fail(v, states[at_ + 1] + " never reached: " + why, t_end);
    }
    failed_ = true;
  }
  TransitionVerdict& after = j_.after_goal;
  if (after.started && !failed_) {
    after.t_end_s = t_end;
    after.energy_exit_J = energy_last_;
    // A plan whose trajectory ends outside its goal says so, and where it went first.
    if (!left_goal_for_.empty() && after.reason.find("left the goal") == std::string::npos) {
      char when[48];
      std::snprintf(when, sizeof when, " at t = %.3f s", left_goal_at_s_);
      after.reason += "; left the goal for " + left_goal_for_ + when;
    }
    if (stable_ != states.back())
      after.reason += "; the trajectory ended in " + stable_ + ", not in the goal";
    else if (!left_goal_for_.empty())
      after.reason += "; it was back in the goal at the end";
  }
  for (std::size_t i = 0; i < n_; ++i) {
    TransitionVerdict& v = j_.transitions[i];
    if (v.verdict == Verdict::kInfeasible && v.reason.empty())
      v.reason = "not reached: the plan failed at an earlier transition";
  }
  j_.feasible = std::all_of(j_.transitions.begin(), j_.transitions.end(),
                            [](const auto& v) { return IsFeasible(v.verdict); }) &&
                after.started && IsFeasible(after.verdict);
  j_.replayed_s = t_end - t_first_;
  if (tube_) j_.strain_warning = StrainWarning(*tube_, j_.peak_strain, j_.peak_strain_t_s);
  return j_;
}

Judgement Judge(const scene::Scene& scene, const trajectories::Trajectory& trajectory,
                const std::vector<std::string>& states, const Limits& limits,
                const TickWatcher& watch) {
  // One tick at a time (TickStream), not Resample: a long recording is not held twice.
  trajectories::TickStream ticks(trajectory, scene.model.time_step_s);
  return Judge(scene, ticks, states, limits, watch, trajectory.stopped_early);
}

Judgement Judge(const scene::Scene& scene, trajectories::TickSource& ticks,
                const std::vector<std::string>& states, const Limits& limits,
                const TickWatcher& watch, const std::string& stopped_early) {
  const auto clock_start = std::chrono::steady_clock::now();
  const double T = scene.model.time_step_s;
  core::Core core(scene);
  core.Reset(Pose(ticks.Tick(0)));
  Judging judging(states, limits, T, scene.tube);
  const auto text = [&core] { return core.FormationText(); };
  for (std::size_t k = 0; k < ticks.count(); ++k) {
    const trajectories::HandSample sample = ticks.Tick(k);
    judging.Tick(sample.t_s, core.Step(sample.t_s, Pose(sample)), text);
    if (watch) watch(sample.t_s, core);
  }
  Judgement j = judging.Finish(stopped_early);
  j.run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return j;
}

}  // namespace tubeplan::plan
