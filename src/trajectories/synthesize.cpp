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

namespace {

// The operator's tremor and the device's resolution (SynthesisOptions::tremor_m, quantum_m).
class OperatorNoise {
 public:
  explicit OperatorNoise(const SynthesisOptions& o)
      : tremor_m_(o.tremor_m), quantum_m_(o.quantum_m) {
    std::seed_seq sequence{static_cast<std::uint32_t>(o.seed),
                           static_cast<std::uint32_t>(o.seed >> 32)};
    std::mt19937_64 rng(sequence);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int axis = 0; axis < 3; ++axis) {
      frequency_[std::size_t(axis)] = 8.0 + 4.0 * unit(rng);
      phase_[std::size_t(axis)] = 2.0 * std::numbers::pi * unit(rng);
    }
  }

  void Apply(HandSample& sample) const {
    if (tremor_m_ > 0.0) {
      for (int axis = 0; axis < 3; ++axis) {
        sample.p_WH_m[axis] += tremor_m_ * std::sin(2.0 * std::numbers::pi *
                                                        frequency_[std::size_t(axis)] * sample.t_s +
                                                    phase_[std::size_t(axis)]);
      }
    }
    if (quantum_m_ > 0.0) {
      for (int axis = 0; axis < 3; ++axis)
        sample.p_WH_m[axis] = quantum_m_ * std::round(sample.p_WH_m[axis] / quantum_m_);
    }
  }

 private:
  double tremor_m_, quantum_m_;
  std::array<double, 3> frequency_{}, phase_{};
};

}  // namespace

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

  const OperatorNoise noise(o);
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
    noise.Apply(sample);
    trajectory.samples.push_back(sample);
  }
  return trajectory;
}

double PeakSpeed(std::span<const HandSample> samples) {
  double peak_m_per_s = 0.0;
  for (std::size_t k = 1; k < samples.size(); ++k)
    peak_m_per_s = std::max(peak_m_per_s, (samples[k].p_WH_m - samples[k - 1].p_WH_m).norm() /
                                              (samples[k].t_s - samples[k - 1].t_s));
  return peak_m_per_s;
}

Trajectory RetimeHandPath(std::span<const HandSample> path, const SynthesisOptions& o,
                          double stretch) {
  Trajectory trajectory;
  trajectory.device = "synthetic (tubeplan plans): the explorer's hand path, retimed";
  trajectory.nominal_rate_Hz = o.rate_Hz;
  if (path.empty()) return trajectory;
  const double speed_m_per_s = PeakSpeed(path);
  double turn_rad_per_s = 0.0;
  for (std::size_t k = 1; k < path.size(); ++k)
    turn_rad_per_s = std::max(turn_rad_per_s, path[k].q_WH.angularDistance(path[k - 1].q_WH) /
                                                  (path[k].t_s - path[k - 1].t_s));
  // The clock stretched so that neither speed nor turn passes its asked peak, never shrunk; a
  // move made at the asked speed reads a millionth faster from rounding and keeps its clock.
  double scale =
      std::max({1.0, speed_m_per_s / o.peak_speed_m_per_s, turn_rad_per_s / o.peak_turn_rad_per_s});
  if (scale < 1.0 + 1e-6) scale = 1.0;
  scale *= stretch;
  Trajectory scaled;
  scaled.samples.reserve(path.size() + 1);
  for (const HandSample& s : path)
    scaled.samples.push_back({(s.t_s - path.front().t_s) * scale, s.p_WH_m, s.q_WH});
  if (o.hold_s > 0.0) {
    HandSample last = scaled.samples.back();
    last.t_s += o.hold_s;
    scaled.samples.push_back(last);
  }
  const OperatorNoise noise(o);
  trajectory.samples = Resample(scaled, 1.0 / o.rate_Hz);
  for (HandSample& sample : trajectory.samples) noise.Apply(sample);
  return trajectory;
}

}  // namespace tubeplan::trajectories
