// The host check (`live --check-host`): known lateness injected through a clock the test
// controls gives exact figures and the verdict the servo's limits imply; the command measures
// this host and reports consistent figures, and refuses options that do not go with it.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/device/host_check.hpp>

#include "../alloc_count.hpp"
#include "../cli/run_tool.hpp"

namespace {

using namespace tubeplan;
using device::HostFitness;
using testing::RunTool;

// Time that moves only on a sleep: to the deadline, plus the lateness `late_ns(n)` of the n-th
// sleep (counted from 0), as a scheduler that wakes the thread that late would.
class LateClock final : public device::Clock {
 public:
  explicit LateClock(std::function<std::int64_t(long)> late_ns) : late_ns_(std::move(late_ns)) {}
  std::int64_t NowNs() const override { return now_ns_; }
  void SleepUntilNs(std::int64_t deadline_ns) override {
    // The measuring thread's allocations at its first and its latest sleep.
    if (sleeps_ == 0) allocations_at_first = testing::g_allocations;
    allocations_at_last = testing::g_allocations;
    now_ns_ = std::max(now_ns_, deadline_ns) + late_ns_(sleeps_++);
  }
  long sleeps() const { return sleeps_; }
  std::int64_t allocations_at_first = -1, allocations_at_last = -1;

 private:
  std::function<std::int64_t(long)> late_ns_;
  std::int64_t now_ns_ = 5'000'000'000;  // an arbitrary origin, as CLOCK_MONOTONIC's
  long sleeps_ = 0;
};

constexpr double kPeriod_s = 1e-3;

// No fact that calls for advice beyond real-time scheduling.
device::HostFacts GoodHost() { return device::HostFacts{}; }

}  // namespace

TEST_CASE("The host check's percentiles are the nearest ranks of the lateness injected",
          "[device][host-check]") {
  // 1000 wakes in 1 s, late by a shuffle of 1..1000 us (7919 is prime to 1000): the sorted
  // lateness is 1..1000 us, so the nearest ranks are exact. 1000 us is a period, not more: no
  // stall.
  LateClock clock([](long n) { return ((n * 7919) % 1000 + 1) * 1000; });
  const device::HostLatency l = device::MeasureHostLatency(clock, 1.0, kPeriod_s, false);
  CHECK(l.wakes == 1000);
  CHECK(clock.sleeps() == 1000);
  CHECK(l.median_us == 500.0);
  CHECK(l.p99_us == 990.0);
  CHECK(l.p999_us == 999.0);
  CHECK(l.max_us == 1000.0);
  CHECK(l.stalls == 0);
  CHECK(l.periods_lost == 0);
  CHECK(l.worst_stalls_per_s == 0);
  CHECK(l.realtime_note.empty());
  // Nothing allocated from the first wake-up to the last.
  CHECK(clock.allocations_at_first >= 0);
  CHECK(clock.allocations_at_last == clock.allocations_at_first);
  // Up to a whole period late is no stall, but little margin: the advice comes.
  const device::HostVerdict v = device::JudgeHost(l, GoodHost(), device::ServoConfig{});
  CHECK(v.fitness == HostFitness::kFine);
  CHECK_THAT(v.summary, Catch::StartsWith("fine, with little margin"));
  REQUIRE(v.advice.size() == 1);
  CHECK_THAT(v.advice[0], Catch::Contains("--no-realtime"));
  // Asked and refused: how to grant the priority the servo asks for.
  device::HostLatency refused = l;
  refused.realtime_asked = true;
  refused.realtime_note = "real-time priority (SCHED_FIFO) not permitted";
  const device::HostVerdict r = device::JudgeHost(refused, GoodHost(), device::ServoConfig{});
  REQUIRE(r.advice.size() == 1);
  CHECK_THAT(r.advice[0], Catch::Contains("rtprio " + std::to_string(device::RealtimePriority()) +
                                          "\" | sudo tee "
                                          "/etc/security/limits.d/"));
  CHECK_THAT(r.advice[0], Catch::Contains("setcap cap_sys_nice+ep"));
  // Asked and granted: nothing to grant.
  refused.realtime_note.clear();
  CHECK(device::JudgeHost(refused, GoodHost(), device::ServoConfig{}).advice.empty());
}

TEST_CASE("The host check counts stalls as the servo does, and their worst second",
          "[device][host-check]") {
  // 3 s of 20 us wake-ups with stalls injected by sleep: 5 of 1.5 ms (1 period lost each) 100
  // sleeps apart from sleep 100, then 12 of 2.5 ms (2 lost each) 10 sleeps apart from sleep
  // 1500. The 12 fall within 0.2 s, the first 5 lie more than a second before them.
  LateClock clock([](long n) -> std::int64_t {
    if (n >= 100 && n <= 500 && n % 100 == 0) return 1'500'000;
    if (n >= 1500 && n <= 1610 && n % 10 == 0) return 2'500'000;
    return 20'000;
  });
  const device::HostLatency l = device::MeasureHostLatency(clock, 3.0, kPeriod_s, false);
  CHECK(l.stalls == 17);
  CHECK(l.periods_lost == 5 * 1 + 12 * 2);
  CHECK(l.wakes == 3000 - l.periods_lost);
  CHECK(l.worst_stalls_per_s == 12);
  CHECK(l.median_us == 20.0);
  // 17 of 2971 wakes are stalls: within the top 1 %, more than the top 0.1 %.
  CHECK(l.p99_us == 20.0);
  CHECK(l.p999_us == 2500.0);
  CHECK(l.max_us == 2500.0);

  const device::HostVerdict v = device::JudgeHost(l, GoodHost(), device::ServoConfig{});
  CHECK(v.fitness == HostFitness::kStalls);
  CHECK_THAT(v.summary, Catch::StartsWith("expect occasional stalls: 17 wake-ups"));
  CHECK_THAT(v.summary, Catch::Contains("at most 12 in a second, the longest 2.5 ms"));
  // The servo's limits decide: the same figures with at most 10 stalls a second are a fault.
  device::ServoConfig strict;
  strict.max_stalls_per_s = 10;
  const device::HostVerdict f = device::JudgeHost(l, GoodHost(), strict);
  CHECK(f.fitness == HostFitness::kFault);
  CHECK_THAT(f.summary, Catch::Contains("12 stalls within one second, more than the 10"));
}

