// The friction law of one contact: the load-dependent limit and the stick/slip return mapping.
#include <cmath>
#include <limits>
#include <random>

#include <catch2/catch.hpp>

#include <tubeplan/core/friction.hpp>

namespace {

using tubeplan::core::FrictionLimit;
using tubeplan::core::FrictionShare;
using tubeplan::core::ReturnMap;
using tubeplan::scene::Friction;

// Table I rubber: mu_s 0.7, mu_k 0.08, beta 2/3, N0 1 N.
const Friction kRubber{0.7, 0.08, 2.0 / 3.0, 1.0};
const Friction kCoulomb{0.3, 0.2, 1.0, 1.0};

}  // namespace

TEST_CASE("Friction limit follows mu N0 (N/N0)^beta", "[friction]") {
  // Hand values: 0.7 * 8^(2/3) = 0.7 * 4 = 2.8 N; 0.7 * 0.125^(2/3) = 0.7 * 0.25 = 0.175 N.
  CHECK(FrictionLimit(kRubber, 0.7, 8.0) == Approx(2.8).epsilon(1e-15));
  CHECK(FrictionLimit(kRubber, 0.7, 0.125) == Approx(0.175).epsilon(1e-15));
  // The reference load makes the coefficient dimensionless: at N = N0 the limit is mu N0.
  Friction shifted = kRubber;
  shifted.reference_load_N = 2.0;
  CHECK(FrictionLimit(shifted, 0.7, 2.0) == Approx(1.4).epsilon(1e-15));
  // Coulomb (beta = 1): exactly mu N, for any N0.
  CHECK(FrictionLimit(kCoulomb, 0.3, 5.0) == 0.3 * 5.0);
}

TEST_CASE("Friction limit at and near zero load is zero and finite", "[friction]") {
  CHECK(FrictionLimit(kRubber, 0.7, 0.0) == 0.0);
  CHECK(FrictionLimit(kRubber, 0.7, -1.0) == 0.0);  // a contact that pulls holds nothing
  // beta < 1: infinite slope at 0, but the value goes to 0 like N^(2/3).
  const double tiny = std::numeric_limits<double>::denorm_min();
  const double f = FrictionLimit(kRubber, 0.7, tiny);
  CHECK(std::isfinite(f));
  CHECK(f >= 0.0);
  CHECK(f < 1e-200);
  CHECK(FrictionLimit(kRubber, 0.7, 1e-30) == Approx(0.7 * 1e-20).epsilon(1e-13));
}

TEST_CASE("A PC's points share its limit: the shares add up to f_max at its normal force",
          "[friction]") {
  std::mt19937_64 rng(20261125);
  std::uniform_real_distribution<double> load(0.0, 10.0);
  for (int trial = 0; trial < 1000; ++trial) {
    // Two or three points pressed with random normal forces (N0 = 1 N).
    const int n = 2 + trial % 2;
    double N[3] = {load(rng), load(rng), n == 3 ? load(rng) : 0.0};
    const double total = N[0] + N[1] + N[2];
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += FrictionShare(kRubber, 0.7, N[i], total);
    // Summing n shares rounds at most a few ulps.
    CHECK(sum == Approx(FrictionLimit(kRubber, 0.7, total)).epsilon(1e-14));
    // Each point holds less than a limit of its own would give it (f_max is concave for beta < 1)
    // and the points together less than those would: by up to n^(1 - beta) for equal loads.
    for (int i = 0; i < n; ++i)
      CHECK(FrictionShare(kRubber, 0.7, N[i], total) <= FrictionLimit(kRubber, 0.7, N[i]));
    // Given the PC's limit found once, each share is the same bits.
    for (const Friction& law : {kRubber, kCoulomb})
      for (int i = 0; i < n; ++i)
        CHECK(FrictionShare(law, 0.7, N[i], total, FrictionLimit(law, 0.7, total)) ==
              FrictionShare(law, 0.7, N[i], total));
  }
  // Two points of 2 N: limits of their own would hold 2^(1/3) times the PC's 4 N.
  const double own = FrictionLimit(kRubber, 0.7, 2.0);
  CHECK(2.0 * own ==
        Approx(std::cbrt(2.0) * 2.0 * FrictionShare(kRubber, 0.7, 2.0, 4.0)).epsilon(1e-15));
  // A PC of one point, and Coulomb's law, are the limit itself, bit for bit.
  CHECK(FrictionShare(kRubber, 0.7, 2.5, 2.5) == FrictionLimit(kRubber, 0.7, 2.5));
  CHECK(FrictionShare(kCoulomb, 0.3, 2.5, 7.0) == FrictionLimit(kCoulomb, 0.3, 2.5));
  // A point that does not press holds nothing; a PC that does not press neither.
  CHECK(FrictionShare(kRubber, 0.7, 0.0, 3.0) == 0.0);
  CHECK(FrictionShare(kRubber, 0.7, 0.0, 0.0) == 0.0);
}

