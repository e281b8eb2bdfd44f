#pragma once
// Hand trajectories: the pose of the operator's hand over time, as a PHANToM records it (loaded by
// io/trajectory_csv.hpp), and their resampling onto the core's fixed step. Plain data, SI.

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tubeplan::trajectories {

/// One sample of the hand pose X_WH at time t_s.
struct HandSample {
  double t_s = 0.0;
  Eigen::Vector3d p_WH_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_WH = Eigen::Quaterniond::Identity();  ///< unit quaternion
};

struct Trajectory {
  std::vector<HandSample> samples;  ///< strictly increasing t_s, at least two
  std::string device;               ///< from the "# device:" line, may be empty
  double nominal_rate_Hz = 0.0;     ///< from the "# rate:" line, 0 when not given
  /// From the "# stopped:" line a live recording of a run that stopped early ends with: why and
  /// when ("interrupted at t = 2.310 s"). Empty for a whole trajectory.
  std::string stopped_early;
  std::vector<std::string> extra_columns;  ///< names of columns beyond the pose
  /// Per sample, in extra_columns order: the number a field spells, NaN for other text (extra
  /// columns may hold any text). Empty when there are no extra columns (an empty vector per
  /// row would cost 24 bytes a sample: 86 MB for an hour at 1 kHz).
  std::vector<std::vector<double>> extra_values;
};

/// The trajectory on the grid t0 + k T, k = 0 .. floor((t_end - t0) / T) (plus a tiny tolerance
/// so that a grid point that falls on the last sample up to rounding is kept). Positions are
/// interpolated linearly and orientations by spherical linear interpolation on the shorter arc
/// between the two samples around each grid time; grid times that coincide with a sample return
/// it exactly. Requires T > 0 and a trajectory of at least two samples.
std::vector<HandSample> Resample(const Trajectory& trajectory, double step_s);

/// Resample's grid one tick at a time, for replays that must not hold a second copy of a long
/// trajectory: Tick(k) is Resample(...)[k] exactly, for k = 0, 1, 2, ... in order (a k may be
/// asked again). The grid t0 + k T, k < count(), is fixed by the first and last samples' times.
class TickSource {
 public:
  virtual ~TickSource() = default;
  std::size_t count() const { return count_; }
  /// The grid time of tick k: t0 + k T.
  double TimeOf(std::size_t k) const { return t0_ + static_cast<double>(k) * step_s_; }
  /// The last sample's time (the first is TimeOf(0)).
  double t_last_s() const { return t_last_s_; }
  virtual HandSample Tick(std::size_t k) = 0;

 protected:
  /// Throws std::invalid_argument as Resample does for a step that is not finite and positive.
  TickSource(double t_first_s, double t_last_s, double step_s);
  /// The time Tick(k) interpolates at: the grid time, held at the last sample.
  double SampleTimeOf(std::size_t k) const { return std::min(TimeOf(k), t_last_s_); }

 private:
  double step_s_ = 0.0;
  double t0_ = 0.0;
  double t_last_s_ = 0.0;
  std::size_t count_ = 0;
};

/// The ticks of a trajectory in memory, in O(1) a tick. Same requirements as Resample (it throws
/// the same way).
class TickStream final : public TickSource {
 public:
  TickStream(const Trajectory& trajectory, double step_s);
  HandSample Tick(std::size_t k) override;

 private:
  const Trajectory& trajectory_;
  std::size_t cursor_ = 0;
};

/// Samples in time order, one at a time: a trajectory file read row by row.
class SampleSource {
 public:
  virtual ~SampleSource() = default;
  /// The next sample; false after the last.
  virtual bool Next(HandSample& sample) = 0;
};

/// The ticks of samples that arrive in order (an hour's recording read from its file a second
/// time), holding only the two samples around the current grid time: TickStream's ticks, bit for
/// bit, for the trajectory those samples make. The first and last samples' times come from a
/// first pass (they fix the grid); a source that ends early or runs past t_last_s is a
/// std::runtime_error.
class SampleTicks final : public TickSource {
 public:
  SampleTicks(SampleSource& samples, double t_first_s, double t_last_s, double step_s);
  HandSample Tick(std::size_t k) override;

 private:
  void Advance();
  SampleSource& samples_;
  HandSample a_, b_;  // a_.t_s <= the current time < b_.t_s, or both the last sample at the end
  bool started_ = false, ended_ = false;
};

/// The pose at time t_s, interpolated as Resample does; times outside the trajectory are held at
/// its ends. `cursor` is the index of a sample at or before t (start at 0); callers that move
/// forward in time pass it back each call, so a replay costs O(1) per tick and allocates nothing.
HandSample PoseAt(const Trajectory& trajectory, double t_s, std::size_t& cursor);

}  // namespace tubeplan::trajectories
