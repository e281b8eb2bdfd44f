#pragma once
// A haptic device as the servo loop sees it, shaped like the established interfaces (CHAI3D's
// cGenericHapticDevice, HAPI's HAPIHapticsDevice): open, calibrate, read the pose, velocity and
// buttons, send a wrench, the device's limits, close. A wrench reaches a device only as the
// output of device::WrenchLimiter (Send takes a LimitedWrench), and disabling or closing a device
// sends zero first.

#include <cstdint>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/device/wrench_limiter.hpp>

namespace tubeplan::device {

/// What a device can do: its nominal limits (a real device reports its own at run time).
struct DeviceSpec {
  std::string name;
  double max_force_N = 0.0;
  double max_torque_Nm = 0.0;
  double max_stiffness_N_per_m = 0.0;  ///< largest stiffness it renders stably at 1 kHz
  double damping_Ns_per_m = 0.0;       ///< its own physical damping b (for passivity)
  Eigen::Vector3d workspace_half_extents_m = Eigen::Vector3d::Zero();  ///< box about its centre
  int button_count = 0;
  bool senses_rotation = false;  ///< 6-DOF pose in (gimbal encoders)
  bool actuates_torque = false;  ///< 6-DOF wrench out
};

/// The PHANToM Premium 1.5/6DOF's nominal data (docs/scene-format.md, "Device": from CHAI3D's
/// device tables; the workspace 381 x 267 x 191 mm from SensAble's data sheet).
DeviceSpec PhantomPremium15Spec();

/// The safety limits for a device: the smaller of its own maxima and the scene's, a 10 ms ramp
/// from zero to the maximum (as LimitsFor(scene::Device)).
SafetyLimits LimitsFor(const DeviceSpec& device, const scene::Device& scene_device);

/// One reading of the device.
struct DeviceSample {
  /// Increases with every new reading the device delivered; equal to the last one means the data
  /// is stale (the device, its driver or its link stopped updating).
  std::uint64_t sequence = 0;
  Eigen::Isometry3d X_W_hand = Eigen::Isometry3d::Identity();  ///< pose of the hand (stylus)
  Eigen::Vector3d v_W_m_per_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_W_rad_per_s = Eigen::Vector3d::Zero();
  std::uint32_t buttons = 0;  ///< bit i: button i pressed
};

class HapticDevice {
 public:
  virtual ~HapticDevice() = default;
  HapticDevice() = default;
  HapticDevice(const HapticDevice&) = delete;
  HapticDevice& operator=(const HapticDevice&) = delete;

  /// Connects. Returns an empty string on success, else what went wrong.
  virtual std::string Open() = 0;
  /// Homes the encoders where the device needs it (a no-op for others); empty on success.
  virtual std::string Calibrate() = 0;
  virtual const DeviceSpec& spec() const = 0;
  /// The latest reading. False on a device error (then `sample` is unchanged). Called from the
  /// servo thread only; never allocates.
  virtual bool Read(DeviceSample& sample) = 0;
  /// Sends the limiter's output: the only way a wrench reaches a device.
  void Send(const LimitedWrench& wrench) { SendWrench(wrench.force_N, wrench.torque_Nm); }
  /// Zero force now, and the device stays at zero until the next Send.
  void Disable() { SendWrench(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()); }
  /// Sends zero and disconnects; safe to call twice.
  virtual void Close() = 0;

 protected:
  virtual void SendWrench(const Eigen::Vector3d& force_W_N, const Eigen::Vector3d& torque_W_Nm) = 0;
};

}  // namespace tubeplan::device