TEST_CASE("A tip stuck on a wall: k Delta until f_max, then the kinetic force", "[friction]") {
  // The analytic stuck-tip case in the friction law's terms: the hand moves sideways by Delta, the
  // stuck tip's spring k = 3 E I / l^3 stretches, the trial force is k Delta. Below mu_s N it
  // sticks; above, it slides and carries mu_k N, and it slips until k (Delta - slip) = mu_k N.
  const double k = 7.27;  // N/m: scenes/groove.yaml's tube, 3 E I / l^3
  const double normal_N = 1.0;
  const double f_static = 0.7, f_kinetic = 0.08;  // at N = N0 = 1 N
  for (double delta_m = 0.0; delta_m < 0.3; delta_m += 0.005) {
    CAPTURE(delta_m);
    const Eigen::Vector3d trial(k * delta_m, 0.0, 0.0);
    const auto r = ReturnMap(kRubber, trial, normal_N, normal_N, k);
    if (k * delta_m <= f_static) {
      CHECK_FALSE(r.sliding);
      CHECK(r.force_N == trial);
      CHECK(r.slip_m.isZero(0.0));
    } else {
      CHECK(r.sliding);
      CHECK(r.force_N.x() == Approx(f_kinetic).epsilon(1e-15));
      CHECK(k * (delta_m - r.slip_m.x()) == Approx(f_kinetic).epsilon(1e-12));
    }
  }
}

TEST_CASE("Return mapping: friction never exceeds f_max and opposes nothing it should not",
          "[friction]") {
  std::mt19937_64 rng(7u);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  std::uniform_real_distribution<double> load(0.0, 10.0);
  for (const Friction& friction : {kRubber, kCoulomb}) {
    for (int i = 0; i < 10000; ++i) {
      const Eigen::Vector3d trial(u(rng), u(rng), 0.0);
      const double normal_N = load(rng);
      const auto r = ReturnMap(friction, trial, normal_N, normal_N, 100.0);
      const double f_max = FrictionLimit(friction, friction.static_coefficient, normal_N);
      CHECK(r.force_N.norm() <= f_max * (1 + 1e-15));
      CHECK(r.force_N.allFinite());
      // The friction is along the trial force (never sideways to it): cross product ~ 0.
      CHECK(r.force_N.cross(trial).norm() <= 1e-12 * trial.norm() * trial.norm());
      // After the slip the spring carries exactly the friction force.
      CHECK((100.0 * (trial / 100.0 - r.slip_m) - r.force_N).norm() <= 1e-12 * (1 + trial.norm()));
    }
  }
}

TEST_CASE("A frictionless contact carries no friction and slips freely", "[friction]") {
  const Friction none{};
  const auto r = ReturnMap(none, Eigen::Vector3d(0.3, -0.4, 0.0), 2.0, 2.0, 10.0);
  CHECK(r.force_N.isZero(0.0));
  CHECK(r.sliding);
  CHECK(r.slip_m.isApprox(Eigen::Vector3d(0.03, -0.04, 0.0), 1e-15));
  // Zero trial force with zero load: stuck, nothing moves, no NaN from a 0/0 direction.
  const auto zero = ReturnMap(kRubber, Eigen::Vector3d::Zero(), 0.0, 0.0, 10.0);
  CHECK_FALSE(zero.sliding);
  CHECK(zero.force_N.isZero(0.0));
}
