// The live path: the device emulator's hand against an analytic solution, the lock-free
// hand-offs under two threads, the servo loop's safety (each fault injected into the emulator,
// the force sent checked on that tick), and a live run of a shipped plan whose verdicts equal
// the batch replay of its recording. Everything runs on a stepped clock: no wall time is assumed.
#include <cmath>
#include <csignal>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>
#include <thread>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/device/emulator.hpp>
#include <tubeplan/device/handoff.hpp>
#include <tubeplan/device/servo.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>

#include "cli/app.hpp"
#include "io/text_file.hpp"
#include "live_replay.hpp"

namespace {

using namespace tubeplan;
using device::StopReason;

using testing::InsertPlan;
using testing::SourcePath;

trajectories::Trajectory StillTarget(const Eigen::Vector3d& p_W_m, double duration_s) {
  trajectories::Trajectory t;
  t.samples.resize(2);
  t.samples[0].p_WH_m = t.samples[1].p_WH_m = p_W_m;
  t.samples[1].t_s = duration_s;
  return t;
}

// A servo session on a stepped clock over the groove-insert plan, with every tick's record kept.
struct Session {
  device::SteppedClock clock;
  device::EmulatorDevice dev{clock, *InsertPlan().trajectory};
  core::Core core{*InsertPlan().scene};
  device::SpscRing<device::TickRecord> ring{8192};
  device::ServoConfig config;
  std::vector<device::TickRecord> records;
  device::ServoStats stats;

  Session() {
    config.realtime = false;
    config.max_ticks = 6000;
    REQUIRE(dev.Open().empty());
  }
  void Run(const std::function<void(long, device::ServoLoop&)>& hook) {
    device::ServoLoop servo(core, dev, clock,
                            device::LimitsFor(dev.spec(), InsertPlan().scene->device), config,
                            &ring, nullptr);
    servo.on_tick = [&](long k) { hook(k, servo); };
    stats = servo.Run();
    for (device::TickRecord r; ring.TryPop(r);) records.push_back(r);
  }
};

// Where the force sent first exceeds this, a fault is injected: the test then sees the force go
// from clearly non-zero to exactly zero. Free motion in the groove-insert plan sends no force;
// 0.015 N is reached once the rim presses on the floor (the emulated run's peak is 0.031 N).
constexpr double kLoaded_N = 0.015;

}  // namespace

TEST_CASE("The emulated hand settles where its arm balances a constant device force", "[device]") {
  // m x'' = K (x* - x) - (D + b) x' + F with a still target: at rest x - x* = F / K exactly.
  device::SteppedClock clock;
  device::HandModel hand;
  device::EmulatorDevice dev(clock, StillTarget(Eigen::Vector3d(0.01, 0.02, 0.03), 10.0), hand);
  REQUIRE(dev.Open().empty());
  device::WrenchLimiter limiter(device::LimitsFor(dev.spec(), scene::Device{}), 1e-3);
  const Eigen::Vector3d force_N(3.0, 0.0, -1.0);
  device::DeviceSample s;
  // 3 s: overdamped (D + b = 24 N s/m > 2 sqrt(K m) = 19), its slow root s = -15.5 /s leaves
  // exp(-46) of the 10 mm start, nothing.
  for (int k = 0; k < 3000; ++k) {
    clock.AdvanceNs(1'000'000);
    dev.Send(limiter.Command(force_N, Eigen::Vector3d::Zero()));
    REQUIRE(dev.Read(s));
  }
  const Eigen::Vector3d offset = s.X_W_hand.translation() - Eigen::Vector3d(0.01, 0.02, 0.03);
  // 1e-9 m: the decayed transient and the rounding of 3000 x 10 sub-steps are far below it.
  CHECK((offset - force_N / hand.stiffness_N_per_m).norm() < 1e-9);
  CHECK(s.v_W_m_per_s.norm() < 1e-9);
  CHECK(s.sequence == 3000);
  dev.Close();
  CHECK(dev.force_sent_N().isZero(0.0));  // closing sends zero
}

