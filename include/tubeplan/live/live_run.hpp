#pragma once
// A plan verified live with a haptic device (docs/live.md): a servo thread runs the core at the
// scene's step against the device (device::ServoLoop); the calling thread judges every tick with
// the same judge as `evaluate`, writes the recording and feeds the display, from the servo's
// lock-free hand-offs.
#include <functional>
#include <ostream>
#include <string>

#include <tubeplan/batch/evaluate.hpp>
#include <tubeplan/device/servo.hpp>
#include <tubeplan/plan/judge.hpp>

namespace tubeplan::live {

/// What a live run is asked to do.
struct LiveRequest {
  std::string plan;                 ///< the plan file
  std::string device = "emulator";  ///< the device's text (device::ParseDeviceChoice)
  std::string record;               ///< the recording (trajectory CSV), empty for none
  double duration_s = 0.0;          ///< 0: the emulator's trajectory and a settling time
  bool realtime = true;             ///< SCHED_FIFO for the servo thread (not with a stepped clock)
};

/// Called about 30 times a second with the judge's state and the servo's; `new_line` once a
/// second and whenever a new state counts (what a plain, non-terminal display prints).
using LiveProgress =
    std::function<void(const plan::Judging& judging, const device::ServoStatus& status,
                       double max_force_N, bool new_line)>;

enum class LiveEnd {
  kBadInput,  ///< the plan, the device or an output was refused; nothing ran
  kNoTick,    ///< the servo stopped before its first tick
  kRan,       ///< the run ended; `evaluated` holds its verdicts
};

/// What a live run did.
struct LiveRun {
  LiveEnd end = LiveEnd::kBadInput;
  batch::Evaluated evaluated;  ///< the run's one plan judged, as `evaluate` gives it
  device::ServoStats stats;
  device::ServoConfig config;
  std::string device_name;
  bool stepped = false;       ///< the emulator on a stepped clock
  std::string stopped_early;  ///< "interrupted at t = ..." or "<fault> at t = ...", or empty
  std::string record_error;   ///< why the recording was not written, empty when it was
  std::string recording;      ///< the recording written, empty for none
};

/// Runs the plan live: loads it, opens the device, serves it until the trajectory, the duration
/// or a signal ends the run, then judges what it did. Every problem and note goes to `err` as it
/// happens (diagnostics, refusals, the servo's notes); `progress` may be empty.
LiveRun RunLive(const LiveRequest& request, std::ostream& err, const LiveProgress& progress);

}  // namespace tubeplan::live
