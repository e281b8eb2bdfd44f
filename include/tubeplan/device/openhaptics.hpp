#pragma once
// The `openhaptics` device: a PHANToM through the OpenHaptics HD API. Built only with
// -DTUBEPLAN_OPENHAPTICS=ON and the SDK found (docs/live.md); compile-checked in every build
// against tools/openhaptics-check/HD/hd.h, a header declaring only the HD calls used here. Thin
// on purpose: each Read and Send is one synchronous call into the HD scheduler's thread (the
// HD API reads and writes the device only inside a frame there). Its limits are the device's own
// nominal ones, read at Open. The device frame is taken as the world frame, mm turned into m.

#include <memory>
#include <string>

#include <tubeplan/device/device.hpp>

namespace tubeplan::device {

class OpenHapticsDevice final : public HapticDevice {
 public:
  /// `configuration`: the device's name in the Phantom configuration utility; empty for the
  /// default device.
  explicit OpenHapticsDevice(std::string configuration = {});
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
  std::string configuration_;
  DeviceSpec spec_;
  std::unique_ptr<State> state_;
};

/// True when this tubeplan was built with the OpenHaptics SDK (-DTUBEPLAN_OPENHAPTICS=ON).
bool OpenHapticsBuiltIn();
/// The openhaptics device (`live --device openhaptics[:NAME]`), or null and `error` saying how to
/// get one when the SDK was not built in. Compiled in every build, so that its callers are too.
std::unique_ptr<HapticDevice> MakeOpenHapticsDevice(const std::string& configuration,
                                                    std::string& error);

}  // namespace tubeplan::device