TEST_CASE("A stall longer than the servo survives is a fault; a quiet host is fine",
          "[device][host-check]") {
  // One 150 ms stall at sleep 200: the schedule moves on by 150 periods.
  LateClock stalled([](long n) -> std::int64_t { return n == 200 ? 150'000'000 : 30'000; });
  const device::HostLatency l = device::MeasureHostLatency(stalled, 1.0, kPeriod_s, false);
  CHECK(l.stalls == 1);
  CHECK(l.periods_lost == 150);
  CHECK(l.wakes == 850);
  CHECK(l.max_us == 150000.0);
  CHECK(l.worst_stalls_per_s == 1);
  device::HostFacts facts;
  facts.load_average = 1.8;
  facts.cpus = 2;
  facts.governor = "powersave";
  facts.preempt_rt = false;
  facts.isolated_cpus = false;
  facts.virtual_machine = true;
  const device::HostVerdict v = device::JudgeHost(l, facts, device::ServoConfig{});
  CHECK(v.fitness == HostFitness::kFault);
  CHECK_THAT(v.summary, Catch::Contains("a stall of 150 ms, longer than the 100 ms"));
  // Each fact that calls for it gives its advice, after real-time scheduling.
  REQUIRE(v.advice.size() == 6);
  CHECK_THAT(v.advice[1], Catch::Contains("load average was 1.8 on 2 CPUs"));
  CHECK_THAT(v.advice[2], Catch::Contains("governor (now powersave)"));
  CHECK_THAT(v.advice[3], Catch::Contains("virtual machine"));
  CHECK_THAT(v.advice[4], Catch::Contains("PREEMPT_RT"));
  CHECK_THAT(v.advice[5], Catch::Contains("isolcpus=1"));

  // Wakes 30 us late throughout: fine, and nothing to advise.
  LateClock quiet([](long) -> std::int64_t { return 30'000; });
  const device::HostLatency q = device::MeasureHostLatency(quiet, 0.5, kPeriod_s, false);
  CHECK(q.wakes == 500);
  CHECK(q.max_us == 30.0);
  const device::HostVerdict fine = device::JudgeHost(q, facts, device::ServoConfig{});
  CHECK(fine.fitness == HostFitness::kFine);
  CHECK_THAT(fine.summary, Catch::StartsWith("fine: "));
  CHECK(fine.advice.empty());
}

TEST_CASE("live --check-host measures this host and reports consistent figures",
          "[device][host-check][live]") {
  const testing::Outcome r = RunTool({"live", "--check-host", "--duration", "0.3", "--json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  CHECK(j["tubeplan_host_check"] == 1);
  // 300 deadlines in 0.3 s, fewer by the periods the stalls skipped (a last stall may skip
  // past the end), each stall skipping one at least.
  const long wakes = j["wakes"], lost = j["periods_lost"], stalls = j["stalls"];
  CHECK(wakes <= 300);
  CHECK(wakes + lost >= 300);
  CHECK(stalls <= lost);
  if (stalls == 0) CHECK(wakes == 300);
  const double median_us = j["median_us"], p99_us = j["p99_us"], p999_us = j["p999_us"],
               max_us = j["max_us"];
  CHECK(median_us >= 0.0);
  CHECK(median_us <= p99_us);
  CHECK(p99_us <= p999_us);
  CHECK(p999_us <= max_us);
  CHECK(j["worst_stalls_per_s"].get<long>() <= j["stalls"].get<long>());
  // The verdict follows from the figures by the servo's limits.
  const bool fault = (stalls > 0 && max_us > j["max_stall_ms"].get<double>() * 1e3) ||
                     j["worst_stalls_per_s"].get<long>() > j["max_stalls_per_s"].get<long>();
  CHECK(j["verdict"] == (fault ? "fault" : stalls > 0 ? "stalls" : "fine"));
  CHECK(j["max_stall_ms"] == 100.0);
  CHECK(j["max_stalls_per_s"] == 50);
}

TEST_CASE("live --check-host refuses a plan and a device, and live without it needs a plan",
          "[device][host-check][live]") {
  testing::Outcome r =
      RunTool({"live", testing::SourcePath("plans/groove-insert.yaml"), "--check-host"});
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("plan excludes --check-host"));
  r = RunTool({"live", "--check-host", "--device", "emulator:fast"});
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("--device excludes --check-host"));
  r = RunTool({"live", "--check-host", "--duration", "0"});
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("--duration"));
  r = RunTool({"live", "--check-host", "--duration", "7200"});
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("--check-host --duration 7200: expected at most 3600 s"));
  r = RunTool({"live", "--device", "emulator:fast"});
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("a plan file is needed (or --check-host"));
}
