// The core's closed-form distances against FCL's GJK, an independent method.
#include "core/collision.hpp"  // private to the core (src/)

#include <cmath>
#include <random>

#include <catch2/catch.hpp>
#include <fcl/narrowphase/detail/gjk_solver_indep.h>

using namespace tubeplan;

namespace {

Eigen::Isometry3d SegmentPose(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = 0.5 * (a + b);
  X.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), b - a).toRotationMatrix();
  return X;
}

// FCL's GJK as the core configures it: 1e-12 (its default 1e-6 leaves micrometres in d).
fcl::detail::GJKSolver_indep<double> TightGjk() {
  fcl::detail::GJKSolver_indep<double> gjk;
  gjk.gjk_tolerance = 1e-12;
  gjk.gjk_max_iterations = 128;
  return gjk;
}

}  // namespace

TEST_CASE("End cylinder near a box face: the closed form agrees with GJK", "[core][collision]") {
  // The groove scene's end piece (r1 = 8 mm, 12.5 mm long) around a 60 x 200 x 10 mm floor.
  const double r = 0.008, length = 0.0125;
  const Eigen::Vector3d half(0.03, 0.1, 0.005);
  fcl::detail::GJKSolver_indep<double> gjk = TightGjk();
  const fcl::Boxd box(2.0 * half);
  const fcl::Cylinderd cylinder(r, length);
  std::mt19937_64 rng(20261123);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int certified = 0, exact_ties = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    // Centres within a few radii of the box, axes in every direction; every tenth axis exactly
    // along a box axis or across it (the end face or a generator parallel to a face: the ties).
    const Eigen::Vector3d centre(unit(rng) * 0.05, unit(rng) * 0.12, unit(rng) * 0.03);
    Eigen::Vector3d u(unit(rng), unit(rng), unit(rng));
    if (trial % 10 == 0) u = Eigen::Vector3d::Unit(trial / 10 % 3) * (trial % 20 == 0 ? 1 : -1);
    if (trial % 10 == 5) u = Eigen::Vector3d(unit(rng), unit(rng), 0.0);
    if (!(u.norm() > 1e-3)) continue;
    u.normalize();
    const Eigen::Vector3d a = centre - 0.5 * length * u, b = centre + 0.5 * length * u;
    double d = 0.0;
    Eigen::Vector3d p, q;
    if (!core::CylinderBoxFaceDistance(a, b, r, half, d, p, q)) continue;
    ++certified;
    if (trial % 10 == 0 || trial % 10 == 5) ++exact_ties;
    double d_gjk = 0.0;
    Eigen::Vector3d p_gjk, q_gjk;
    const bool separated = gjk.shapeDistance(cylinder, SegmentPose(a, b), box,
                                             Eigen::Isometry3d::Identity(), &d_gjk, &p_gjk, &q_gjk);
    INFO("trial " << trial << " centre " << centre.transpose() << " axis " << u.transpose());
    REQUIRE(separated);
    // GJK at tolerance 1e-12 on a curved shape converges to ~1e-9 m here (a few iterations
    // short of the exact support point); the closed form is exact to rounding.
    CHECK(d == Approx(d_gjk).margin(1e-8));
    // The returned points are on the shapes and d apart.
    CHECK((p - q).norm() == Approx(d).margin(1e-12));
    CHECK((q.cwiseAbs() - half).maxCoeff() <= 1e-15);
    const double along = (p - a).dot(u);
    CHECK(along >= -1e-12);
    CHECK(along <= length + 1e-12);
    CHECK((p - a - along * u).norm() <= r + 1e-12);
  }
  // The certificate holds for most poses near a face (those where a face, not an edge or a
  // vertex, is nearest): the test must have compared many, ties included.
  CHECK(certified > 1000);
  CHECK(exact_ties > 50);
}

TEST_CASE("Segment to box: the closed form against dense sampling", "[core][collision]") {
  // The squared distance from a point to the box is exact (clamp); sampling the segment at 20001
  // points, both ends included, bounds the minimum from above. An interior minimum of a smooth
  // convex piece is flat, so the samples come within ~(step)^2 / length of it (< 1e-9 m here):
  // the closed form must never exceed them and must be that close.
  const Eigen::Vector3d half(0.03, 0.1, 0.005);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto point_sq = [&](const Eigen::Vector3d& x) {
    return (x.cwiseAbs() - half).cwiseMax(0.0).squaredNorm();
  };
  int one_face = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Eigen::Vector3d a(unit(rng) * 0.05, unit(rng) * 0.12, unit(rng) * 0.02);
    Eigen::Vector3d b = a + 0.004 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    if (trial % 2 == 0) {  // over the top face, both ends beyond it: the fast path
      a.z() = half.z() + 1e-4 + 0.003 * std::abs(unit(rng));
      b.z() = half.z() + 1e-4 + 0.003 * std::abs(unit(rng));
      a.x() = 0.02 * unit(rng), b.x() = 0.02 * unit(rng);
      ++one_face;
    }
    double t = -1.0;
    const double f = core::SegmentBoxDistanceSquared(a, b, half, t);
    double sampled = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 20000; ++i)
      sampled = std::min(sampled, point_sq(a + (i / 20000.0) * (b - a)));
    INFO("trial " << trial);
    CHECK(f <= sampled + 1e-18);
    CHECK(std::sqrt(f) == Approx(std::sqrt(sampled)).margin(1e-9));
    CHECK(point_sq(a + t * (b - a)) == Approx(f).margin(1e-18));
  }
  CHECK(one_face == 1000);
}

