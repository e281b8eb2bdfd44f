#include <algorithm>
#include <limits>
#include <stdexcept>

#include <tubeplan/device/emulator.hpp>

namespace tubeplan::device {

EmulatorDevice::EmulatorDevice(Clock& clock, trajectories::Trajectory target, HandModel hand)
    : clock_(clock), target_(std::move(target)), hand_(hand), spec_(PhantomPremium15Spec()) {
  if (target_.samples.size() < 2)
    throw std::invalid_argument("EmulatorDevice: the target trajectory needs two samples");
  if (!(hand_.mass_kg > 0.0) || !(hand_.substep_s > 0.0) || !(hand_.stiffness_N_per_m >= 0.0) ||
      !(hand_.damping_Ns_per_m >= 0.0))
    throw std::invalid_argument("EmulatorDevice: the hand's mass and step must be positive");
  spec_.name += " (emulated)";
}

double EmulatorDevice::target_duration_s() const {
  return target_.samples.back().t_s - target_.samples.front().t_s;
}

Eigen::Isometry3d EmulatorDevice::TargetAt(double t_s, Eigen::Vector3d& v_W_m_per_s) {
  const double t0 = target_.samples.front().t_s;
  // Velocity by a 1 ms forward difference of the interpolated pose (the samples are 1 ms apart
  // in a 1 kHz recording: finer would only see the interpolation's kinks).
  constexpr double kDt_s = 1e-3;
  std::size_t ahead = cursor_;
  const trajectories::HandSample a = trajectories::PoseAt(target_, t0 + t_s, cursor_);
  const trajectories::HandSample b = trajectories::PoseAt(target_, t0 + t_s + kDt_s, ahead);
  v_W_m_per_s = (b.p_WH_m - a.p_WH_m) / kDt_s;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = a.q_WH.toRotationMatrix();
  X.translation() = a.p_WH_m;
  return X;
}

std::string EmulatorDevice::Open() {
  start_ns_ = clock_.NowNs();
  elapsed_s_ = 0.0;
  cursor_ = 0;
  Eigen::Vector3d v;
  const Eigen::Isometry3d X = TargetAt(0.0, v);
  p_W_m_ = X.translation();
  v_W_m_per_s_.setZero();
  q_W_ = Eigen::Quaterniond(X.linear());
  force_N_.setZero();
  torque_Nm_.setZero();
  open_ = true;
  return {};
}

void EmulatorDevice::Advance(double to_s) {
  // A late read integrates the time it missed, in sub-steps; more than 100 ms is a stall of the
  // caller, not motion: the hand is then advanced by 100 ms only.
  to_s = std::min(to_s, elapsed_s_ + 0.1);
  const double m = hand_.mass_kg, K = hand_.stiffness_N_per_m, D = hand_.damping_Ns_per_m;
  const double b = spec_.damping_Ns_per_m;
  while (elapsed_s_ < to_s) {
    const double h = std::min(hand_.substep_s, to_s - elapsed_s_);
    Eigen::Vector3d v_target;
    const Eigen::Isometry3d X_target = TargetAt(elapsed_s_ + h, v_target);
    const Eigen::Vector3d a = (K * (X_target.translation() - p_W_m_) +
                               D * (v_target - v_W_m_per_s_) - b * v_W_m_per_s_ + force_N_) /
                              m;
    v_W_m_per_s_ += h * a;  // semi-implicit Euler: velocity first, then position
    p_W_m_ += h * v_W_m_per_s_;
    q_W_ = Eigen::Quaterniond(X_target.linear());
    elapsed_s_ += h;
  }
}

bool EmulatorDevice::Read(DeviceSample& sample) {
  if (!open_ || fail_reads_) return false;
  if (frozen_) {
    sample = last_;  // a driver that stopped updating hands back its last reading
    return true;
  }
  Advance(double(clock_.NowNs() - start_ns_) * 1e-9);
  DeviceSample s;
  s.sequence = ++sequence_;
  s.X_W_hand.linear() = q_W_.toRotationMatrix();
  s.X_W_hand.translation() = p_W_m_;
  s.v_W_m_per_s = v_W_m_per_s_;
  if (inject_nan_) s.X_W_hand.translation().x() = std::numeric_limits<double>::quiet_NaN();
  last_ = s;
  sample = s;
  return true;
}

void EmulatorDevice::SendWrench(const Eigen::Vector3d& force_W_N,
                                const Eigen::Vector3d& torque_W_Nm) {
  force_N_ = force_W_N;
  torque_Nm_ = torque_W_Nm;
  ++sends_;
}

void EmulatorDevice::Close() {
  if (!open_) return;
  Disable();
  open_ = false;
}

}  // namespace tubeplan::device
