#pragma once
// The servo loop's time: the real monotonic clock with absolute-deadline sleeps, or a stepped
// clock that jumps to each deadline at once, so that tests and fast runs are deterministic and
// never wait on the wall clock.

#include <atomic>
#include <cstdint>

namespace tubeplan::device {

class Clock {
 public:
  virtual ~Clock() = default;
  /// Nanoseconds since an arbitrary fixed origin; never goes back.
  virtual std::int64_t NowNs() const = 0;
  /// Returns at or after `deadline_ns` (at once when it has passed).
  virtual void SleepUntilNs(std::int64_t deadline_ns) = 0;
};

/// CLOCK_MONOTONIC; sleeps with clock_nanosleep(TIMER_ABSTIME), so a late tick does not push the
/// later deadlines back (no drift) and a signal only shortens one sleep.
class MonotonicClock final : public Clock {
 public:
  std::int64_t NowNs() const override;
  void SleepUntilNs(std::int64_t deadline_ns) override;
};

/// Time that moves only when slept on (to the deadline) or advanced by hand (to make a tick
/// late in a test). Thread-safe to read.
class SteppedClock final : public Clock {
 public:
  explicit SteppedClock(std::int64_t start_ns = 0) : now_ns_(start_ns) {}
  std::int64_t NowNs() const override { return now_ns_.load(std::memory_order_acquire); }
  void SleepUntilNs(std::int64_t deadline_ns) override;
  void AdvanceNs(std::int64_t ns) { now_ns_.fetch_add(ns, std::memory_order_acq_rel); }

 private:
  std::atomic<std::int64_t> now_ns_;
};

}  // namespace tubeplan::device