TEST_CASE("The seqlock never hands out a torn value and the ring keeps every value in order",
          "[device][handoff]") {
  struct Payload {
    std::uint64_t a, b, c, d;  // all equal in every value written
  };
  device::Seqlock<Payload> latest;
  device::SpscRing<std::uint64_t> ring(64);
  constexpr std::uint64_t kCount = 200000;
  std::thread producer([&] {
    for (std::uint64_t k = 1; k <= kCount; ++k) {
      latest.Store({k, k, k, k});
      while (!ring.TryPush(k)) std::this_thread::yield();  // the test waits; the servo drops
    }
  });
  std::uint64_t expected = 1, torn = 0, last_seen = 0, backwards = 0;
  while (expected <= kCount) {
    if (const std::optional<Payload> p = latest.Load()) {
      torn += !(p->a == p->b && p->b == p->c && p->c == p->d);
      backwards += p->a < last_seen;
      last_seen = p->a;
    }
    std::uint64_t v = 0;
    if (ring.TryPop(v)) {
      REQUIRE(v == expected);
      ++expected;
    }
  }
  producer.join();
  CHECK(torn == 0);
  CHECK(backwards == 0);
  CHECK(latest.Load()->a == kCount);
  CHECK(ring.dropped() > 0);  // the producer's retries on a full ring, each counted
  // A full ring drops (and counts) instead of waiting.
  device::SpscRing<int> small(4);
  for (int i = 0; i < 6; ++i) small.TryPush(i);
  CHECK(small.dropped() == 2);
}

TEST_CASE("A recorded pose reads back to the same bits", "[device]") {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  std::string csv = io::TrajectoryCsvHeader("test", 1000.0);
  std::vector<trajectories::HandSample> written;
  for (int k = 0; k < 500; ++k) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = Eigen::Quaterniond(Eigen::Vector4d(u(random), u(random), u(random), u(random)))
                     .normalized()
                     .toRotationMatrix();
    X.translation() = Eigen::Vector3d(u(random), u(random), u(random));
    written.push_back(device::AsRecorded(double(k) * 1e-3, X));
    io::AppendTrajectoryCsvRow(csv, written.back());
  }
  const io::TrajectoryLoadResult read = io::LoadTrajectoryText(csv, "recording.csv");
  INFO(read.diagnostics.FormatAll());
  REQUIRE(read.trajectory);
  const std::vector<trajectories::HandSample> grid = trajectories::Resample(*read.trajectory, 1e-3);
  REQUIRE(grid.size() == written.size());
  for (std::size_t k = 0; k < written.size(); ++k) {
    // Exactly: the replay must step the core with the bits the live run used.
    CHECK(grid[k].t_s == written[k].t_s);
    CHECK(grid[k].p_WH_m == written[k].p_WH_m);
    CHECK(grid[k].q_WH.coeffs() == written[k].q_WH.normalized().coeffs());
  }
}

