#pragma once
// The `emulator` device: a simulated PHANToM Premium 1.5/6DOF held by a simulated hand. The hand
// is a point mass pulled towards a target pose (a trajectory file or the plan's trajectory) by a
// PD "arm" and pushed by the force the device renders, so a plan that needs more force than the
// device gives shows up as a hand that falls behind. It runs on a device::Clock: in real time on
// the monotonic clock, or stepped (deterministic, faster than real time) in tests.
//
// The hand's orientation follows the target's exactly (a stiff wrist): the PHANToM Premium's
// largest torque, 0.188 N m, would turn a hand by nothing one could see, and the core's grip
// saturates at that torque anyway.

#include <cstdint>

#include <tubeplan/device/clock.hpp>
#include <tubeplan/device/device.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::device {

/// The operator's hand and arm along each axis: m x'' = K (x* - x) + D (v* - v) - b x' + F.
struct HandModel {
  /// Hand plus the device's moving parts (a PHANToM's apparent mass is about 75 g; a relaxed
  /// grasping hand and forearm a few hundred grams).
  double mass_kg = 0.30;
  /// Arm's pull towards the target: a relaxed arm is a few hundred N/m (Hogan's measurements of
  /// human arm stiffness are 200-800 N/m); 300 N/m lets the 8.5 N device push the hand back by
  /// 28 mm, which is how a too-hard plan shows.
  double stiffness_N_per_m = 300.0;
  /// Damping relative to the target's velocity: about critical, 2 sqrt(K m) = 19 N s/m.
  double damping_Ns_per_m = 19.0;
  /// Integration step inside the emulator (semi-implicit Euler; stable far beyond this for
  /// these values: omega T = 0.003).
  double substep_s = 1e-4;
};

class EmulatorDevice final : public HapticDevice {
 public:
  /// Follows `target` (at least two samples) from its first pose, starting at the clock's time
  /// when Open() is called; after its end the target stays at its last pose.
  EmulatorDevice(Clock& clock, trajectories::Trajectory target, HandModel hand = {});

  std::string Open() override;
  std::string Calibrate() override { return {}; }
  const DeviceSpec& spec() const override { return spec_; }
  bool Read(DeviceSample& sample) override;
  void Close() override;

  /// Target time that has elapsed since Open (s).
  double elapsed_s() const { return elapsed_s_; }
  double target_duration_s() const;

  // What the device was sent (for tests: the force it pushed the hand with).
  const Eigen::Vector3d& force_sent_N() const { return force_N_; }
  const Eigen::Vector3d& torque_sent_Nm() const { return torque_Nm_; }
  std::uint64_t sends() const { return sends_; }
  bool open() const { return open_; }

  // Fault injection (tests): a NaN pose; frozen data (the sequence stops advancing); a failing
  // read.
  void InjectNaN(bool on) { inject_nan_ = on; }
  void Freeze(bool on) { frozen_ = on; }
  void FailReads(bool on) { fail_reads_ = on; }

 protected:
  void SendWrench(const Eigen::Vector3d& force_W_N, const Eigen::Vector3d& torque_W_Nm) override;

 private:
  void Advance(double to_s);
  Eigen::Isometry3d TargetAt(double t_s, Eigen::Vector3d& v_W_m_per_s);

  Clock& clock_;
  trajectories::Trajectory target_;
  HandModel hand_;
  DeviceSpec spec_;
  bool open_ = false;
  std::int64_t start_ns_ = 0;
  double elapsed_s_ = 0.0;
  std::size_t cursor_ = 0;
  Eigen::Vector3d p_W_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_W_m_per_s_ = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_W_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d force_N_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_Nm_ = Eigen::Vector3d::Zero();
  std::uint64_t sequence_ = 0;
  std::uint64_t sends_ = 0;
  bool inject_nan_ = false, frozen_ = false, fail_reads_ = false;
  DeviceSample last_{};
};

}  // namespace tubeplan::device
