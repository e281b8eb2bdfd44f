#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <sys/utsname.h>
#include <thread>
#include <unistd.h>

#include <tubeplan/device/host_check.hpp>

namespace tubeplan::device {
namespace {

// Nearest rank of `per_mille` in `sorted` (integer arithmetic: no rounding at the ranks).
std::int64_t NearestRank(const std::vector<std::int64_t>& sorted, long count, long per_mille) {
  const long rank = std::max(1L, (count * per_mille + 999) / 1000);
  return sorted[std::size_t(rank - 1)];
}

// The first line of a small file, or empty.
std::string FirstLine(const char* path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

bool FileContains(const char* path, const std::string& word) {
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);)
    if (line.find(word) != std::string::npos) return true;
  return false;
}

// `value` with `digits` decimals, or as briefly as it reads back (digits < 0).
std::string Decimal(double value, int digits = -1) {
  std::ostringstream text;
  if (digits >= 0) text << std::fixed << std::setprecision(digits);
  text << value;
  return text.str();
}

// A duration in ms at a precision that suits it: 0.35 ms, 5.3 ms, 150 ms.
std::string Ms(double ms) { return Decimal(ms, ms < 1.0 ? 2 : ms < 10.0 ? 1 : 0) + " ms"; }

// What would help, given what the host has; most effective first.
std::vector<std::string> Advice(const HostLatency& l, const HostFacts& facts) {
  std::vector<std::string> advice;
  if (!l.realtime_asked) {
    advice.push_back(
        "real-time scheduling: leave out --no-realtime, so that the thread asks for SCHED_FIFO");
  } else if (!l.realtime_note.empty()) {
    const std::string priority = std::to_string(RealtimePriority());
    advice.push_back(
        "real-time scheduling, which was not permitted: grant an rtprio limit of at least " +
        priority + " (`echo \"$USER - rtprio " + priority +
        "\" | sudo tee /etc/security/limits.d/99-tubeplan.conf`, then log in again) or the "
        "capability to the binary (`sudo setcap cap_sys_nice+ep \"$(command -v tubeplan)\"`)");
  }
  if (facts.load_average >= 0.5)
    advice.push_back("an idle machine: the load average was " + Decimal(facts.load_average, 1) +
                     " on " + std::to_string(facts.cpus) + (facts.cpus == 1 ? " CPU" : " CPUs") +
                     "; builds and other work delay even a real-time thread's wake-ups");
  if (!facts.governor.empty() && facts.governor != "performance")
    advice.push_back("the performance CPU governor (now " + facts.governor +
                     "): `sudo cpupower frequency-set -g performance`; a CPU waking from a "
                     "low-power state wakes the thread late");
  if (facts.virtual_machine)
    advice.push_back(
        "a physical machine: this is a virtual machine, whose host can stall its virtual CPUs "
        "for milliseconds whatever is set inside it");
  if (!facts.preempt_rt)
    advice.push_back(
        "a PREEMPT_RT kernel (Debian: linux-image-rt-amd64), whose scheduler preempts the "
        "kernel's own work for a real-time thread");
  if (!facts.isolated_cpus && facts.cpus >= 2)
    advice.push_back("a CPU of its own: `isolcpus=" + std::to_string(facts.cpus - 1) +
                     "` on the kernel command line, and `taskset -c " +
                     std::to_string(facts.cpus - 1) + " tubeplan live ...`");
  return advice;
}

}  // namespace

