#pragma once
// Operator trajectories made from hand poses (the witnesses of a candidate plan): minimum-jerk
// motion between them (Flash & Hogan 1985: the smoothest point-to-point motion, a good model of
// an unhurried human reach), a hold at each, sampled at the device's rate, with optional
// physiological tremor and position quantisation of the device's encoders.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::trajectories {

struct SynthesisOptions {
  double peak_speed_m_per_s = 0.08;  ///< a calm insertion; minimum jerk peaks at 1.875 x the mean
  double peak_turn_rad_per_s = 1.0;
  double min_segment_s = 0.4;  ///< no reach is quicker than this
  double hold_s = 0.3;         ///< pause at each waypoint (longer than any dwell a plan asks)
  double rate_Hz = 1000.0;
  /// Tremor: three sinusoids (one per axis) of this amplitude at frequencies in 8-12 Hz, the
  /// band of physiological tremor, with phases and frequencies from `seed`. 0: none.
  double tremor_m = 0.0;
  /// Device resolution: positions are rounded to multiples of this (PHANToM Premium 1.5: about
  /// 0.03 mm). 0: none.
  double quantum_m = 0.0;
  std::uint64_t seed = 1;
};

/// s(u) = 10u^3 - 15u^4 + 6u^5: the minimum-jerk profile, 0 -> 1 with zero velocity and
/// acceleration at both ends.
double MinimumJerk(double u);

/// A trajectory through `waypoints` (at least one): from each to the next by minimum jerk in
/// position and the same profile along the slerp in orientation, holding `hold_s` at each.
Trajectory SynthesizeTrajectory(std::span<const Eigen::Isometry3d> waypoints,
                                const SynthesisOptions& options);

/// The largest hand speed between consecutive samples [m/s] (0 for fewer than two).
double PeakSpeed(std::span<const HandSample> samples);

/// A recorded hand path (samples at strictly increasing times) as a plan's trajectory: its clock
/// stretched so that neither its speed nor its turn rate passes the options' peaks (a path within
/// them keeps its clock: never quicker than it was made), then `stretch` (>= 1) times more (a
/// slower try), held `hold_s` at its end, resampled at `rate_Hz`, with the options' tremor and
/// quantum.
Trajectory RetimeHandPath(std::span<const HandSample> path, const SynthesisOptions& options,
                          double stretch = 1.0);

}  // namespace tubeplan::trajectories
