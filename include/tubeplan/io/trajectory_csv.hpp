#pragma once
// Loading recorded hand trajectories (CSV; the format is documented in docs/trajectory-format.md).

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <tubeplan/io/diagnostics.hpp>
#include <tubeplan/plan/trajectory.hpp>

namespace tubeplan::io {

struct TrajectoryLoadOptions {
  double max_gap_s = 0.050;  ///< a longer pause between samples is an error (a dropped recording)
  /// |q| may differ from 1 by this much and is normalised; more is an error. A recorder writing
  /// six significant digits is off by ~1e-6, so 1e-3 catches real mistakes (a column swapped,
  /// degrees written for a quaternion) and never a rounding.
  double quaternion_norm_tolerance = 1e-3;
};

struct TrajectoryLoadResult {
  std::optional<plan::Trajectory> trajectory;  ///< set only when there is no error
  Diagnostics diagnostics;                     ///< every problem found (capped, see the docs)
};

TrajectoryLoadResult LoadTrajectoryFile(const std::filesystem::path& path,
                                        const TrajectoryLoadOptions& options = {});
TrajectoryLoadResult LoadTrajectoryText(std::string_view text, const std::string& display_name,
                                        const TrajectoryLoadOptions& options = {});

}  // namespace tubeplan::io
