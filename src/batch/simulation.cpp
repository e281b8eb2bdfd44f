#include <numbers>

#include <tubeplan/batch/simulation.hpp>
#include <tubeplan/core/core.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/plan/judge.hpp>

namespace tubeplan::batch {
namespace {

// The core starts with the held end at the hand's first pose. A trajectory that starts away
// from the scene's start is allowed but said.
void SayStartAway(const SimulationInput& input, const trajectories::HandSample& first,
                  std::ostream& err) {
  const scene::Scene& s = *input.scene;
  const double start_offset_m = (first.p_WH_m - s.X_WH_start.translation()).norm();
  const double start_turn_rad =
      Eigen::AngleAxisd(s.X_WH_start.linear().transpose() * first.q_WH.toRotationMatrix()).angle();
  if (start_offset_m > 1e-3 || start_turn_rad > 1e-2) {
    err << input.trajectory_path << ": warning: the trajectory starts " << start_offset_m * 1e3
        << " mm and " << start_turn_rad * 180.0 / std::numbers::pi
        << " deg away from the scene's start pose; the held end starts at the trajectory's\n";
  }
}

}  // namespace

bool LoadSimulation(const std::string& scene_path, const std::string& trajectory_path,
                    SimulationInput& input, std::ostream& err) {
  input.scene_path = scene_path;
  input.trajectory_path = trajectory_path;
  io::SceneLoadResult scene = io::LoadSceneFile(scene_path);
  io::TrajectoryScanResult trajectory = io::ScanTrajectoryFile(trajectory_path);
  err << scene.diagnostics.FormatAll() << trajectory.diagnostics.FormatAll();
  input.scene = std::move(scene.scene);
  input.trajectory = std::move(trajectory.info);
  return input.scene && input.trajectory;
}

Simulated RunSimulation(const SimulationInput& input, std::ostream& err,
                        const plan::StepWatcher& watch) {
  const scene::Scene& s = *input.scene;
  // Ticks one at a time from the file's rows: only the two samples around a tick are held.
  io::TrajectoryFileSamples samples(*input.trajectory);
  trajectories::SampleTicks ticks(samples, input.trajectory->t_first_s, input.trajectory->t_last_s,
                                  s.model.time_step_s);
  core::Core core(s);
  SayStartAway(input, ticks.Tick(0), err);
  Simulated simulated;
  simulated.run = plan::Simulate(ticks, core, watch);
  simulated.element_count = core.element_count();
  // The same warning evaluate gives for a strain beyond the material's elastic range.
  simulated.strain_warning =
      plan::StrainWarning(s.tube, simulated.run.peak_strain, simulated.run.peak_strain_t_s);
  return simulated;
}

}  // namespace tubeplan::batch
