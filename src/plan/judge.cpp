#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <tubeplan/core/core.hpp>
#include <tubeplan/plan/judge.hpp>

namespace tubeplan::plan {

namespace {

std::string Format(const char* what, double value, const char* unit, double limit, double t_s) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "limit exceeded: %s %.4g %s > %.4g %s at t = %.3f s", what,
                value, unit, limit, unit, t_s);
  return buffer;
}

Eigen::Isometry3d Pose(const HandSample& s) {
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
  }
  return "infeasible";
}

Judgement Judge(const scene::Scene& scene, const Trajectory& trajectory,
                const std::vector<std::string>& states, const Limits& limits) {
  const auto clock_start = std::chrono::steady_clock::now();
  Judgement j;
  const double T = scene.model.time_step_s;
  // One tick at a time (TickStream), not Resample: a long recording is not held twice.
  TickStream ticks(trajectory, T);
  core::Core core(scene);
  core.Reset(Pose(ticks.Tick(0)));
  const int dwell = std::max(1, static_cast<int>(std::lround(limits.dwell_s / T)));

  // Per planned transition i (states[i] -> states[i+1]).
  const std::size_t n = states.size() - 1;
  j.transitions.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    j.transitions[i].from = states[i];
    j.transitions[i].to = states[i + 1];
  }
  std::size_t at = 0;       // the transition being waited for
  bool failed = false;      // a transition failed: later ones are not reached
  std::string stable, raw;  // counted state and the core's state
  core::FormationKey raw_key{};
  int raw_held = 0;
  double raw_since = 0.0, raw_energy = 0.0;
  std::vector<std::string> passed;  // unplanned states since states[at]
  // Last tick's contacts, to measure each sliding PC's slip (fixed size: nothing allocated per
  // tick).
  core::StepOutput last{};
  long stuck_ticks = 0;  // held end separated from the hand, in a row

  auto fail = [&](std::size_t i, const std::string& reason) {
    TransitionVerdict& v = j.transitions[i];
    if (v.verdict != Verdict::kInfeasible || v.reason.empty()) v.reason = reason;
    v.verdict = Verdict::kInfeasible;
  };

  for (std::size_t k = 0; k < ticks.count(); ++k) {
    const HandSample sample = ticks.Tick(k);
    const core::StepOutput& out = core.Step(sample.t_s, Pose(sample));
    ++j.ticks;
    // Figures and limits of the transition under way.
    if (!failed && at < n) {
      TransitionVerdict& v = j.transitions[at];
      const double force_N = out.force_W_N.norm();
      v.peak_force_N = std::max(v.peak_force_N, force_N);
      if (force_N > limits.max_force_N && v.reason.empty())
        fail(at, Format("operator force", force_N, "N", limits.max_force_N, sample.t_s));
      if (out.max_strain > limits.max_strain && v.reason.empty())
        fail(at, Format("strain", out.max_strain, "", limits.max_strain, sample.t_s));
      for (const core::ContactState& c : out.Contacts()) {
        if (-c.distance_m > limits.max_penetration_m && v.reason.empty())
          fail(at, Format("penetration", -c.distance_m * 1e3, "mm", limits.max_penetration_m * 1e3,
                          sample.t_s));
        if (!c.sliding) continue;
        for (const core::ContactState& before : last.Contacts()) {
          if (before.tube == c.tube && before.part_element == c.part_element)
            v.friction_work_J += c.friction_W_N.norm() * (c.p_WC_m - before.p_WC_m).norm();
        }
      }
    }
    last = out;
    stuck_ticks = (out.flags & core::kProxySeparated) ? stuck_ticks + 1 : 0;

    // Debounce: a state counts once held `dwell` ticks.
    const core::FormationKey key = core::KeyOf(out);
    if (j.ticks == 1 || key != raw_key) {
      raw_key = key;
      raw = core.FormationText();  // text only when the state changes
      raw_held = 0;
      raw_since = sample.t_s;
      raw_energy = out.energy_J;
    }
    ++raw_held;
    const bool first = j.observed.empty();
    if (!(first || (raw_held == dwell && raw != stable))) continue;
    stable = raw;
    j.observed.push_back({raw_since, raw});
    if (first) {
      j.transitions[0].t_start_s = raw_since;
      j.transitions[0].energy_entry_J = raw_energy;
      if (raw != states[0]) {
        fail(0, "the replay starts in " + raw + ", not in the planned " + states[0]);
        failed = true;
      }
      continue;
    }
    if (failed || at >= n) continue;
    TransitionVerdict& v = j.transitions[at];
    if (raw == states[at + 1]) {
      v.t_end_s = raw_since;
      v.energy_exit_J = raw_energy;
      v.detour = passed;
      if (v.verdict == Verdict::kInfeasible && !v.reason.empty()) {
        failed = true;  // a limit was exceeded on the way
      } else {
        v.verdict = passed.empty() ? Verdict::kFeasible : Verdict::kFeasibleWithDetour;
      }
      passed.clear();
      ++at;
      if (at < n) {
        j.transitions[at].t_start_s = raw_since;
        j.transitions[at].energy_entry_J = raw_energy;
      }
    } else if (std::find(states.begin() + long(at) + 2, states.end(), raw) != states.end()) {
      v.t_end_s = raw_since;
      v.detour = passed;
      fail(at,
           "another state reached instead: " + raw + ", planned later, before " + states[at + 1]);
      failed = true;
    } else if (raw != states[at]) {
      passed.push_back(raw);
    }
  }

  const double t_end = ticks.TimeOf(ticks.count() - 1);
  if (!failed && at < n) {
    TransitionVerdict& v = j.transitions[at];
    v.t_end_s = t_end;
    v.detour = passed;
    if (v.reason.empty()) {
      char buffer[96];
      std::string why;
      if (stuck_ticks * T >= limits.stall_s) {
        std::snprintf(buffer, sizeof buffer,
                      "stalled: the tube was held back from the hand for the last %.2f s",
                      stuck_ticks * T);
        why = buffer;
      } else if (stable == states[at]) {
        why = passed.empty() ? "the trajectory ended still in " + stable
                             : "went back to " + stable + " and the trajectory ended";
      } else {
        why = "another state reached instead: " + stable + " (the trajectory ended there)";
      }
      fail(at, states[at + 1] + " never reached: " + why);
    }
    failed = true;
  }
  for (std::size_t i = 0; i < n; ++i) {
    TransitionVerdict& v = j.transitions[i];
    if (v.verdict == Verdict::kInfeasible && v.reason.empty())
      v.reason = "not reached: the plan failed at an earlier transition";
  }
  j.feasible = std::all_of(j.transitions.begin(), j.transitions.end(),
                           [](const auto& v) { return v.verdict != Verdict::kInfeasible; });
  j.replayed_s = t_end - ticks.TimeOf(0);
  j.run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return j;
}

}  // namespace tubeplan::plan
