#pragma once
// Writing plan files (docs/plan-format.md). Reading and validating them is the batch
// evaluation's (tubeplan evaluate).

#include <string>

#include <tubeplan/plan/plan.hpp>
#include <tubeplan/plan/trajectory.hpp>

namespace tubeplan::io {

/// The plan as YAML text, format version 1, units written out.
std::string FormatPlanYaml(const plan::Plan& plan);

/// A trajectory as CSV in the format LoadTrajectoryText reads: '#' metadata lines (device,
/// rate, units), the header t,px,py,pz,qw,qx,qy,qz, one row per sample (positions to the
/// nanometre, quaternions to 1e-9).
std::string FormatTrajectoryCsv(const plan::Trajectory& trajectory);

}  // namespace tubeplan::io
