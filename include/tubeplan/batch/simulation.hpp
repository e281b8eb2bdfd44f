#pragma once
// A recorded hand trajectory replayed through the core as `tubeplan simulate` does
// (docs/simulate-output.md): the scene read and the trajectory file checked in a streamed pass,
// then the file read again row by row as the core steps, so that an hour's recording is never
// held (docs/hardening.md).

#include <optional>
#include <ostream>
#include <string>

#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/plan/simulate.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::batch {

/// A simulation's inputs, read and checked.
struct SimulationInput {
  std::string scene_path;             ///< as given: the messages and the reports name it so
  std::string trajectory_path;        ///< as given
  std::optional<scene::Scene> scene;  ///< set when the scene has no error
  std::optional<io::TrajectoryInfo> trajectory;  ///< set when the trajectory file has no error
};

/// Reads the scene and checks the trajectory file, printing both's diagnostics on `err`. False
/// when either has an error.
bool LoadSimulation(const std::string& scene_path, const std::string& trajectory_path,
                    SimulationInput& input, std::ostream& err);

/// What a simulation gave.
struct Simulated {
  plan::Simulation run;
  int element_count = 0;       ///< the rod's elements
  std::string strain_warning;  ///< plan::StrainWarning of the peak strain, "" within range
};

/// Replays the checked trajectory file (LoadSimulation's) on the scene's step from its first
/// pose, saying on `err` when that is away from the scene's start pose (a plan may begin
/// mid-task); `watch` (may be empty) sees every tick. Throws io::InputChanged when the file is
/// no longer the one checked.
Simulated RunSimulation(const SimulationInput& input, std::ostream& err,
                        const plan::StepWatcher& watch = {});

}  // namespace tubeplan::batch
