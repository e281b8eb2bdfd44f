#include <algorithm>
#include <chrono>

#include <tubeplan/plan/simulate.hpp>

namespace tubeplan::plan {
namespace {

Eigen::Isometry3d HandPose(const trajectories::HandSample& sample) {
  Eigen::Isometry3d X_W_hand = Eigen::Isometry3d::Identity();
  X_W_hand.linear() = sample.q_WH.toRotationMatrix();
  X_W_hand.translation() = sample.p_WH_m;
  return X_W_hand;
}

// One tick's figures into the summary: a new visit when the formation (or its fault) changed,
// the peaks, the flags.
void Count(const core::StepOutput& out, double t_s, const std::string& cf_text, Simulation& sum) {
  const bool fault = (out.flags & core::kSolverFault) != 0;
  if (sum.visits.empty() || sum.visits.back().cf != cf_text || sum.visits.back().fault != fault)
    sum.visits.push_back({t_s, cf_text, fault});
  const double force_N = out.force_W_N.norm();
  if (force_N > sum.peak_force_N) sum.peak_force_N = force_N, sum.peak_force_t_s = t_s;
  if (out.max_strain > sum.peak_strain) sum.peak_strain = out.max_strain, sum.peak_strain_t_s = t_s;
  sum.peak_energy_J = std::max(sum.peak_energy_J, out.energy_J);
  sum.peak_torque_Nm = std::max(sum.peak_torque_Nm, out.torque_W_Nm.norm());
  for (int b = 0; b < core::kStepFlagCount; ++b)
    if (out.flags & (1u << b)) ++sum.flag_ticks[std::size_t(b)];
}

}  // namespace

Simulation Simulate(trajectories::TickSource& ticks, core::Core& core, const StepWatcher& watch) {
  core.Reset(HandPose(ticks.Tick(0)));
  Simulation sum;
  for (std::size_t k = 0; k < ticks.count(); ++k) {
    const trajectories::HandSample sample = ticks.Tick(k);
    const Eigen::Isometry3d X_W_hand = HandPose(sample);
    // The core's step alone is timed.
    const auto start = std::chrono::steady_clock::now();
    const core::StepOutput& out = core.Step(sample.t_s, X_W_hand);
    const double tick_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    sum.core_s += tick_s;
    sum.worst_tick_s = std::max(sum.worst_tick_s, tick_s);
    sum.final_cf = core.FormationText();
    Count(out, sample.t_s, sum.final_cf, sum);
    if (watch) watch(core, out, sum.final_cf);
  }
  sum.tick_count = ticks.count();
  sum.duration_s = ticks.TimeOf(sum.tick_count - 1) - ticks.TimeOf(0);
  return sum;
}

}  // namespace tubeplan::plan