TEST_CASE("Each safety fault zeroes the force on the tick it is seen", "[device][safety]") {
  struct Case {
    const char* name;
    StopReason reason;
    int ticks_to_zero;  // after the injection
  };
  const Case cases[] = {{"NaN pose", StopReason::kNonFinite, 0},
                        {"stale data", StopReason::kStaleData, 0},
                        {"device error", StopReason::kDeviceError, 0},
                        {"SIGTERM", StopReason::kSignal, 0},
                        {"SIGINT", StopReason::kSignal, 0},
                        {"stop request", StopReason::kStopRequested, 0},
                        // A stall of 200 ms, beyond the 100 ms a run survives.
                        {"missed deadlines", StopReason::kMissedDeadlines, 0}};
  for (const Case& c : cases) {
    DYNAMIC_SECTION(c.name) {
      device::ScopedStopSignals signals;
      Session s;
      long injected = -1;
      s.Run([&](long k, device::ServoLoop& servo) {
        if (injected >= 0 || s.dev.force_sent_N().norm() < kLoaded_N) return;
        injected = k;
        const std::string name = c.name;
        if (name == "NaN pose") s.dev.InjectNaN(true);
        if (name == "stale data") s.dev.Freeze(true);
        if (name == "device error") s.dev.FailReads(true);
        if (name == "SIGTERM") std::raise(SIGTERM);
        if (name == "SIGINT") std::raise(SIGINT);
        if (name == "stop request") servo.RequestStop();
        if (name == "missed deadlines") s.clock.AdvanceNs(200'000'000);
      });
      REQUIRE(injected > 0);
      CHECK(s.stats.stop == c.reason);
      const long zero_tick = injected + c.ticks_to_zero;
      REQUIRE(s.records.back().tick == zero_tick);  // the loop ended on that tick
      CHECK(s.records.back().force_sent_N.isZero(0.0));
      CHECK(s.records.back().torque_sent_Nm.isZero(0.0));
      // The tick before sent a real force (else the check above shows nothing).
      CHECK(s.records[s.records.size() - 2].force_sent_N.norm() >= kLoaded_N * 0.9);
      CHECK(s.dev.force_sent_N().isZero(0.0));  // and zero after the loop
    }
  }
  device::ScopedStopSignals::Clear();
}

TEST_CASE("A stall is survived: zero force on its tick, the force back after, the run goes on",
          "[device][safety]") {
  // One tick 5 ms late once the rim presses: the loop moves its schedule on by the 5 periods it
  // lost (still stepping every tick), sends zero on the late tick and the force again after it
  // (ramped at the limiter's rate: these forces are far below one tick's step of 0.85 N), and
  // runs to its end.
  Session s;
  long injected = -1;
  s.Run([&](long k, device::ServoLoop&) {
    if (injected >= 0 || s.dev.force_sent_N().norm() < kLoaded_N) return;
    injected = k;
    s.clock.AdvanceNs(5'000'000);
  });
  REQUIRE(injected > 0);
  CHECK(s.stats.stop == StopReason::kCompleted);
  CHECK(s.stats.stalls == 1);
  CHECK(s.stats.ticks_lost == 5);
  CHECK(s.stats.longest_stall_ms == Approx(5.0));
  std::size_t at = 0;
  while (at < s.records.size() && !s.records[at].stalled) ++at;
  REQUIRE(at + 1 < s.records.size());
  CHECK(s.records[at].tick == injected);
  CHECK(s.records[at - 1].tick == injected - 1);
  CHECK(s.records[at].stall_ms == Approx(s.stats.longest_stall_ms));
  CHECK(s.records[at - 1].stall_ms == 0.0f);
  CHECK(s.records[at - 1].force_sent_N.norm() >= kLoaded_N * 0.9);
  CHECK(s.records[at].force_sent_N.isZero(0.0));
  CHECK(s.records[at].stepped);
  // The tick after sends what the core asks again.
  CHECK((s.records[at + 1].force_sent_N - s.records[at + 1].out.force_W_N).norm() < 1e-12);
  CHECK(s.records[at + 1].force_sent_N.norm() > 0.0);
  CHECK(s.records.back().tick == s.config.max_ticks - 1);
}

TEST_CASE("Stalls more often than the run survives end it with zero force", "[device][safety]") {
  // A 2 ms stall every 10 ticks from the first loaded tick: 100 a second, beyond the 20 a run
  // survives; the 21st within a second ends it, on that tick, with zero force.
  Session s;
  long first = -1;
  s.Run([&](long k, device::ServoLoop&) {
    if (first < 0 && s.dev.force_sent_N().norm() >= kLoaded_N) first = k;
    if (first >= 0 && (k - first) % 10 == 0) s.clock.AdvanceNs(2'000'000);
  });
  REQUIRE(first > 0);
  CHECK(s.stats.stop == StopReason::kMissedDeadlines);
  CHECK(s.stats.stalls == s.config.max_stalls_per_s + 1);
  CHECK(s.records.back().stalled);
  CHECK(s.records.back().force_sent_N.isZero(0.0));
  CHECK(s.dev.force_sent_N().isZero(0.0));
}

