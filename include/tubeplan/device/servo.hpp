#pragma once
// The servo loop: the one core (core::Core::Step) driven by a haptic device at the scene's step
// (1 kHz), each tick woken at an absolute deadline. Per tick: read the device, step the core with
// the hand's pose, pass the wrench through the WrenchLimiter, send it, measure the tick, and hand
// what happened to the other threads without a lock or an allocation (handoff.hpp).
//
// Safety (docs/live.md, "Safety"): the wrench sent is zero from the tick on which any of these is
// seen, and stays zero: a non-finite number anywhere (device reading, core output), a streak of
// missed deadlines, stale device data, a device error, SIGINT or SIGTERM, a stop request, and the
// end of the loop. The loop ends after such a fault has been sent, and the device is disabled.

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <tubeplan/core/core.hpp>
#include <tubeplan/device/clock.hpp>
#include <tubeplan/device/device.hpp>
#include <tubeplan/device/handoff.hpp>
#include <tubeplan/device/wrench_limiter.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::device {

/// Why the loop ended (or kNone while it runs).
enum class StopReason : unsigned char {
  kNone,
  kCompleted,        ///< ran its tick count
  kStopRequested,    ///< RequestStop() (the session's end, from another thread)
  kSignal,           ///< SIGINT or SIGTERM
  kNonFinite,        ///< NaN or Inf in the device's reading or the core's output
  kMissedDeadlines,  ///< stalls too long or too frequent (ServoConfig), or the limiter's streak
  kStaleData,        ///< the device's reading stopped changing
  kDeviceError,      ///< the device failed a read
};
const char* ToString(StopReason reason);
/// True for the reasons that are faults (not a normal end of a session).
bool IsFault(StopReason reason);

struct ServoConfig {
  /// Ticks to run; 0: until stopped.
  long max_ticks = 0;
  /// This many ticks in a row with the device's sequence unchanged is stale data. 1: a reading
  /// that did not change since the last tick zeroes the force on that tick (the emulator and an
  /// OpenHaptics device update at least at the servo's rate; a network bridge at a lower rate
  /// needs more).
  int max_stale_ticks = 1;
  /// Try SCHED_FIFO for the servo thread (a note says when it is not permitted).
  bool realtime = true;
  /// A tick that wakes more than a period late is a stall, which the run survives: its force is
  /// zero, the schedule moves on by the periods it lost (the core still steps every tick: the
  /// run's time falls behind the clock's by the stalls, and a replay of the recording steps the
  /// core the same) and the force ramps back in at the limiter's rates (zero to the maximum in
  /// 10 ms). A persistent fault ends the run: one stall longer than this, or more than
  /// `max_stalls_per_s` stalls within a second.
  double max_stall_s = 0.1;
  /// A stall every 20 ms for a second: the force then spends about half its time ramping back
  /// and renders the contact no more. Bursts below it (a virtual machine's host, a build) are
  /// ridden out. At most 63; 0: no limit on the rate.
  int max_stalls_per_s = 50;
};

/// What one tick did, handed to the judge and the recorder (every tick, in order).
struct TickRecord {
  long tick = 0;
  trajectories::HandSample hand;  ///< the pose given to the core, as the recording stores it
  core::StepOutput out;           ///< valid when stepped
  bool stepped = false;           ///< false on a tick that faulted before stepping the core
  Eigen::Vector3d force_sent_N = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_sent_Nm = Eigen::Vector3d::Zero();
  std::uint32_t buttons = 0;
  bool stalled = false;          ///< this tick woke more than a period late: its force was zero
  float stall_ms = 0.0f;         ///< how late it woke when it stalled [ms], 0 otherwise
  std::int32_t response_ns = 0;  ///< from the tick's deadline to its wrench sent
};

/// The latest state, for the display (seqlock).
struct ServoStatus {
  long ticks = 0;
  long overruns = 0;
  double t_s = 0.0;
  double force_N = 0.0;      ///< |force| sent
  double request_N = 0.0;    ///< |force| the core asked for
  double worst_us = 0.0;     ///< worst response time so far
  double rate_hz = 0.0;      ///< ticks per second of wall time since the start
  core::FormationKey key{};  ///< CF of the last tick
  StopReason stop = StopReason::kNone;
};

/// Statistics of the response time (deadline to wrench sent) over a run.
struct ServoStats {
  long ticks = 0;
  long overruns = 0;  ///< ticks whose wrench went out after the next tick's deadline
  long late_wakeups = 0;
  long stalls = 0;      ///< late wake-ups survived (ServoConfig::max_stall_s)
  long ticks_lost = 0;  ///< ticks the stalls skipped
  double longest_stall_ms = 0.0;
  double first_stall_s = -1.0;  ///< run time of the first stall, -1 for none
  double median_us = 0.0, p999_us = 0.0, max_us = 0.0;
  double max_latency_us = 0.0;  ///< worst wake-up latency (deadline to running)
  double max_jitter_us = 0.0;   ///< worst |period - T| between two wake-ups
  double rate_hz = 0.0;         ///< ticks per second of clock time
  std::uint64_t dropped = 0;    ///< tick records the consumer did not take in time
  StopReason stop = StopReason::kNone;
  std::string realtime_note;  ///< empty when SCHED_FIFO was set
};

/// Installs SIGINT and SIGTERM handlers that only set a flag the servo loop polls (restored on
/// destruction).
class ScopedStopSignals {
 public:
  ScopedStopSignals();
  ~ScopedStopSignals();
  ScopedStopSignals(const ScopedStopSignals&) = delete;
  ScopedStopSignals& operator=(const ScopedStopSignals&) = delete;
  static int received();  ///< the signal number seen, 0 if none
  static void Clear();
};

/// The SCHED_FIFO priority the servo thread asks for (an rtprio limit must allow at least this).
int RealtimePriority();
/// Asks SCHED_FIFO at RealtimePriority() for the calling thread: empty when set, else a note of
/// why not and what would permit it.
std::string TryRealtime();

/// The pose a recording (io::FormatTrajectoryCsvRow, 1 nm and 1e-9) gives back on reading,
/// including the reader's normalisation of the quaternion. The servo feeds the core this pose,
/// so a replay of the recording steps the core with the same bits and reaches the same verdicts.
trajectories::HandSample AsRecorded(double t_s, const Eigen::Isometry3d& X_W_hand);

class ServoLoop {
 public:
  /// `core` must have been Reset by the caller or is reset here to the device's first pose.
  /// `ring` and `status` may be null.
  ServoLoop(core::Core& core, HapticDevice& device, Clock& clock, const SafetyLimits& limits,
            ServoConfig config, SpscRing<TickRecord>* ring, Seqlock<ServoStatus>* status);

  /// Runs on the calling thread until its tick count, a stop or a fault; sends zero and disables
  /// the device before returning. Allocates nothing per tick.
  ServoStats Run();
  /// From any thread: the loop sends zero on its next tick and ends.
  void RequestStop() { stop_requested_.store(true, std::memory_order_release); }

  /// Test hook, called at the start of every tick (after the wake-up) with the tick index: where
  /// a test injects faults.
  std::function<void(long tick)> on_tick;

 private:
  core::Core& core_;
  HapticDevice& device_;
  Clock& clock_;
  WrenchLimiter limiter_;
  ServoConfig config_;
  SpscRing<TickRecord>* ring_;
  Seqlock<ServoStatus>* status_;
  std::atomic<bool> stop_requested_{false};
  std::vector<std::uint32_t> histogram_;  // response time, 1 us bins (allocated once)
};

}  // namespace tubeplan::device
