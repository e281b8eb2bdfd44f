#include <algorithm>

#include <tubeplan/device/device.hpp>

namespace tubeplan::device {

DeviceSpec PhantomPremium15Spec() {
  DeviceSpec spec;
  spec.name = "PHANToM Premium 1.5/6DOF";
  spec.max_force_N = 8.5;
  spec.max_torque_Nm = 0.188;
  spec.max_stiffness_N_per_m = 800.0;
  spec.damping_Ns_per_m = 5.0;
  spec.workspace_half_extents_m = Eigen::Vector3d(0.381, 0.267, 0.191) / 2.0;
  spec.button_count = 2;
  spec.senses_rotation = true;
  spec.actuates_torque = true;
  return spec;
}

SafetyLimits LimitsFor(const DeviceSpec& device, const scene::Device& scene_device) {
  scene::Device d = scene_device;
  d.max_force_N = std::min(d.max_force_N, device.max_force_N);
  d.max_torque_Nm = std::min(d.max_torque_Nm, device.actuates_torque ? device.max_torque_Nm : 0.0);
  SafetyLimits limits = LimitsFor(d);
  // A device without torque output gets none; the limiter still needs positive rates.
  if (!(limits.max_torque_rate_Nm_per_s > 0.0)) limits.max_torque_rate_Nm_per_s = 1e-9;
  return limits;
}

}  // namespace tubeplan::device