TEST_CASE("The end of a session sends zero, and every wrench is within the device's limits",
          "[device][safety]") {
  Session s;
  s.config.max_ticks = 3000;
  double largest_N = 0.0, largest_step_N = 0.0;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  s.Run([](long, device::ServoLoop&) {});
  CHECK(s.stats.stop == StopReason::kCompleted);
  REQUIRE(s.records.size() == 3000);
  for (const device::TickRecord& r : s.records) {
    largest_N = std::max(largest_N, r.force_sent_N.norm());
    largest_step_N = std::max(largest_step_N, (r.force_sent_N - previous).norm());
    previous = r.force_sent_N;
  }
  CHECK(s.records.back().force_sent_N.norm() > 0.0);  // loaded at the end of the run ...
  CHECK(s.dev.force_sent_N().isZero(0.0));            // ... and zero once it ended
  CHECK(largest_N <= 8.5);
  CHECK(largest_step_N <= 0.85 * (1 + 1e-12));  // the limiter's ramp, 850 N/s at 1 ms
  // The stepped clock never overruns: each tick starts exactly at its deadline.
  CHECK(s.stats.overruns == 0);
  CHECK(s.stats.max_latency_us == 0.0);
}

TEST_CASE("A live run of a shipped plan gets the verdicts of the batch replay of its recording",
          "[device][live]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("tubeplan-live-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path recording = dir / "insert.csv";
  std::ostringstream out, err;
  const std::vector<std::string> live = {"live",     SourcePath("plans/groove-insert.yaml"),
                                         "--device", "emulator:fast",
                                         "--record", recording.string(),
                                         "--json"};
  const int code = cli::Run(live, out, err);
  INFO(err.str());
  REQUIRE(code == 0);  // the emulated hand inserts the tube as planned
  const nlohmann::json live_report = nlohmann::json::parse(out.str());
  REQUIRE(fs::exists(recording));
  CHECK(!fs::exists(recording.string() + ".tmp." + std::to_string(::getpid())));
  CHECK(live_report["servo"]["stop"] == "completed");
  CHECK(live_report["servo"]["ticks"] == 6001);  // 5.5 s of trajectory and 0.5 s, both ends

  // The plan with the recording for its trajectory, judged by `evaluate`.
  const testing::Evaluated batch = testing::EvaluateRecording(recording, dir / "insert.yaml");
  REQUIRE(batch.exit_code == 0);
  testing::CheckSameVerdicts(live_report, batch.report);
  // The same schema as evaluate's, plus the servo's figures.
  for (const char* key : {"ticks", "overruns", "median_us", "p999_us", "max_us", "rate_hz"})
    CHECK(live_report["servo"].contains(key));
  CHECK(live_report["tubeplan_evaluate"] == batch.report["tubeplan_evaluate"]);
  fs::remove_all(dir);
}

TEST_CASE("live rejects an unknown device and bad emulator arguments", "[device][live]") {
  std::ostringstream out, err;
  CHECK(cli::Run(std::vector<std::string>{"live", SourcePath("plans/groove-insert.yaml"),
                                          "--device", "phantom"},
                 out, err) == 2);
  CHECK_THAT(err.str(), Catch::Contains("unknown device kind \"phantom\""));
  std::ostringstream out2, err2;
  CHECK(cli::Run(std::vector<std::string>{"live", SourcePath("plans/groove-insert.yaml"),
                                          "--device", "emulator:fast,mass=2m"},
                 out2, err2) == 2);
  CHECK_THAT(err2.str(), Catch::Contains("mass=\"2m\""));
}
