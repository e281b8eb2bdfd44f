#pragma once
// A host check like cyclictest (`tubeplan live --check-host`, docs/live.md "Checking a host"): a
// thread woken every period on absolute deadlines exactly as the servo loop wakes (the same
// Clock, the same SCHED_FIFO request, a stall moving the schedule on by the periods it lost), the
// lateness of each wake-up measured; and what those figures mean for a live run, judged by the
// servo's own stall limits (ServoConfig).

#include <string>
#include <vector>

#include <tubeplan/device/clock.hpp>
#include <tubeplan/device/servo.hpp>

namespace tubeplan::device {

/// How late a thread woke, every period on absolute deadlines, over a measured time.
struct HostLatency {
  double period_s = 0.0;
  double duration_s = 0.0;  ///< clock time the deadlines span
  long wakes = 0;
  /// Lateness: from a deadline to the thread running again [us]; percentiles by nearest rank.
  double median_us = 0.0, p99_us = 0.0, p999_us = 0.0, max_us = 0.0;
  long stalls = 0;              ///< wakes more than a period late (ServoConfig's stalls)
  long periods_lost = 0;        ///< periods the stalls skipped, as the servo skips them
  long worst_stalls_per_s = 0;  ///< most stalls within any one second
  bool realtime_asked = false;  ///< SCHED_FIFO was asked for
  std::string realtime_note;    ///< empty when SCHED_FIFO was set or not asked for
};

/// Wakes a thread of its own every `period_s` of `clock`'s time for `duration_s` (the deadlines
/// start + k period, k >= 1, up to start + duration), asking for SCHED_FIFO first when `realtime`
/// (TryRealtime, as the servo thread does). Nothing is allocated while it measures. Throws
/// std::invalid_argument unless 0 < period_s <= duration_s.
HostLatency MeasureHostLatency(Clock& clock, double duration_s, double period_s, bool realtime);

/// What about the host bears on wake-up latency, from /proc and /sys (unknowns left at the
/// defaults, which give no advice).
struct HostFacts {
  int cpus = 1;
  double load_average = 0.0;  ///< 1-minute load average
  /// "performance" when every CPU's cpufreq governor is, else the first other one seen; empty
  /// without cpufreq (a virtual machine has none).
  std::string governor;
  bool preempt_rt = true;        ///< a PREEMPT_RT kernel (/sys/kernel/realtime, uname)
  bool isolated_cpus = true;     ///< CPUs kept from the scheduler (isolcpus=)
  bool virtual_machine = false;  ///< the CPU reports a hypervisor
};
HostFacts ReadHostFacts();

enum class HostFitness : unsigned char {
  kFine,    ///< no stall: a live run should see none (with little margin past half a period)
  kStalls,  ///< stalls a live run survives (zero force on the tick, ramped back after)
  kFault,   ///< a stall too long or too many in a second: a live run would stop on a fault
};
/// "fine", "stalls" or "fault".
const char* ToString(HostFitness fitness);

/// What a live run at this period may expect on this host, and what would help.
struct HostVerdict {
  HostFitness fitness = HostFitness::kFine;
  std::string summary;  ///< one sentence, starting with what to expect
  /// What would help, only what applies; empty when no wake-up was half a period late.
  std::vector<std::string> advice;
};

/// Judges `latency` by `limits`' stall limits (max_stall_s, max_stalls_per_s); `facts` choose
/// the advice.
HostVerdict JudgeHost(const HostLatency& latency, const HostFacts& facts,
                      const ServoConfig& limits);

}  // namespace tubeplan::device