TEST_CASE("End cylinder pressed into a box: the depth through a face", "[core][collision]") {
  // The groove scene's end piece (r1 = 8 mm, 12.5 mm long) pressed into a 60 x 200 x 10 mm floor.
  const double r = 0.008, length = 0.0125;
  const Eigen::Vector3d half(0.03, 0.1, 0.005);
  double depth = 0.0;
  Eigen::Vector3d p, q, n;

  SECTION("end face flat on the top face: the depth is how far it is pressed in") {
    // Axis along -z, end face 0.3 mm below the top face: exact (the plane is the only way out).
    const Eigen::Vector3d b(0.004, -0.02, half.z() - 0.0003), a = b + Eigen::Vector3d(0, 0, length);
    REQUIRE(core::CylinderBoxPenetration(a, b, r, half, depth, p, q, n));
    CHECK(depth == Approx(0.0003).margin(1e-15));  // one subtraction of doubles
    CHECK(n == Eigen::Vector3d::UnitZ());
    CHECK(q.z() == half.z());
  }
  SECTION("tilted end: the rim point lowest along the normal sets the depth") {
    // Axis tilted 30 degrees from -z about y: the lowest rim point is r sin 30 below the end's
    // centre; centre placed so that point is 0.5 mm under the top face.
    const double tilt = std::acos(-1.0) / 6.0;
    const Eigen::Vector3d u(std::sin(tilt), 0.0, -std::cos(tilt));
    const Eigen::Vector3d b(0.0, 0.0, half.z() - 0.0005 + r * std::sin(tilt));
    REQUIRE(core::CylinderBoxPenetration(b - length * u, b, r, half, depth, p, q, n));
    CHECK(depth == Approx(0.0005).margin(1e-12));  // sin and cos to their last bits
    CHECK(n == Eigen::Vector3d::UnitZ());
  }
  SECTION("apart or deeper than r1: no depth is given") {
    const Eigen::Vector3d b(0.0, 0.0, half.z() + 0.001), a = b + Eigen::Vector3d(0, 0, length);
    CHECK_FALSE(core::CylinderBoxPenetration(a, b, r, half, depth, p, q, n));
    const Eigen::Vector3d deep(0.0, 0.0, half.z() - 1.5 * r);
    CHECK_FALSE(core::CylinderBoxPenetration(deep + Eigen::Vector3d(0, 0, length), deep, r, half,
                                             depth, p, q, n));
  }
  SECTION("random overlaps: moving out by the depth along the normal separates them (GJK)") {
    // The depth is a way out, so it bounds the true penetration from above; GJK, an independent
    // method, confirms the moved cylinder no longer overlaps the box.
    fcl::detail::GJKSolver_indep<double> gjk = TightGjk();
    const fcl::Boxd box(2.0 * half);
    const fcl::Cylinderd cylinder(r, length);
    std::mt19937_64 rng(20261123);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    int checked = 0;
    for (int trial = 0; trial < 3000; ++trial) {
      const Eigen::Vector3d centre(unit(rng) * 0.04, unit(rng) * 0.11, unit(rng) * 0.02);
      const Eigen::Vector3d u = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
      const Eigen::Vector3d a = centre - 0.5 * length * u, b = centre + 0.5 * length * u;
      if (!core::CylinderBoxPenetration(a, b, r, half, depth, p, q, n)) continue;
      ++checked;
      const Eigen::Vector3d out = (depth + 1e-9) * n;  // 1 nm beyond: GJK's own resolution
      double d = 0.0;
      const bool apart = gjk.shapeDistance(cylinder, SegmentPose(a + out, b + out), box,
                                           Eigen::Isometry3d::Identity(), &d, nullptr, nullptr);
      INFO("trial " << trial << " depth " << depth);
      CHECK(apart);
    }
    CHECK(checked > 300);  // the sampling overlaps the box often enough to mean something
  }
}
