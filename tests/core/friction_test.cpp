// The friction law of one contact: the load-dependent limit and the stick/slip return mapping.
#include <cmath>
#include <limits>
#include <random>

#include <catch2/catch.hpp>

#include <tubeplan/core/friction.hpp>

namespace {

using tubeplan::core::FrictionLimit;
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

TEST_CASE("A tip stuck on a wall: k Delta until f_max, then the kinetic force", "[friction]") {
  // The analytic case in the friction law's terms: the hand moves sideways by Delta, the
  // stuck tip's spring k = 3 E I / l^3 stretches, the trial force is k Delta. Below mu_s N it
  // sticks; above, it slides and carries mu_k N, and it slips until k (Delta - slip) = mu_k N.
  const double k = 7.27;  // N/m: scenes/groove.yaml's tube, 3 E I / l^3
  const double normal_N = 1.0;
  const double f_static = 0.7, f_kinetic = 0.08;  // at N = N0 = 1 N
  for (double delta_m = 0.0; delta_m < 0.3; delta_m += 0.005) {
    CAPTURE(delta_m);
    const Eigen::Vector3d trial(k * delta_m, 0.0, 0.0);
    const auto r = ReturnMap(kRubber, trial, normal_N, k);
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
      const auto r = ReturnMap(friction, trial, normal_N, 100.0);
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
  const auto r = ReturnMap(none, Eigen::Vector3d(0.3, -0.4, 0.0), 2.0, 10.0);
  CHECK(r.force_N.isZero(0.0));
  CHECK(r.sliding);
  CHECK(r.slip_m.isApprox(Eigen::Vector3d(0.03, -0.04, 0.0), 1e-15));
  // Zero trial force with zero load: stuck, nothing moves, no NaN from a 0/0 direction.
  const auto zero = ReturnMap(kRubber, Eigen::Vector3d::Zero(), 0.0, 10.0);
  CHECK_FALSE(zero.sliding);
  CHECK(zero.force_N.isZero(0.0));
}
