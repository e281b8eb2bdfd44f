// The device's last line of defence: clamp, rate limit, zero on NaN / missed deadlines / stop.
#include <cmath>
#include <limits>
#include <random>

#include <catch2/catch.hpp>

#include <tubeplan/device/wrench_limiter.hpp>

namespace {
using tubeplan::device::Fault;
using tubeplan::device::LimitsFor;
using tubeplan::device::SafetyLimits;
using tubeplan::device::WrenchLimiter;

const Eigen::Vector3d kNoTorque = Eigen::Vector3d::Zero();
constexpr double kStep = 1e-3;
}  // namespace

TEST_CASE("Limits come from the device: 10 ms from zero to the maximum", "[safety]") {
  const SafetyLimits limits = LimitsFor(tubeplan::scene::Device{});
  CHECK(limits.max_force_N == 8.5);
  CHECK(limits.max_force_rate_N_per_s == Approx(850.0).epsilon(1e-15));
  CHECK(limits.max_torque_rate_Nm_per_s == Approx(18.8).epsilon(1e-15));
}

TEST_CASE("A step request is clamped in magnitude and ramped at the rate limit", "[safety]") {
  WrenchLimiter limiter(SafetyLimits{}, kStep);
  // 20 N along (3, 4, 0)/5: clamped to 8.5 N in that direction, reached by 0.85 N a tick.
  const Eigen::Vector3d request(12.0, 16.0, 0.0);
  const Eigen::Vector3d direction = request.normalized();
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  int ticks = 0;
  for (; ticks < 100; ++ticks) {
    const auto out = limiter.Command(request, kNoTorque);
    CHECK(out.clamped);
    CHECK(out.force_N.norm() <= 8.5 * (1 + 1e-15));
    CHECK((out.force_N - previous).norm() <= 0.85 * (1 + 1e-12));
    CHECK(out.force_N.cross(direction).norm() < 1e-12);  // the direction is kept
    previous = out.force_N;
    if (!out.rate_limited) break;
  }
  // 8.5 N at 0.85 N per tick: ten ticks of ramp, the tenth arrives exactly (within rounding).
  CHECK(ticks == 10);
  CHECK(previous.norm() == Approx(8.5).epsilon(1e-12));
}

TEST_CASE("Dropping to zero is immediate", "[safety]") {
  WrenchLimiter limiter(SafetyLimits{}, kStep);
  for (int i = 0; i < 20; ++i) limiter.Command(Eigen::Vector3d(5.0, 0, 0), kNoTorque);
  const auto out = limiter.Command(Eigen::Vector3d::Zero(), kNoTorque);
  CHECK(out.force_N.isZero(0.0));
  CHECK_FALSE(out.rate_limited);
  // A reversal is not a drop: it is rate limited.
  for (int i = 0; i < 20; ++i) limiter.Command(Eigen::Vector3d(5.0, 0, 0), kNoTorque);
  const auto reversed = limiter.Command(Eigen::Vector3d(-5.0, 0, 0), kNoTorque);
  CHECK(reversed.rate_limited);
  CHECK(reversed.force_N.x() == Approx(5.0 - 0.85).epsilon(1e-12));
}

TEST_CASE("NaN zeroes the output and latches until reset, then it ramps again", "[safety]") {
  WrenchLimiter limiter(SafetyLimits{}, kStep);
  for (int i = 0; i < 20; ++i) limiter.Command(Eigen::Vector3d(3.0, 0, 0), kNoTorque);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto bad = limiter.Command(Eigen::Vector3d(nan, 0, 0), kNoTorque);
  CHECK(bad.force_N.isZero(0.0));
  CHECK(bad.fault == Fault::kNonFinite);
  // A good request afterwards is still refused: a NaN means the core is broken.
  CHECK(limiter.Command(Eigen::Vector3d(3.0, 0, 0), kNoTorque).force_N.isZero(0.0));
  const auto inf_torque = limiter.Command(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, HUGE_VAL));
  CHECK(inf_torque.torque_Nm.isZero(0.0));
  limiter.Reset();
  const auto first = limiter.Command(Eigen::Vector3d(3.0, 0, 0), kNoTorque);
  CHECK(first.fault == Fault::kNone);
  CHECK(first.force_N.x() == Approx(0.85).epsilon(1e-12));  // from zero, not from 3 N
}

TEST_CASE("Missed deadlines: one is tolerated, a streak faults", "[safety]") {
  WrenchLimiter limiter(SafetyLimits{}, kStep);
  const Eigen::Vector3d f(1.0, 0, 0);
  CHECK(limiter.Command(f, kNoTorque, true).fault == Fault::kNone);
  CHECK(limiter.Command(f, kNoTorque, true).fault == Fault::kNone);
  CHECK(limiter.Command(f, kNoTorque, false).fault == Fault::kNone);  // streak broken
  limiter.Command(f, kNoTorque, true);
  limiter.Command(f, kNoTorque, true);
  const auto out = limiter.Command(f, kNoTorque, true);  // third in a row
  CHECK(out.fault == Fault::kMissedDeadlines);
  CHECK(out.force_N.isZero(0.0));
}

TEST_CASE("Stop zeroes at once and stays zero", "[safety]") {
  WrenchLimiter limiter(SafetyLimits{}, kStep);
  for (int i = 0; i < 20; ++i) limiter.Command(Eigen::Vector3d(0, 4.0, 0), kNoTorque);
  limiter.Stop();
  const auto out = limiter.Command(Eigen::Vector3d(0, 4.0, 0), kNoTorque);
  CHECK(out.force_N.isZero(0.0));
  CHECK(out.fault == Fault::kStopped);
}

TEST_CASE("Whatever is requested, the output is finite, bounded and smooth", "[safety]") {
  const SafetyLimits limits{};
  WrenchLimiter limiter(limits, kStep);
  std::mt19937_64 rng(99u);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  Eigen::Vector3d last_force = Eigen::Vector3d::Zero(), last_torque = Eigen::Vector3d::Zero();
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d f(u(rng), u(rng), u(rng)), t(u(rng), u(rng), u(rng));
    const auto out = limiter.Command(i % 97 == 0 ? Eigen::Vector3d::Zero() : f, 0.01 * t);
    CHECK(out.force_N.allFinite());
    CHECK(out.force_N.norm() <= limits.max_force_N * (1 + 1e-15));
    CHECK(out.torque_Nm.norm() <= limits.max_torque_Nm * (1 + 1e-15));
    if (!out.force_N.isZero(0.0)) CHECK((out.force_N - last_force).norm() <= 0.85 * (1 + 1e-12));
    if (!out.torque_Nm.isZero(0.0))
      CHECK((out.torque_Nm - last_torque).norm() <= 0.0188 * (1 + 1e-12));
    last_force = out.force_N;
    last_torque = out.torque_Nm;
  }
}
