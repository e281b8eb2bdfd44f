#pragma once
// The `openhaptics` device: a PHANToM through the OpenHaptics HD API. Built only with
// -DTUBEPLAN_OPENHAPTICS=ON and the SDK found (docs/live.md); compile-checked in every build
// against tools/openhaptics-check/HD/hd.h, a header declaring only the HD calls used here. Thin
// on purpose: each Read and Send is one synchronous call into the HD scheduler's thread (the
// HD API reads and writes the device only inside a frame there). Its limits are the device's own
// nominal ones, read at Open. The device frame is taken as the world frame, mm turned into m.

#include <memory>

#include <tubeplan/device/device.hpp>

namespace tubeplan::device {

class OpenHapticsDevice final : public HapticDevice {
 public:
  OpenHapticsDevice();
  ~OpenHapticsDevice() override;

  std::string Open() override;
  std::string Calibrate() override;
  const DeviceSpec& spec() const override { return spec_; }
  bool Read(DeviceSample& sample) override;
  void Close() override;

  struct State;  // what the scheduler callbacks exchange (src/device/openhaptics.cpp)

 protected:
  void SendWrench(const Eigen::Vector3d& force_W_N, const Eigen::Vector3d& torque_W_Nm) override;

 private:
  DeviceSpec spec_;
  std::unique_ptr<State> state_;
};

}  // namespace tubeplan::device
