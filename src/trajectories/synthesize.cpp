#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include <tubeplan/trajectories/synthesize.hpp>

namespace tubeplan::trajectories {

double MinimumJerk(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
}

Trajectory SynthesizeTrajectory(std::span<const Eigen::Isometry3d> waypoints,
                                const SynthesisOptions& o) {
  Trajectory trajectory;
  trajectory.device = "synthetic (tubeplan plans): minimum-jerk through the plan's witnesses";
  trajectory.nominal_rate_Hz = o.rate_Hz;
  if (waypoints.empty()) return trajectory;
  // Segment k runs from waypoint k to k+1 after holding at k; durations from the peak speeds.
  std::vector<double> start_s = {0.0}, move_s;
  for (std::size_t k = 0; k + 1 < waypoints.size(); ++k) {
    const double distance_m = (waypoints[k + 1].translation() - waypoints[k].translation()).norm();
    const double angle_rad =
        Eigen::AngleAxisd(waypoints[k].linear().transpose() * waypoints[k + 1].linear()).angle();
    const double T = std::max({1.875 * distance_m / o.peak_speed_m_per_s,
                               1.875 * angle_rad / o.peak_turn_rad_per_s, o.min_segment_s});
    move_s.push_back(T);
    start_s.push_back(start_s.back() + o.hold_s + T);
  }
  const double end_s = start_s.back() + o.hold_s;

  std::seed_seq sequence{static_cast<std::uint32_t>(o.seed),
                         static_cast<std::uint32_t>(o.seed >> 32)};
  std::mt19937_64 rng(sequence);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::array<double, 3> frequency{}, phase{};
  for (int axis = 0; axis < 3; ++axis) {
    frequency[std::size_t(axis)] = 8.0 + 4.0 * unit(rng);
    phase[std::size_t(axis)] = 2.0 * std::numbers::pi * unit(rng);
  }

  const long count = static_cast<long>(std::floor(end_s * o.rate_Hz + 1e-9)) + 1;
  trajectory.samples.reserve(static_cast<std::size_t>(count));
  std::size_t k = 0;
  for (long i = 0; i < count; ++i) {
    const double t = static_cast<double>(i) / o.rate_Hz;
    while (k + 1 < start_s.size() && t >= start_s[k + 1]) ++k;
    HandSample sample;
    sample.t_s = t;
    const Eigen::Isometry3d& A = waypoints[k];
    const double moving_from = start_s[k] + o.hold_s;
    if (k + 1 < waypoints.size() && t > moving_from) {
      const Eigen::Isometry3d& B = waypoints[k + 1];
      const double s = MinimumJerk((t - moving_from) / move_s[k]);
      sample.p_WH_m = A.translation() + s * (B.translation() - A.translation());
      sample.q_WH = Eigen::Quaterniond(A.linear()).slerp(s, Eigen::Quaterniond(B.linear()));
    } else {
      sample.p_WH_m = A.translation();
      sample.q_WH = Eigen::Quaterniond(A.linear());
    }
    sample.q_WH.normalize();
    if (o.tremor_m > 0.0) {
      for (int axis = 0; axis < 3; ++axis) {
        sample.p_WH_m[axis] +=
            o.tremor_m * std::sin(2.0 * std::numbers::pi * frequency[std::size_t(axis)] * t +
                                  phase[std::size_t(axis)]);
      }
    }
    if (o.quantum_m > 0.0) {
      for (int axis = 0; axis < 3; ++axis)
        sample.p_WH_m[axis] = o.quantum_m * std::round(sample.p_WH_m[axis] / o.quantum_m);
    }
    trajectory.samples.push_back(sample);
  }
  return trajectory;
}

}  // namespace tubeplan::trajectories