HostLatency MeasureHostLatency(Clock& clock, double duration_s, double period_s, bool realtime) {
  if (!(period_s > 0.0) || !(duration_s >= period_s))
    throw std::invalid_argument("MeasureHostLatency: expected 0 < period_s <= duration_s, got " +
                                std::to_string(period_s) + " s and " + std::to_string(duration_s) +
                                " s");
  const auto T_ns = static_cast<std::int64_t>(std::llround(period_s * 1e9));
  const auto duration_ns = static_cast<std::int64_t>(std::llround(duration_s * 1e9));
  // Every wake's lateness, and the wake times of the stalls: at most one per deadline.
  const auto capacity = static_cast<std::size_t>(duration_ns / T_ns);
  std::vector<std::int64_t> lateness_ns(capacity), stall_wake_ns(capacity);

  HostLatency l;
  l.period_s = period_s;
  l.duration_s = duration_s;
  l.realtime_asked = realtime;
  // A thread of its own, as the servo's: its scheduling is not the caller's.
  std::thread thread([&] {
    if (realtime) l.realtime_note = TryRealtime();
    const std::int64_t start_ns = clock.NowNs();
    const std::int64_t end_ns = start_ns + duration_ns;
    // Wake k is due at schedule_ns + k T; a stall moves the schedule on by the periods it lost.
    std::int64_t schedule_ns = start_ns;
    for (std::int64_t k = 1; schedule_ns + k * T_ns <= end_ns; ++k) {
      const std::int64_t deadline_ns = schedule_ns + k * T_ns;
      clock.SleepUntilNs(deadline_ns);
      const std::int64_t wake_ns = clock.NowNs();
      const std::int64_t late_ns = wake_ns - deadline_ns;
      lateness_ns[std::size_t(l.wakes++)] = late_ns;
      if (late_ns > T_ns) {
        const std::int64_t lost = late_ns / T_ns;
        schedule_ns += lost * T_ns;
        l.periods_lost += long(lost);
        stall_wake_ns[std::size_t(l.stalls++)] = wake_ns;
      }
    }
  });
  thread.join();

  // The percentiles of the lateness, exact.
  std::sort(lateness_ns.begin(), lateness_ns.begin() + l.wakes);
  if (l.wakes > 0) {
    // Divided, not multiplied by 1e-3: the nearest double to the decimal number of us.
    l.median_us = double(NearestRank(lateness_ns, l.wakes, 500)) / 1000.0;
    l.p99_us = double(NearestRank(lateness_ns, l.wakes, 990)) / 1000.0;
    l.p999_us = double(NearestRank(lateness_ns, l.wakes, 999)) / 1000.0;
    l.max_us = double(lateness_ns[std::size_t(l.wakes - 1)]) / 1000.0;
  }
  // The most stalls within one second, as the servo counts them (less than 1 s apart).
  for (long first = 0, last = 0; last < l.stalls; ++last) {
    while (stall_wake_ns[std::size_t(last)] - stall_wake_ns[std::size_t(first)] >= 1'000'000'000)
      ++first;
    l.worst_stalls_per_s = std::max(l.worst_stalls_per_s, last - first + 1);
  }
  return l;
}

HostFacts ReadHostFacts() {
  HostFacts facts;
  facts.cpus = std::max(1, int(sysconf(_SC_NPROCESSORS_ONLN)));
  double load[1] = {0.0};
  if (getloadavg(load, 1) == 1) facts.load_average = load[0];
  // cpufreq's governor of each CPU: "performance" only when all are.
  for (int cpu = 0; cpu < facts.cpus; ++cpu) {
    const std::string path =
        "/sys/devices/system/cpu/cpu" + std::to_string(cpu) + "/cpufreq/scaling_governor";
    const std::string governor = FirstLine(path.c_str());
    if (governor.empty()) continue;
    if (facts.governor.empty() || facts.governor == "performance") facts.governor = governor;
  }
  utsname name{};
  facts.preempt_rt =
      FirstLine("/sys/kernel/realtime") == "1" ||
      (uname(&name) == 0 && std::string(name.version).find("PREEMPT_RT") != std::string::npos);
  facts.isolated_cpus = !FirstLine("/sys/devices/system/cpu/isolated").empty() ||
                        FileContains("/proc/cmdline", "isolcpus=");
  facts.virtual_machine = FileContains("/proc/cpuinfo", " hypervisor");
  return facts;
}

const char* ToString(HostFitness fitness) {
  switch (fitness) {
    case HostFitness::kFine:
      return "fine";
    case HostFitness::kStalls:
      return "stalls";
    case HostFitness::kFault:
      return "fault";
  }
  return "unknown";
}

HostVerdict JudgeHost(const HostLatency& l, const HostFacts& facts, const ServoConfig& limits) {
  HostVerdict v;
  const double period_ms = l.period_s * 1e3;
  const std::string in = " in " + Decimal(l.duration_s) + " s";
  const std::string rate = "a live run at " + Decimal(1.0 / l.period_s) + " Hz";
  // A fault, as the servo judges one: a stall too long, or too many within a second.
  std::string fault;
  if (l.stalls > 0 && l.max_us * 1e-6 > limits.max_stall_s)
    fault = "a stall of " + Ms(l.max_us * 1e-3) + ", longer than the " +
            Ms(limits.max_stall_s * 1e3) + " a run survives";
  if (limits.max_stalls_per_s > 0 && l.worst_stalls_per_s > limits.max_stalls_per_s)
    fault += (fault.empty() ? "" : "; ") + std::to_string(l.worst_stalls_per_s) +
             " stalls within one second, more than the " + std::to_string(limits.max_stalls_per_s) +
             " a run survives";
  if (!fault.empty()) {
    v.fitness = HostFitness::kFault;
    v.summary = rate + " would stop on a fault: " + fault;
  } else if (l.stalls > 0) {
    v.fitness = HostFitness::kStalls;
    v.summary = "expect occasional stalls: " + std::to_string(l.stalls) +
                (l.stalls == 1 ? " wake-up" : " wake-ups") + " more than a period (" +
                Ms(period_ms) + ") late" + in + ", at most " +
                std::to_string(l.worst_stalls_per_s) + " in a second, the longest " +
                Ms(l.max_us * 1e-3) +
                "; on each the force drops to zero and ramps back, and the run goes on";
  } else if (l.max_us * 1e-3 > 0.5 * period_ms) {
    v.summary = "fine, with little margin: no stall" + in + ", but the latest wake-up was " +
                Ms(l.max_us * 1e-3) + " late of a " + Ms(period_ms) + " period";
  } else {
    v.summary = "fine: no wake-up more than half a period (" + Ms(0.5 * period_ms) + ") late" + in +
                "; " + rate + " should see no stalls";
  }
  if (l.max_us * 1e-3 > 0.5 * period_ms) v.advice = Advice(l, facts);
  return v;
}

}  // namespace tubeplan::device
