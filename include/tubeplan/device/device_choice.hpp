#pragma once
// `tubeplan live --device KIND[:ARGS]` as data (docs/live.md, "Devices"): the emulator with its
// trajectory, clock and hand model, a bridge over OpenIGTLink with its address, windows and
// limits, or OpenHaptics with a device name; every argument with a unit checked.

#include <memory>
#include <string>

#include <tubeplan/device/clock.hpp>
#include <tubeplan/device/emulator.hpp>
#include <tubeplan/device/openigtlink.hpp>

namespace tubeplan::device {

/// What `--device emulator[:ARG,...]` asks for.
struct EmulatorArgs {
  std::string trajectory;  ///< empty: the plan's
  bool stepped = false;    ///< `fast`: stepped clock, as fast as the core runs
  HandModel hand;
};

/// What `--device KIND[:ARGS]` asks for.
struct DeviceChoice {
  enum class Kind { kEmulator, kOpenIGTLink, kOpenHaptics } kind = Kind::kEmulator;
  EmulatorArgs emulator;
  OpenIGTLinkOptions igtl;
  std::string openhaptics_name;  ///< empty: the default device
};

/// Parses `text` (`emulator[:FILE.csv][,fast][,mass=M][,stiffness=K][,damping=D]`,
/// `openigtlink://HOST:PORT[,timeout=T][,stale=T][,max_force=F]...`, `openhaptics[:NAME]`) into
/// `choice`; false with `error` naming the argument and what was expected when it is not one.
bool ParseDeviceChoice(const std::string& text, DeviceChoice& choice, std::string& error);

/// The device `choice` names, not yet opened: the emulator following `target` on `clock`, a
/// bridge over OpenIGTLink, or OpenHaptics; null with `error` when it cannot be made (OpenHaptics
/// not built in, or its device not found).
std::unique_ptr<HapticDevice> MakeDevice(const DeviceChoice& choice, Clock& clock,
                                         const trajectories::Trajectory& target,
                                         std::string& error);

}  // namespace tubeplan::device
