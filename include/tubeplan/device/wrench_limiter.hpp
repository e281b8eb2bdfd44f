#pragma once
// The last thing between a computed wrench and a haptic device (docs/live.md, "Safety"): clamps,
// rate-limits, and zeroes on NaN, on a streak of missed deadlines and on stop. Used by every path
// that sends a wrench to a device, live or recorded.

#include <Eigen/Core>

#include <tubeplan/scene/scene.hpp>

namespace tubeplan::device {

struct SafetyLimits {
  double max_force_N = 8.5;
  double max_torque_Nm = 0.188;
  /// Largest change of force per second. The default lets the force go from zero to the maximum
  /// in 10 ms: fast enough for contact rendering (a 800 N/m wall hit at 1 m/s rises at 800 N/s),
  /// too slow for a step the operator would feel as a knock.
  double max_force_rate_N_per_s = 850.0;
  double max_torque_rate_Nm_per_s = 18.8;
  /// This many missed deadlines in a row fault the limiter (one late tick is tolerated: the
  /// wrench is then one tick old, which is safe; several mean the loop has lost control).
  int max_missed_deadlines = 3;
};

/// The device's limits from a scene, rates for a 10 ms ramp to the maximum.
SafetyLimits LimitsFor(const scene::Device& device);

enum class Fault : unsigned char { kNone, kNonFinite, kMissedDeadlines, kStopped };

struct LimitedWrench {
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_Nm = Eigen::Vector3d::Zero();
  bool clamped = false;        ///< the request exceeded a maximum
  bool rate_limited = false;   ///< the request changed faster than allowed
  Fault fault = Fault::kNone;  ///< set: the output is zero until Reset()
};

class WrenchLimiter {
 public:
  WrenchLimiter(const SafetyLimits& limits, double step_s);

  /// The wrench to send this tick for the requested one. Zero, and latched, on a non-finite
  /// request or a streak of missed deadlines; going to zero is never rate-limited (removing force
  /// cannot push the operator).
  LimitedWrench Command(const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm,
                        bool deadline_missed = false);

  /// Zero on this tick only (a stall: the loop woke late), not a fault: the commands after it
  /// ramp back up from zero at the rate limits.
  LimitedWrench Drop();
  /// Zero from now on (exit, device error), until Reset().
  void Stop();
  /// Clears a fault; the output then ramps up from zero.
  void Reset();
  Fault fault() const { return fault_; }

 private:
  LimitedWrench Zero();

  SafetyLimits limits_;
  double max_force_step_N_;
  double max_torque_step_Nm_;
  Eigen::Vector3d last_force_N_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_torque_Nm_ = Eigen::Vector3d::Zero();
  int missed_in_a_row_ = 0;
  Fault fault_ = Fault::kNone;
};

}  // namespace tubeplan::device
