#pragma once
// Plan files (docs/plan-format.md): reading them with their scene and trajectory, every problem
// at once as file:line:col, and writing them.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <tubeplan/io/diagnostics.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/plan/plan.hpp>
#include <tubeplan/scene/scene.hpp>
#include <tubeplan/states/contact_formation.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::io {

struct PlanLoadResult {
  /// All set only when there is no error anywhere (plan, its scene, its trajectory).
  std::optional<plan::Plan> plan;
  std::optional<scene::Scene> scene;
  std::optional<trajectories::Trajectory> trajectory;  ///< unless the options asked for it streamed
  /// With PlanLoadOptions::trajectory_in_memory false: the checked trajectory file, to replay
  /// row by row (TrajectoryFileSamples) instead of `trajectory`.
  std::optional<TrajectoryInfo> trajectory_file;
  std::vector<states::ContactFormation> states;  ///< the planned CFs, parsed
  Diagnostics diagnostics;
};

/// Reads a plan, then its scene and trajectory (paths relative to the plan's directory), and
/// checks each planned CF against the scene: unknown elements are errors naming them; the word
/// `goal` stands for the scene's goal.
struct PlanLoadOptions {
  /// True: the trajectory's samples are loaded (what Monte Carlo perturbation and the live
  /// verification need). False: the trajectory file is checked streamed (the same diagnostics)
  /// and only its TrajectoryInfo kept, so that memory does not grow with the recording.
  bool trajectory_in_memory = true;
};

PlanLoadResult LoadPlanFile(const std::filesystem::path& path, const PlanLoadOptions& options = {});
PlanLoadResult LoadPlanText(std::string_view yaml_text, const std::string& display_name,
                            const std::filesystem::path& directory,
                            const PlanLoadOptions& options = {});

/// The plan as YAML text, format version 1, units written out.
std::string FormatPlanYaml(const plan::Plan& plan);

/// A trajectory as CSV in the format LoadTrajectoryText reads: '#' metadata lines (device,
/// rate, units), the header t,px,py,pz,qw,qx,qy,qz, one row per sample (positions to the
/// nanometre, quaternions to 1e-9), and the "# stopped:" line of a trajectory that has one.
std::string FormatTrajectoryCsv(const trajectories::Trajectory& trajectory);

/// The trajectory as its file reads back (FormatTrajectoryCsv, then LoadTrajectoryText: rounded
/// as written), or nothing if it would not load; what a replay of the written plan sees
/// (plan::AsWritten).
std::optional<trajectories::Trajectory> TrajectoryAsWritten(
    const trajectories::Trajectory& trajectory);

/// The '#' metadata lines and the header of a trajectory CSV, as FormatTrajectoryCsv writes them,
/// with `extra_columns` after the pose columns.
std::string TrajectoryCsvHeader(const std::string& device, double nominal_rate_Hz,
                                const std::vector<std::string>& extra_columns = {});
/// The line that ends the recording of a run that stopped early (trajectories::Trajectory's
/// stopped_early).
std::string TrajectoryCsvStopped(const std::string& stopped_early);
/// Appends one sample as a row for a streamed recording: t as the shortest text that reads back
/// to the same double (so a replay's grid t0 + k T meets the samples exactly), the position to
/// the nanometre and the quaternion to 1e-9 as written (the reader normalises it), then
/// `extra_fields` (the extra columns' fields, comma-separated) when not empty.
void AppendTrajectoryCsvRow(std::string& out, const trajectories::HandSample& sample,
                            std::string_view extra_fields = {});

}  // namespace tubeplan::io
