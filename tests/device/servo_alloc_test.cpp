// The servo's tick allocates nothing (docs/live.md, "The servo loop"): the whole per-tick path,
// from the device's reading through the core, the limiter, the send and both hand-offs, counted
// with every operator new of the test program replaced (tests/alloc_count.cpp).
#include <algorithm>

#include <catch2/catch.hpp>

#include <tubeplan/device/emulator.hpp>
#include <tubeplan/device/servo.hpp>
#include <tubeplan/io/plan_file.hpp>

#include "../alloc_count.hpp"

namespace {

using namespace tubeplan;
using tubeplan::testing::g_allocations;

std::string SourcePath(const std::string& relative) {
  return std::string(TUBEPLAN_SOURCE_DIR) + "/" + relative;
}

}  // namespace

TEST_CASE("A servo tick allocates nothing", "[device][alloc]") {
  const io::PlanLoadResult loaded = io::LoadPlanFile(SourcePath("plans/groove-insert.yaml"));
  REQUIRE(loaded.plan);
  device::SteppedClock clock;
  device::EmulatorDevice dev(clock, *loaded.trajectory);
  core::Core core(*loaded.scene);
  REQUIRE(dev.Open().empty());
  // The whole insertion (5.5 s): free motion, the end's contact, the side landing and the tube
  // lying in the groove, so every branch of the core's tick is in the count.
  constexpr long kTicks = 6000;
  device::SpscRing<device::TickRecord> ring(kTicks + 16);
  device::Seqlock<device::ServoStatus> status;
  device::ServoConfig config;
  config.realtime = false;  // asking for SCHED_FIFO builds a note (set-up, not the tick)
  config.max_ticks = kTicks;
  device::ServoLoop servo(core, dev, clock, device::LimitsFor(dev.spec(), loaded.scene->device),
                          config, &ring, &status);
  // The count from the start of tick 1 (tick 0 resets the core: set-up) to the start of the
  // last tick: every tick in between, whole, on this thread (the servo runs on the caller's).
  std::int64_t at_first = -1, at_last = -1;
  servo.on_tick = [&](long k) {
    if (k == 1) at_first = g_allocations;
    if (k == kTicks - 1) at_last = g_allocations;
  };
  const device::ServoStats stats = servo.Run();
  REQUIRE(stats.stop == device::StopReason::kCompleted);
  REQUIRE(at_first >= 0);
  REQUIRE(at_last >= 0);
  CHECK(at_last - at_first == 0);
  // The ticks did load the tube (else the count above saw only free motion).
  double largest_N = 0.0;
  for (device::TickRecord r; ring.TryPop(r);)
    largest_N = std::max(largest_N, r.force_sent_N.norm());
  CHECK(largest_N > 0.02);  // free motion sends none; the pressed rim about 0.03 N
  // The counter does count on this thread: the cold path (the CF as text) allocates.
  const std::int64_t before = g_allocations;
  CHECK(!core.FormationText().empty());
  CHECK(g_allocations > before);
}
