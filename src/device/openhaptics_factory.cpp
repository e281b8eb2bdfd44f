// Whether `live` can offer the openhaptics device: the one place that knows if the SDK was
// built in, so that the command line compiles the same in every build.
#include <tubeplan/device/openhaptics.hpp>

namespace tubeplan::device {

bool OpenHapticsBuiltIn() {
#ifdef TUBEPLAN_WITH_OPENHAPTICS
  return true;
#else
  return false;
#endif
}

std::unique_ptr<HapticDevice> MakeOpenHapticsDevice(const std::string& configuration,
                                                    std::string& error) {
#ifdef TUBEPLAN_WITH_OPENHAPTICS
  error.clear();
  return std::make_unique<OpenHapticsDevice>(configuration);
#else
  (void)configuration;
  error =
      "this tubeplan was built without the OpenHaptics SDK; rebuild with "
      "-DTUBEPLAN_OPENHAPTICS=ON (docs/live.md)";
  return nullptr;
#endif
}

}  // namespace tubeplan::device
