// The tick's reduced system solved by its structure (src/core/contact_system.hpp) against the
// independent method: the whole 3n x 3n system assembled and solved by Eigen's dense LU.
#include "core/contact_system.hpp"

#include <random>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

namespace {
using tubeplan::core::kMaxLoads;
using tubeplan::core::SolveOneMoving;

Eigen::Vector3d RandomUnit(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Vector3d v(g(rng), g(rng), g(rng));
  return v.normalized();
}
}  // namespace

TEST_CASE("The structured solve of the tick's system equals the dense LU's", "[core][system]") {
  // Loads as the tick has them (scenes/groove.yaml): penalty K = 1e4 N/m along the normal, a
  // stuck spring Kt = K across it or none, coupling K_c,eff = 400 + 2 / 1e-3 N/m, so C_i =
  // G_i / K_c,eff has entries up to ~4; the moving load's compliance W (symmetric, PSD) up to
  // 1e-2 m/N, the rubber tube's tip (K W ~ 100, beam_chain.hpp).
  std::mt19937 rng(20261130);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double K = 1e4, Kc_eff = 2400.0;
  int checked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int count = 2 + trial % (kMaxLoads - 1);
    const int moving = trial % 5 == 0 ? -1 : int(u(rng) * count);
    std::array<Eigen::Matrix3d, kMaxLoads> C;
    std::array<Eigen::Vector3d, kMaxLoads> b;
    Eigen::Matrix3d A_moving = Eigen::Matrix3d::Identity();
    const int n = 3 * count;
    Eigen::MatrixXd M = Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd rhs(n);
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector3d nrm = RandomUnit(rng);
      const bool stuck = u(rng) < 0.5;
      const Eigen::Matrix3d NN = nrm * nrm.transpose();
      const Eigen::Matrix3d G = K * NN + (stuck ? K : 0.0) * (Eigen::Matrix3d::Identity() - NN);
      C[std::size_t(i)] = G / Kc_eff;
      b[std::size_t(i)] = Eigen::Vector3d::Random() * 5.0;
      for (int j = 0; j < count; ++j) M.block<3, 3>(3 * i, 3 * j) += C[std::size_t(i)];
      if (i == moving) {
        const Eigen::Matrix3d L = Eigen::Matrix3d::Random() * 0.1;
        const Eigen::Matrix3d W = L * L.transpose();  // up to ~1e-2 m/N
        A_moving += G * W;
        M.block<3, 3>(3 * i, 3 * i) += G * W;
      }
      rhs.segment<3>(3 * i) = b[std::size_t(i)];
    }
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3 * kMaxLoads, 1> z(n);
    SolveOneMoving(count, moving, A_moving, C, b, z);
    const Eigen::VectorXd dense = M.partialPivLu().solve(rhs);
    // Each is within ~cond(M) eps of the exact forces, relative to their size: the dense LU as a
    // backward-stable solve. The structured one inverts 3 x 3 blocks by cofactors, which is not
    // backward stable in general (Higham, Accuracy and Stability, 14.6, proves Cramer's rule
    // forward stable for n = 2 only): that it stays within the same bound at the tick's
    // conditioning is what this test measures. A factor 100 covers the growth constants of
    // n <= 24.
    const double cond = [&] {
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(M);
      return svd.singularValues()(0) / svd.singularValues()(n - 1);
    }();
    const double tolerance = 100.0 * cond * std::numeric_limits<double>::epsilon();
    INFO("trial " << trial << ", " << count << " loads, moving " << moving << ", cond " << cond);
    REQUIRE(z.allFinite());
    CHECK((z - dense).norm() <= tolerance * dense.norm());
    // And it solves the system: the residual is the rounding of M z.
    CHECK((M * z - rhs).norm() <= tolerance * (M.norm() * z.norm() + rhs.norm()));
    ++checked;
  }
  CHECK(checked == 400);
}

TEST_CASE("The structured solve with no moving load is the held end's 3 x 3 system",
          "[core][system]") {
  // Every load at the held end: F_i = b_i - C_i S with (I + sum C_i) S = sum b_i. Two loads on
  // a floor (normal z) and a wall (normal x), frictionless, C = G / Kc with G = K n n^T: the
  // sum's matrix is diagonal, so S has a closed form, S_z = b_z,sum / (1 + K / Kc) for the floor.
  const double K = 1e4, Kc = 2400.0;
  std::array<Eigen::Matrix3d, kMaxLoads> C;
  std::array<Eigen::Vector3d, kMaxLoads> b;
  C[0] = K / Kc * Eigen::Vector3d::UnitZ() * Eigen::Vector3d::UnitZ().transpose();
  C[1] = K / Kc * Eigen::Vector3d::UnitX() * Eigen::Vector3d::UnitX().transpose();
  b[0] = Eigen::Vector3d(0.0, 0.0, 3.0);
  b[1] = Eigen::Vector3d(-2.0, 0.0, 0.0);
  Eigen::Matrix<double, 6, 1> z;
  SolveOneMoving(2, -1, Eigen::Matrix3d::Identity(), C, b, z);
  const double S_z = 3.0 / (1.0 + K / Kc), S_x = -2.0 / (1.0 + K / Kc);
  // A few roundings of numbers of order 1.
  CHECK(z(2) == Approx(3.0 - K / Kc * S_z).epsilon(1e-14));
  CHECK(z(3) == Approx(-2.0 - K / Kc * S_x).epsilon(1e-14));
  CHECK(z(0) == 0.0);
  CHECK(z(5) == 0.0);
  // The floor's force is its own penalty in series with the coupling: F = b Kc / (Kc + K).
  CHECK(z(2) == Approx(3.0 * Kc / (Kc + K)).epsilon(1e-14));
}
