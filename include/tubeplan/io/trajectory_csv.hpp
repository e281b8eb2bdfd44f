#pragma once
// Loading recorded hand trajectories (CSV; the format is documented in docs/trajectory-format.md):
// whole into memory, or checked and then replayed row by row for recordings too long to hold.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <tubeplan/io/diagnostics.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::io {

struct TrajectoryLoadOptions {
  double max_gap_s = 0.050;  ///< a longer pause between samples is an error (a dropped recording)
  /// |q| may differ from 1 by this much and is normalised; more is an error. A recorder writing
  /// six significant digits is off by ~1e-6, so 1e-3 catches real mistakes (a column swapped,
  /// degrees written for a quaternion) and never a rounding.
  double quaternion_norm_tolerance = 1e-3;
  /// A faster hand between two samples is warned about: 2 m/s is about the fastest a hand
  /// moves a desktop haptic device's stylus (a PHANToM's end tracks a few m/s at most).
  double max_hand_speed_m_per_s = 2.0;
};

struct TrajectoryLoadResult {
  std::optional<trajectories::Trajectory> trajectory;  ///< set only when there is no error
  Diagnostics diagnostics;  ///< every problem found (capped, see the docs)
};

TrajectoryLoadResult LoadTrajectoryFile(const std::filesystem::path& path,
                                        const TrajectoryLoadOptions& options = {});
TrajectoryLoadResult LoadTrajectoryText(std::string_view text, const std::string& display_name,
                                        const TrajectoryLoadOptions& options = {});

/// What a validating pass over a trajectory file learns: enough to summarise it and to replay
/// it by reading it again row by row (TrajectoryFileSamples), without holding its samples.
struct TrajectoryInfo {
  std::filesystem::path path;
  std::size_t sample_count = 0;  ///< at least two
  double t_first_s = 0.0;        ///< the first and last samples' times
  double t_last_s = 0.0;
  std::string device;                      ///< as trajectories::Trajectory's
  double nominal_rate_Hz = 0.0;            ///< as trajectories::Trajectory's
  std::string stopped_early;               ///< as trajectories::Trajectory's
  std::vector<std::string> extra_columns;  ///< as trajectories::Trajectory's
  std::uintmax_t file_bytes = 0;           ///< the file as it was checked, to see it change
  std::int64_t modified_ns = 0;
};

struct TrajectoryScanResult {
  std::optional<TrajectoryInfo> info;  ///< set only when there is no error
  Diagnostics diagnostics;             ///< exactly LoadTrajectoryFile's
  std::string read_error;  ///< when the file could not be read: why ("no such file", ...)
};

/// LoadTrajectoryFile's validation, streamed: the file is read in chunks of 64 KiB, with the
/// same input checks and every row's checks, and the same diagnostics; memory does not grow with
/// the file's length.
TrajectoryScanResult ScanTrajectoryFile(const std::filesystem::path& path,
                                        const TrajectoryLoadOptions& options = {});

/// A file that changed between its check and its replay (a recorder still writing it).
class InputChanged : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The samples of a checked trajectory file (ScanTrajectoryFile), read again in order, exactly
/// as LoadTrajectoryFile gives them: the second pass of a streamed replay
/// (trajectories::SampleTicks). Throws InputChanged, with a "file: error: ..." message, when the
/// file is not the one that was checked (its size, time or rows differ).
class TrajectoryFileSamples final : public trajectories::SampleSource {
 public:
  explicit TrajectoryFileSamples(const TrajectoryInfo& info,
                                 const TrajectoryLoadOptions& options = {});
  ~TrajectoryFileSamples() override;
  bool Next(trajectories::HandSample& sample) override;

 private:
  struct Rows;
  [[noreturn]] void Changed(const std::string& what) const;
  TrajectoryInfo info_;
  std::unique_ptr<Rows> rows_;
};

}  // namespace tubeplan::io
