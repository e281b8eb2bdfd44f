// The openigtlink:// device against the bridge emulator (tools/igtl-bridge) on loopback: poses
// arrive as the trajectory has them, the wrenches that reach the bridge are within the device's
// limits and end at zero, drops and pauses shorter than the stale window are ridden out and a
// longer pause is stale data, a bridge that stops sending or hangs up zeroes the force, a refused
// connection says so, and a live run's verdicts equal `evaluate` of its recording. The servo
// runs on the real clock here (the bridge does), so only bounds that hold on a loaded machine
// are asserted: the missed-deadline streak is switched off where the loop itself is not under
// test, and stale windows are long where staleness is not under test.
#include <algorithm>
#include <arpa/inet.h>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <netinet/in.h>
#include <poll.h>
#include <spawn.h>
#include <sstream>
#include <string>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/device/openhaptics.hpp>
#include <tubeplan/device/openigtlink.hpp>
#include <tubeplan/device/servo.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>

#include "../alloc_count.hpp"
#include "cli/app.hpp"
#include "io/text_file.hpp"
#include "live_replay.hpp"

extern char** environ;

namespace {

using namespace tubeplan;
using device::StopReason;
namespace fs = std::filesystem;

using testing::InsertPlan;
using testing::SourcePath;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("tubeplan-igtl-" + name + "-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

// The bridge emulator in a process of its own, on an ephemeral loopback port. Every wait is
// bounded; the destructor ends it if a check failed first.
class Bridge {
 public:
  explicit Bridge(std::vector<std::string> extra) {
    std::vector<std::string> args = {TUBEPLAN_IGTL_BRIDGE,
                                     SourcePath("plans/groove-insert.csv"),
                                     "--port",
                                     "0",
                                     "--bind",
                                     "127.0.0.1",
                                     "--accept-timeout",
                                     "20",
                                     "--max-time",
                                     "60"};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    int out[2];
    REQUIRE(::pipe(out) == 0);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    posix_spawn_file_actions_addclose(&actions, out[1]);
    const int e = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    stdout_ = out[0];
    REQUIRE(e == 0);
    // Its first line gives the port.
    const std::string line = ReadUntil('\n', 20'000);
    const std::size_t colon = line.rfind(':');
    REQUIRE(colon != std::string::npos);
    port_ = std::atoi(line.c_str() + colon + 1);
    REQUIRE(port_ > 0);
  }
  ~Bridge() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
    if (stdout_ >= 0) ::close(stdout_);
  }
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;

  int port() const { return port_; }
  /// Waits (at most 30 s) for the bridge to end on its own; its exit code and summary line.
  int Wait(std::string& summary) {
    summary = ReadUntil('\0', 30'000);
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, &status, 0);
    }
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  // Reads stdout up to `end` (or its close), giving up after `timeout_ms`.
  std::string ReadUntil(char end, int timeout_ms) {
    std::string text;
    for (int waited = 0; waited < timeout_ms; waited += 100) {
      pollfd p{stdout_, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      char c = 0;
      const ssize_t n = ::read(stdout_, &c, 1);
      if (n <= 0) break;
      if (c == end) break;
      text += c;
      waited -= 100;  // only idle time counts
    }
    return text;
  }

  pid_t pid_ = -1;
  int stdout_ = -1;
  int port_ = 0;
};

struct WrenchRow {
  double t_s;
  bool force;
  Eigen::Vector3d value;
  double round_trip_us;
};

std::vector<WrenchRow> ReadWrenches(const fs::path& file) {
  std::vector<WrenchRow> rows;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string t, kind, x, y, z, rt;
    std::getline(fields, t, ',');
    std::getline(fields, kind, ',');
    std::getline(fields, x, ',');
    std::getline(fields, y, ',');
    std::getline(fields, z, ',');
    std::getline(fields, rt, ',');
    rows.push_back({std::stod(t), kind == "force",
                    Eigen::Vector3d(std::stod(x), std::stod(y), std::stod(z)), std::stod(rt)});
  }
  return rows;
}

// The forces the bridge received, in order, with their largest size and their largest rise
// from one to the next (a step to zero, a stall or the end, is never rate-limited: removing
// force pushes nobody).
struct BridgeForces {
  std::vector<WrenchRow> forces;
  double largest_N = 0.0, largest_rise_N = 0.0;
};

BridgeForces ForcesOf(const std::vector<WrenchRow>& rows) {
  BridgeForces f;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (const WrenchRow& r : rows) {
    if (!r.force) continue;
    f.forces.push_back(r);
    f.largest_N = std::max(f.largest_N, r.value.norm());
    if (!r.value.isZero(0.0))
      f.largest_rise_N = std::max(f.largest_rise_N, (r.value - previous).norm());
    previous = r.value;
  }
  return f;
}

// The bridge's own counts, from its summary line: poses sent, dropped, delayed (held in a pause
// and sent in its burst) and pauses begun; -1 where the line does not say.
struct BridgeCounts {
  long sent = -1, dropped = -1, delayed = -1, pauses = -1;
};

BridgeCounts ParseSummary(const std::string& summary) {
  BridgeCounts c;
  const std::size_t at = summary.find("sent ");
  if (at != std::string::npos)
    std::sscanf(summary.c_str() + at, "sent %ld poses, dropped %ld, delayed %ld in %ld pauses",
                &c.sent, &c.dropped, &c.delayed, &c.pauses);
  return c;
}

device::OpenIGTLinkOptions Loopback(int port) {
  device::OpenIGTLinkOptions o;
  o.host = "127.0.0.1";
  o.port = port;
  o.connect_timeout_s = 10.0;  // a loaded machine may start the bridge's stream late
  return o;
}

// Limits as live makes them, without the missed-deadline streak: the servo loop's own safety
// is tested on a stepped clock (servo_test.cpp); here a loaded machine must not end the run.
device::SafetyLimits LenientLimits(const device::HapticDevice& dev) {
  device::SafetyLimits limits = device::LimitsFor(dev.spec(), InsertPlan().scene->device);
  limits.max_missed_deadlines = 1 << 30;
  return limits;
}

struct ServoRun {
  device::ServoStats stats;
  std::vector<device::TickRecord> records;
};

ServoRun RunServo(device::HapticDevice& dev, long ticks, int stale_ticks,
                  const device::SafetyLimits& limits) {
  device::MonotonicClock clock;
  core::Core core(*InsertPlan().scene);
  device::SpscRing<device::TickRecord> ring(std::size_t(ticks) + 16);
  device::ServoConfig config;
  config.realtime = false;
  config.max_ticks = ticks;
  config.max_stale_ticks = stale_ticks;
  // On a loaded test machine, and in the sanitizer build, the loop stalls for milliseconds,
  // at times on tick after tick: these tests are about what reaches the bridge, which a tick
  // sends stalled or not, so no stall ends their runs.
  config.max_stall_s = 10.0;
  config.max_stalls_per_s = 0;
  device::ServoLoop servo(core, dev, clock, limits, config, &ring, nullptr);
  ServoRun run;
  run.stats = servo.Run();
  for (device::TickRecord r; ring.TryPop(r);) run.records.push_back(r);
  return run;
}

// Whether the force sent reached the clamp wherever it could: once the plan has pushed harder
// than the clamp for 20 ticks without a stall. A stall drops the force to zero and the ramp back
// takes 10 ticks (0.005 N a tick), so a loaded machine that stalls the servo every few ticks may
// never let it reach the clamp: `settled` counts the ticks where it had to.
struct ClampReached {
  long settled = 0, below_clamp = 0;
};

ClampReached CountClampTicks(const std::vector<device::TickRecord>& records, double clamp_N) {
  ClampReached c;
  int pushing = 0;
  for (const device::TickRecord& r : records) {
    pushing = r.stepped && !r.stalled && r.out.force_W_N.norm() > clamp_N ? pushing + 1 : 0;
    if (pushing < 20) continue;
    ++c.settled;
    c.below_clamp += r.force_sent_N.norm() < clamp_N * 0.999;
  }
  return c;
}

}  // namespace

TEST_CASE("Poses from an OpenIGTLink bridge are the trajectory's, in order",
          "[device][openigtlink]") {
  Bridge bridge({});
  device::OpenIGTLinkDevice dev(Loopback(bridge.port()));
  REQUIRE(dev.Open().empty());
  const trajectories::Trajectory& trajectory = *InsertPlan().trajectory;
  std::size_t cursor = 0;
  std::uint64_t previous = 0;
  int checked = 0;
  // The bridge sends the trajectory's pose at t0 + (n - 1) / 1 kHz as its n-th TRANSFORM, so a
  // reading's sequence says which pose it must be, whatever the timing.
  for (int i = 0; i < 200; ++i) {
    device::DeviceSample s;
    REQUIRE(dev.Read(s));
    REQUIRE(s.sequence >= previous);
    if (s.sequence != previous) {
      const trajectories::HandSample expected = trajectories::PoseAt(
          trajectory, trajectory.samples.front().t_s + double(s.sequence - 1) * 1e-3, cursor);
      // float32 millimetres on the wire: 2^-24 of 300 mm is 2e-8 m; the rotation's float32
      // entries are good to about 1e-7.
      CHECK((s.X_W_hand.translation() - expected.p_WH_m).norm() < 1e-7);
      CHECK(Eigen::AngleAxisd(Eigen::Quaterniond(s.X_W_hand.linear()) * expected.q_WH.conjugate())
                .angle() < 1e-6);
      if (s.sequence >= 2) {
        // The velocity: the difference of the last two poses over their timestamps, 1 ms apart
        // (the bridge stamps sample times). float32 positions, 2e-8 m over 1 ms: 2e-5 m/s.
        std::size_t c = 0;
        const trajectories::HandSample before = trajectories::PoseAt(
            trajectory, trajectory.samples.front().t_s + double(s.sequence - 2) * 1e-3, c);
        const Eigen::Vector3d v = (expected.p_WH_m - before.p_WH_m) / 1e-3;
        CHECK((s.v_W_m_per_s - v).norm() < 1e-4);
      }
      ++checked;
    }
    previous = s.sequence;
    ::usleep(2000);
  }
  CHECK(checked >= 10);  // the stream moved on while we read, even on a slow machine
  dev.Close();
  std::string summary;
  CHECK(bridge.Wait(summary) == 0);
  CHECK(dev.counters().poses >= std::uint64_t(checked));
}

TEST_CASE("The servo's wrenches reach the bridge within the device's limits and end at zero",
          "[device][openigtlink][safety]") {
  const fs::path dir = TempDir("limits");
  const fs::path wrenches = dir / "wrenches.csv";
  Bridge bridge({"--wrenches", wrenches.string()});
  device::OpenIGTLinkOptions options = Loopback(bridge.port());
  // A device weaker than the plan needs (its peak is 0.19 N): the clamp must show at the bridge.
  options.spec.max_force_N = 0.05;
  device::OpenIGTLinkDevice dev(options);
  REQUIRE(dev.Open().empty());
  // 4 s of the insertion: the side lands on the floor and presses (about 0.1 N at 3.5 s).
  const device::SafetyLimits limits = LenientLimits(dev);
  const ServoRun run = RunServo(dev, 4000, 1000, limits);
  CHECK(run.stats.stop == StopReason::kCompleted);
  dev.Close();
  std::string summary;
  REQUIRE(bridge.Wait(summary) == 0);  // non-zero: a wrench failed its CRC at the bridge
  INFO(summary);
  const device::OpenIGTLinkCounters counters = dev.counters();
  const std::vector<WrenchRow> rows = ReadWrenches(wrenches);
  const BridgeForces received = ForcesOf(rows);
  const std::vector<WrenchRow>& forces = received.forces;
  const double largest_N = received.largest_N, largest_step_N = received.largest_rise_N;
  // Every wrench written reached the bridge (TCP on loopback; none was lost or garbled).
  REQUIRE(forces.size() == counters.wrenches_sent);
  // One per tick and the zeros at the end, less any skipped on a full socket.
  REQUIRE(forces.size() + counters.wrenches_skipped >= 4000);
  CHECK(largest_N <= 0.05 * (1 + 1e-12));
  // The bridge got what the servo sent, tick by tick (float64 on the wire: exactly).
  if (counters.wrenches_skipped == 0) {
    long differing = 0;
    for (std::size_t k = 0; k < run.records.size(); ++k)
      differing += forces[k].value != run.records[k].force_sent_N;
    CHECK(differing == 0);
  }
  const ClampReached clamp = CountClampTicks(run.records, 0.05);
  CHECK(clamp.below_clamp == 0);
  if (clamp.settled == 0) WARN("the servo stalled too often for the force to reach the clamp");
  // The limiter's ramp (this device's: 0.05 N in 10 ms, 0.005 N a tick), one more step for
  // each wrench the device skipped on a full socket.
  CHECK(limits.max_force_rate_N_per_s == Approx(5.0));
  CHECK(largest_step_N <=
        limits.max_force_rate_N_per_s * 1e-3 * double(1 + counters.wrenches_skipped) * (1 + 1e-9));
  CHECK(forces.back().value.isZero(0.0));  // the last wrench is zero (end of session, Close)
  for (const WrenchRow& r : rows)
    if (!r.force) CHECK(r.value.norm() <= 0.188 * (1 + 1e-12));
  fs::remove_all(dir);
}

TEST_CASE("A bridge that stops sending poses makes the force zero (stale data)",
          "[device][openigtlink][safety]") {
  const fs::path dir = TempDir("stale");
  const fs::path wrenches = dir / "wrenches.csv";
  Bridge bridge({"--stop-after", "1.0", "--wrenches", wrenches.string()});
  device::OpenIGTLinkDevice dev(Loopback(bridge.port()));
  REQUIRE(dev.Open().empty());
  // 50 ms without a pose is stale; the bridge stops after 1 s, the run would last 30 s.
  const ServoRun run = RunServo(dev, 30000, 50, LenientLimits(dev));
  CHECK(run.stats.stop == StopReason::kStaleData);
  REQUIRE(run.records.size() >= 2);
  CHECK(run.records.size() < 30000);
  CHECK(run.records.back().force_sent_N.isZero(0.0));
  CHECK(run.records.back().torque_sent_Nm.isZero(0.0));
  dev.Close();
  std::string summary;
  REQUIRE(bridge.Wait(summary) == 0);
  INFO(summary);
  const std::vector<WrenchRow> rows = ReadWrenches(wrenches);
  REQUIRE(!rows.empty());
  // The bridge, still reading, got the zero: its last force and torque.
  CHECK(rows.back().value.isZero(0.0));
  CHECK(rows[rows.size() - 2].value.isZero(0.0));
  fs::remove_all(dir);
}

TEST_CASE("A bridge that hangs up makes the force zero (device error)",
          "[device][openigtlink][safety]") {
  Bridge bridge({"--close-after", "0.5"});
  device::OpenIGTLinkDevice dev(Loopback(bridge.port()));
  REQUIRE(dev.Open().empty());
  const ServoRun run = RunServo(dev, 30000, 1000, LenientLimits(dev));
  CHECK(run.stats.stop == StopReason::kDeviceError);
  CHECK(run.records.size() < 30000);
  CHECK(run.records.back().force_sent_N.isZero(0.0));
  CHECK_THAT(dev.link_error(), Catch::Contains("the bridge closed the connection"));
  dev.Close();
  std::string summary;
  CHECK(bridge.Wait(summary) == 0);
}

TEST_CASE(
    "Poses dropped and delayed within the stale window: the servo runs on, its wrenches "
    "within the limits and ending at zero",
    "[device][openigtlink][safety]") {
  const fs::path dir = TempDir("lossy");
  const fs::path wrenches = dir / "wrenches.csv";
  // A fifth of the poses lost, and every 250 poses a pause of 10 ms whose poses then come at once.
  Bridge bridge({"--drop", "0.2", "--seed", "7", "--delay-ms", "10", "--delay-every", "250",
                 "--wrenches", wrenches.string()});
  device::OpenIGTLinkOptions options = Loopback(bridge.port());
  // Weaker than the plan needs (its peak is 0.19 N), so that the clamp and the ramp show.
  options.spec.max_force_N = 0.05;
  device::OpenIGTLinkDevice dev(options);
  REQUIRE(dev.Open().empty());
  const device::SafetyLimits limits = LenientLimits(dev);
  // A stale window of 60 ms (as `stale=60ms` makes it): longer than a pause and the drops around
  // it, with room for a loaded machine's scheduling of the bridge.
  const ServoRun run = RunServo(dev, 3000, 60, limits);
  CHECK(run.stats.stop == StopReason::kCompleted);
  CHECK(run.records.size() == 3000);

  // The velocity differences the poses' sample times, not their arrival: a drop (2 ms between
  // two poses) or a burst (poses microseconds apart) leaves it the trajectory's. Read here, after
  // the servo, where the bridge keeps streaming through its pauses (0.6 s: two of them).
  const trajectories::Trajectory& trajectory = *InsertPlan().trajectory;
  double fastest_m_per_s = 0.0;
  for (std::size_t i = 1; i < trajectory.samples.size(); ++i)
    fastest_m_per_s = std::max(
        fastest_m_per_s, (trajectory.samples[i].p_WH_m - trajectory.samples[i - 1].p_WH_m).norm() /
                             (trajectory.samples[i].t_s - trajectory.samples[i - 1].t_s));
  double largest_v_m_per_s = 0.0;
  for (int i = 0; i < 600; ++i) {
    device::DeviceSample s;
    REQUIRE(dev.Read(s));
    largest_v_m_per_s = std::max(largest_v_m_per_s, s.v_W_m_per_s.norm());
    ::usleep(1000);
  }
  // float32 millimetres on the wire: 2e-8 m over at least 1 ms, 2e-5 m/s.
  CHECK(largest_v_m_per_s <= fastest_m_per_s + 1e-4);
  dev.Close();
  std::string summary;
  REQUIRE(bridge.Wait(summary) == 0);  // non-zero: a wrench failed its CRC at the bridge
  INFO(summary);

  // What the bridge sent, every pose of it, reached the device (TCP); what it dropped did not.
  const BridgeCounts bridge_counts = ParseSummary(summary);
  const device::OpenIGTLinkCounters counters = dev.counters();
  CHECK(counters.poses == std::uint64_t(bridge_counts.sent));
  // A fifth of the poses dropped, within 5 standard deviations, sqrt(n p (1 - p)); a pause cut
  // short by the end of the session holds at most 10 poses that are neither sent nor dropped.
  const double sampled = double(bridge_counts.sent + bridge_counts.dropped);
  CHECK(std::abs(double(bridge_counts.dropped) - 0.2 * sampled) <=
        5.0 * std::sqrt(sampled * 0.2 * 0.8) + 10.0);
  // At least 3.6 s of poses: a pause after each 250 of them, each holding its 10 ms of poses
  // that were not dropped.
  CHECK(bridge_counts.pauses >= 3600 / 250 - 1);
  CHECK(bridge_counts.delayed <= 10 * bridge_counts.pauses);
  CHECK(bridge_counts.delayed >= 5 * bridge_counts.pauses);

  const std::vector<WrenchRow> rows = ReadWrenches(wrenches);
  const BridgeForces received = ForcesOf(rows);
  const std::vector<WrenchRow>& forces = received.forces;
  REQUIRE(forces.size() == counters.wrenches_sent);  // every wrench written reached the bridge
  REQUIRE(forces.size() + counters.wrenches_skipped >= 3000);
  // A burst moves the hand 10 ms at once; the force still rises by at most the limiter's step
  // (0.05 N in 10 ms: 0.005 N a tick, one more for each wrench skipped on a full socket) and
  // falls to zero only whole (a stall drops it).
  const double step_N =
      limits.max_force_rate_N_per_s * 1e-3 * double(1 + counters.wrenches_skipped);
  const double largest_N = received.largest_N, largest_step_N = received.largest_rise_N;
  CHECK(largest_N <= 0.05 * (1 + 1e-12));
  // The clamp was reached where the plan pushed harder without a stall.
  const ClampReached clamp = CountClampTicks(run.records, 0.05);
  CHECK(clamp.below_clamp == 0);
  if (clamp.settled == 0) WARN("the servo stalled too often for the force to reach the clamp");
  if (clamp.settled > 0) CHECK(largest_N >= 0.05 * 0.999);
  CHECK(largest_step_N <= step_N * (1 + 1e-9));
  CHECK(forces.back().value.isZero(0.0));
  for (const WrenchRow& r : rows)
    if (!r.force) CHECK(r.value.norm() <= limits.max_torque_Nm * (1 + 1e-12));
  CHECK(rows.back().value.isZero(0.0));
  fs::remove_all(dir);
}

TEST_CASE(
    "A pause longer than the stale window stops live: stale device data, force zero, "
    "exit 4",
    "[device][openigtlink][live][safety]") {
  const fs::path dir = TempDir("pause");
  const fs::path recording = dir / "live.csv";
  const fs::path wrenches = dir / "wrenches.csv";
  // One pause of 200 ms, 1 s into the stream (the hand moves then), against a window of 30 ms.
  Bridge bridge({"--delay-ms", "200", "--delay-every", "1000", "--wrenches", wrenches.string()});
  std::ostringstream out, err;
  const int code = cli::Run(
      std::vector<std::string>{
          "live", SourcePath("plans/groove-insert.yaml"), "--device",
          "openigtlink://127.0.0.1:" + std::to_string(bridge.port()) + ",stale=30ms,timeout=10s",
          "--duration", "3", "--record", recording.string(), "--json"},
      out, err);
  INFO(err.str());
  REQUIRE(!out.str().empty());
  const nlohmann::json report = nlohmann::json::parse(out.str());
  CHECK(report["servo"]["stop"] == "stale device data");
  CHECK(code == cli::kExitDeviceFault);
  CHECK_THAT(err.str(), Catch::Contains("the servo stopped on a fault (stale device data)"));
  // Stopped in the pause, long before the 3001 ticks of the session.
  const long ticks = report["servo"]["ticks"];
  CHECK(ticks > 30);
  CHECK(ticks < 2000);
  std::string summary;
  CHECK(bridge.Wait(summary) == 0);
  INFO(summary);

  // The servo stepped the core on the last pose for 30 ticks (the one that brought it and 29
  // stale ones); the 30th stale tick stopped it unstepped. The hand moves: the pose before
  // differs.
  const io::TrajectoryLoadResult loaded = io::LoadTrajectoryFile(recording.string());
  REQUIRE(loaded.trajectory);
  const std::vector<trajectories::HandSample>& samples = loaded.trajectory->samples;
  REQUIRE(samples.size() == std::size_t(ticks - 1));
  const trajectories::HandSample& last = samples.back();
  std::size_t same = 0;
  while (same < samples.size() && samples[samples.size() - 1 - same].p_WH_m == last.p_WH_m &&
         samples[samples.size() - 1 - same].q_WH.coeffs() == last.q_WH.coeffs())
    ++same;
  CHECK(same == 30);

  // Every tick's wrench reached the bridge, then three zeros (after the loop, its Disable and
  // Close's); from the faulted tick on, force and torque are zero.
  const std::vector<WrenchRow> rows = ReadWrenches(wrenches);
  std::vector<WrenchRow> forces, torques;
  for (const WrenchRow& r : rows) (r.force ? forces : torques).push_back(r);
  REQUIRE(forces.size() == std::size_t(ticks + 3));
  REQUIRE(torques.size() == forces.size());
  for (std::size_t i = forces.size() - 4; i < forces.size(); ++i) {
    CHECK(forces[i].value.isZero(0.0));
    CHECK(torques[i].value.isZero(0.0));
  }
  fs::remove_all(dir);
}

TEST_CASE("Reading and sending over OpenIGTLink allocate nothing in the servo thread",
          "[device][openigtlink][alloc]") {
  Bridge bridge({});
  device::OpenIGTLinkDevice dev(Loopback(bridge.port()));
  REQUIRE(dev.Open().empty());
  device::WrenchLimiter limiter(LenientLimits(dev), 1e-3);
  device::DeviceSample s;
  REQUIRE(dev.Read(s));
  dev.Send(limiter.Command(Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d::Zero()));
  // No assertion inside the counted loop: a reporter that keeps results would allocate there.
  const std::int64_t before = tubeplan::testing::g_allocations;
  int reads_failed = 0;
  for (int i = 0; i < 300; ++i) {
    if (!dev.Read(s)) ++reads_failed;
    dev.Send(limiter.Command(Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d::Zero()));
    ::usleep(500);
  }
  const std::int64_t allocations = tubeplan::testing::g_allocations - before;
  CHECK(reads_failed == 0);
  CHECK(allocations == 0);
  dev.Close();
  std::string summary;
  CHECK(bridge.Wait(summary) == 0);
}

TEST_CASE("A refused connection or a silent bridge is a clear error", "[device][openigtlink]") {
  // A loopback port bound but not listening: connecting is refused, and nobody else can take
  // the port while the test holds it.
  const int holder = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  REQUIRE(::bind(holder, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0);
  socklen_t length = sizeof address;
  ::getsockname(holder, reinterpret_cast<sockaddr*>(&address), &length);
  const int port = ntohs(address.sin_port);
  const std::string where = "127.0.0.1:" + std::to_string(port);

  SECTION("the device") {
    device::OpenIGTLinkDevice dev(Loopback(port));
    CHECK_THAT(dev.Open(), Catch::Contains("connection refused by " + where));
    device::DeviceSample s;
    CHECK(!dev.Read(s));
  }
  SECTION("live: exit 2, the message says where") {
    std::ostringstream out, err;
    const int code =
        cli::Run(std::vector<std::string>{"live", SourcePath("plans/groove-insert.yaml"),
                                          "--device", "openigtlink://" + where, "--duration", "1"},
                 out, err);
    CHECK(code == 2);
    CHECK_THAT(err.str(),
               Catch::Contains("cannot open the device: connection refused by " + where));
    CHECK(out.str().empty());
  }
  SECTION("a bridge that accepts but sends no pose") {
    REQUIRE(::listen(holder, 1) == 0);  // the kernel completes the handshake; nobody answers
    device::OpenIGTLinkOptions options = Loopback(port);
    options.connect_timeout_s = 0.3;
    device::OpenIGTLinkDevice dev(options);
    CHECK_THAT(dev.Open(),
               Catch::Contains("connected to " + where + " but no TRANSFORM arrived within 0.3 s"));
  }
  ::close(holder);
}

TEST_CASE("live over OpenIGTLink gets the verdicts of evaluate of its recording",
          "[device][openigtlink][live]") {
  const fs::path dir = TempDir("live");
  const fs::path recording = dir / "live.csv";
  Bridge bridge({});
  std::ostringstream out, err;
  const int code = cli::Run(
      std::vector<std::string>{
          "live", SourcePath("plans/groove-insert.yaml"), "--device",
          "openigtlink://127.0.0.1:" + std::to_string(bridge.port()) + ",stale=1s,timeout=10s",
          "--duration", "2", "--record", recording.string(), "--json"},
      out, err);
  INFO(err.str());
  REQUIRE(!out.str().empty());
  const nlohmann::json live_report = nlohmann::json::parse(out.str());
  const std::string stop = live_report["servo"]["stop"];
  // SCHED_FIFO where permitted (a note otherwise): a loaded machine stalls a normal thread often.
  // 2 s of a 5.5 s plan: the goal is not reached (exit 1). A loaded machine may stall the servo
  // beyond the stall limits: that ends the run, force zeroed, as a device fault (exit 4); the
  // verdicts of what was recorded must still be evaluate's.
  if (stop == "missed deadlines") {
    CHECK(code == cli::kExitDeviceFault);
  } else {
    CHECK(stop == "completed");
    CHECK(code == 1);
    CHECK(live_report["servo"]["ticks"] == 2001);
  }
  CHECK_THAT(std::string(live_report["servo"]["device"]), Catch::Contains("over OpenIGTLink"));
  CHECK_THAT(err.str(), Catch::Contains("openigtlink: "));
  std::string summary;
  CHECK(bridge.Wait(summary) == 0);
  WARN(summary);  // the round-trip figures, for the record

  REQUIRE(fs::exists(recording));
  const testing::Evaluated batch = testing::EvaluateRecording(recording, dir / "live.yaml");
  CHECK(batch.exit_code == (live_report["plans"][0]["feasible"] == true ? 0 : 1));
  testing::CheckSameVerdicts(live_report, batch.report);
  fs::remove_all(dir);
}

TEST_CASE("live's --device: openigtlink arguments and openhaptics", "[device][live]") {
  const std::string plan = SourcePath("plans/groove-insert.yaml");
  auto run = [&](const std::string& device, std::string& err) {
    std::ostringstream out, e;
    const int code = cli::Run(std::vector<std::string>{"live", plan, "--device", device}, out, e);
    err = e.str();
    return code;
  };
  std::string err;
  CHECK(run("openigtlink://127.0.0.1", err) == 2);
  CHECK_THAT(err, Catch::Contains("expected openigtlink://HOST:PORT"));
  CHECK(run("openigtlink://127.0.0.1:99999", err) == 2);
  CHECK_THAT(err, Catch::Contains("a port from 1 to 65535"));
  CHECK(run("openigtlink://127.0.0.1:18944,stale=2kg", err) == 2);
  CHECK_THAT(err, Catch::Contains("stale=\"2kg\""));
  CHECK(run("openigtlink://127.0.0.1:18944,speed=1", err) == 2);
  CHECK_THAT(err, Catch::Contains("unknown openigtlink argument \"speed\""));
  if (!device::OpenHapticsBuiltIn()) {
    CHECK(run("openhaptics", err) == 2);
    CHECK_THAT(err, Catch::Contains("this tubeplan was built without the OpenHaptics SDK; "
                                    "rebuild with -DTUBEPLAN_OPENHAPTICS=ON"));
    CHECK(run("openhaptics:Default PHANToM", err) == 2);
  }
}
