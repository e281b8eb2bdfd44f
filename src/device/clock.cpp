#include <cerrno>
#include <ctime>

#include <tubeplan/device/clock.hpp>

namespace tubeplan::device {

std::int64_t MonotonicClock::NowNs() const {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void MonotonicClock::SleepUntilNs(std::int64_t deadline_ns) {
  timespec ts{};
  ts.tv_sec = deadline_ns / 1'000'000'000;
  ts.tv_nsec = deadline_ns % 1'000'000'000;
  // A signal interrupts the sleep (EINTR); the deadline is absolute, so sleeping again on it
  // costs nothing. The caller checks its stop flag after waking.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void SteppedClock::SleepUntilNs(std::int64_t deadline_ns) {
  std::int64_t now = now_ns_.load(std::memory_order_acquire);
  while (now < deadline_ns &&
         !now_ns_.compare_exchange_weak(now, deadline_ns, std::memory_order_acq_rel)) {
  }
}

}  // namespace tubeplan::device
