#pragma once
// Hand trajectories: the pose of the operator's hand over time, as a PHANToM records it (loaded by
// io/trajectory_csv.hpp), and their resampling onto the core's fixed step. Plain data, SI.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tubeplan::plan {

/// One sample of the hand pose X_WH at time t_s.
struct HandSample {
  double t_s = 0.0;
  Eigen::Vector3d p_WH_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_WH = Eigen::Quaterniond::Identity();  ///< unit quaternion
};

struct Trajectory {
  std::vector<HandSample> samples;                ///< strictly increasing t_s, at least two
  std::string device;                             ///< from the "# device:" line, may be empty
  double nominal_rate_Hz = 0.0;                   ///< from the "# rate:" line, 0 when not given
  std::vector<std::string> extra_columns;         ///< names of columns beyond the pose
  std::vector<std::vector<double>> extra_values;  ///< per sample, in extra_columns order
};

/// The trajectory on the grid t0 + k T, k = 0 .. floor((t_end - t0) / T) (plus a tiny tolerance
/// so that a grid point that falls on the last sample up to rounding is kept). Positions are
/// interpolated linearly and orientations by spherical linear interpolation on the shorter arc
/// between the two samples around each grid time; grid times that coincide with a sample return
/// it exactly. Requires T > 0 and a trajectory of at least two samples.
std::vector<HandSample> Resample(const Trajectory& trajectory, double step_s);

/// The pose at time t_s, interpolated as Resample does; times outside the trajectory are held at
/// its ends. `cursor` is the index of a sample at or before t (start at 0); callers that move
/// forward in time pass it back each call, so a replay costs O(1) per tick and allocates nothing.
HandSample PoseAt(const Trajectory& trajectory, double t_s, std::size_t& cursor);

}  // namespace tubeplan::plan
