#pragma once
// A hand trajectory replayed through the core with no plan to judge (`tubeplan simulate`,
// docs/simulate-output.md): the contact formations it passes through, its peaks, the ticks
// each flag marked and the core's run time.

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <tubeplan/core/core.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::plan {

/// A contact formation entered, and when.
struct Visit {
  double t_s = 0.0;
  std::string cf;
  bool fault =
      false;  ///< entered on a tick the core flagged fault: {} there is not the tube's state
};

/// What a replay saw, tick by tick.
struct Simulation {
  std::vector<Visit> visits;  ///< every change of the contact formation, the first tick's included
  std::string final_cf;       ///< the last tick's contact formation
  double peak_force_N = 0.0, peak_force_t_s = 0.0;      ///< the operator's force and its time
  double peak_strain = 0.0, peak_strain_t_s = 0.0;      ///< the largest bending strain and its time
  double peak_energy_J = 0.0, peak_torque_Nm = 0.0;     ///< bending energy, the operator's torque
  std::array<long, core::kStepFlagCount> flag_ticks{};  ///< ticks carrying each StepFlag bit
  double core_s = 0.0;                                  ///< wall-clock time in the core's steps
  double worst_tick_s = 0.0;                            ///< the slowest step's
  std::size_t tick_count = 0;
  double duration_s = 0.0;  ///< from the first tick's time to the last's
};

/// Sees every tick after the core's step: the core, the step's output and its formation's text.
using StepWatcher = std::function<void(const core::Core& core, const core::StepOutput& out,
                                       const std::string& cf_text)>;

/// Resets `core` with the held end at the first tick's pose and steps it through every tick of
/// `ticks` (at least one); `watch` (may be empty) sees each tick.
Simulation Simulate(trajectories::TickSource& ticks, core::Core& core,
                    const StepWatcher& watch = {});

}  // namespace tubeplan::plan
