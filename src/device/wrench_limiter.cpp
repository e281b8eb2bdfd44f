#include <stdexcept>

#include <tubeplan/device/wrench_limiter.hpp>

namespace tubeplan::device {
namespace {

// Scales v down to length `limit` if longer; returns whether it did.
bool ClampLength(Eigen::Vector3d& v, double limit) {
  const double length = v.norm();
  if (length <= limit) return false;
  v *= limit / length;
  return true;
}

}  // namespace

SafetyLimits LimitsFor(const scene::Device& device) {
  constexpr double kRampToMax_s = 0.010;
  SafetyLimits limits;
  limits.max_force_N = device.max_force_N;
  limits.max_torque_Nm = device.max_torque_Nm;
  limits.max_force_rate_N_per_s = device.max_force_N / kRampToMax_s;
  limits.max_torque_rate_Nm_per_s = device.max_torque_Nm / kRampToMax_s;
  return limits;
}

WrenchLimiter::WrenchLimiter(const SafetyLimits& limits, double step_s)
    : limits_(limits),
      max_force_step_N_(limits.max_force_rate_N_per_s * step_s),
      max_torque_step_Nm_(limits.max_torque_rate_Nm_per_s * step_s) {
  if (!(step_s > 0.0) || !(limits.max_force_N >= 0.0) || !(limits.max_torque_Nm >= 0.0) ||
      !(max_force_step_N_ > 0.0) || !(max_torque_step_Nm_ > 0.0) || limits.max_missed_deadlines < 1)
    throw std::invalid_argument("WrenchLimiter: limits and step must be positive");
}

LimitedWrench WrenchLimiter::Zero() {
  last_force_N_.setZero();
  last_torque_Nm_.setZero();
  LimitedWrench out;
  out.fault = fault_;
  return out;
}

LimitedWrench WrenchLimiter::Command(const Eigen::Vector3d& force_N,
                                     const Eigen::Vector3d& torque_Nm, bool deadline_missed) {
  if (fault_ != Fault::kNone) return Zero();
  missed_in_a_row_ = deadline_missed ? missed_in_a_row_ + 1 : 0;
  if (missed_in_a_row_ >= limits_.max_missed_deadlines) {
    fault_ = Fault::kMissedDeadlines;
    return Zero();
  }
  if (!force_N.allFinite() || !torque_Nm.allFinite()) {
    fault_ = Fault::kNonFinite;
    return Zero();
  }
  LimitedWrench out;
  out.force_N = force_N;
  out.torque_Nm = torque_Nm;
  out.clamped = ClampLength(out.force_N, limits_.max_force_N);
  out.clamped = ClampLength(out.torque_Nm, limits_.max_torque_Nm) || out.clamped;
  // Rate limit the change, except towards zero: shrinking along the current direction never
  // pushes the operator, so a drop is passed at once.
  Eigen::Vector3d force_step = out.force_N - last_force_N_;
  Eigen::Vector3d torque_step = out.torque_Nm - last_torque_Nm_;
  const bool force_drops = out.force_N.isZero(0.0);
  const bool torque_drops = out.torque_Nm.isZero(0.0);
  if (!force_drops && ClampLength(force_step, max_force_step_N_)) {
    out.force_N = last_force_N_ + force_step;
    out.rate_limited = true;
  }
  if (!torque_drops && ClampLength(torque_step, max_torque_step_Nm_)) {
    out.torque_Nm = last_torque_Nm_ + torque_step;
    out.rate_limited = true;
  }
  last_force_N_ = out.force_N;
  last_torque_Nm_ = out.torque_Nm;
  return out;
}

LimitedWrench WrenchLimiter::Drop() { return Zero(); }

void WrenchLimiter::Stop() {
  fault_ = Fault::kStopped;
  Zero();
}

void WrenchLimiter::Reset() {
  fault_ = Fault::kNone;
  missed_in_a_row_ = 0;
  Zero();
}

}  // namespace tubeplan::device
