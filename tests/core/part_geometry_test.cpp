// The parts' geometry as the contact stage sees it: a cylinder's signed distance against FCL's
// GJK (a different method) outside and against its faces' planes and side inside, its normal's
// derivative against the curvature it reports, and its rims and round side as edges.
#include "core/part_geometry.hpp"

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/distance.h>

#include <tubeplan/scene/elements.hpp>
#include <tubeplan/scene/scene.hpp>

using namespace tubeplan;

namespace {

// A post of radius 6 mm and length 40 mm, turned and moved off the origin so that no axis of
// the part lines up with the world's.
scene::Part TurnedPost() {
  Eigen::Isometry3d X_WP = Eigen::Isometry3d::Identity();
  X_WP.linear() = scene::RotationFromRpy({0.4, -0.7, 1.1});
  X_WP.translation() = Eigen::Vector3d(0.01, -0.02, 0.03);
  return scene::MakeCylinder("post", 6e-3, 40e-3, X_WP);
}

}  // namespace

TEST_CASE("A cylinder's distance outside agrees with FCL's GJK, inside with its faces", "[core]") {
  const scene::Part post = TurnedPost();
  const core::PartGeometry g(post);
  const std::vector<scene::PartElement> elements = scene::ElementsOf(post, 0);
  const double radius = 6e-3, h = 20e-3;
  const fcl::CollisionObjectd cylinder(std::make_shared<fcl::Cylinderd>(radius, 2.0 * h),
                                       post.X_WP);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-0.04, 0.04);
  int outside = 0, inside = 0;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d p_P(0.5 * coordinate(rng), 0.5 * coordinate(rng), coordinate(rng));
    const Eigen::Vector3d p_W = post.X_WP * p_P;
    const core::PartDistance d = g.Distance(p_W);
    CAPTURE(p_P.transpose());
    const double rho = p_P.head<2>().norm();
    const bool beyond_side = rho > radius, beyond_end = std::abs(p_P.z()) > h;
    // The nearest point is on the surface, the normal unit, the point p - d n.
    CHECK(d.normal_W.norm() == Approx(1.0).epsilon(1e-12));
    CHECK((d.point_W - (p_W - d.distance_m * d.normal_W)).norm() < 1e-15);
    if (beyond_side || beyond_end) {
      ++outside;
      fcl::DistanceRequestd request(true);
      request.distance_tolerance = 1e-10;
      fcl::DistanceResultd result;
      const fcl::CollisionObjectd point(std::make_shared<fcl::Sphered>(0.0),
                                        Eigen::Isometry3d(Eigen::Translation3d(p_W)));
      fcl::distance(&cylinder, &point, request, result);
      // 1e-7 m: GJK on a cylinder converges to its tolerance on the support mapping, not exactly.
      CHECK(d.distance_m == Approx(result.min_distance).margin(1e-7));
      CHECK((d.point_W - result.nearest_points[0]).norm() < 1e-6);
      // The element the nearest point lies on: the side beyond the radius, an end beyond it,
      // their rim beyond both.
      const std::string end = p_P.z() > 0.0 ? "top" : "bottom";
      const std::string expected = beyond_side && beyond_end ? "post." + end + "_side"
                                   : beyond_side             ? "post.side"
                                                             : "post." + end;
      REQUIRE(d.element < elements.size());
      CHECK(elements[d.element].name == expected);
    } else {
      ++inside;
      // Inside: out through the nearest of the three faces.
      const double nearest = std::max(rho - radius, std::abs(p_P.z()) - h);
      CHECK(d.distance_m == Approx(nearest).margin(1e-15));
      CHECK(d.distance_m < 0.0);
    }
  }
  CHECK(outside > 500);
  CHECK(inside > 40);  // the post fills 3.5 % of the sampled box
}

TEST_CASE("A cylinder's distance curves as its normal turns", "[core]") {
  // The reported second derivative against central differences of the normal, beside the side,
  // beyond a rim and beyond an end (where it is zero).
  const scene::Part post = TurnedPost();
  const core::PartGeometry g(post);
  for (const Eigen::Vector3d& p_P :
       {Eigen::Vector3d(9e-3, 2e-3, 5e-3), Eigen::Vector3d(7e-3, -3e-3, 23e-3),
        Eigen::Vector3d(1e-3, 2e-3, -25e-3)}) {
    const Eigen::Vector3d p_W = post.X_WP * p_P;
    const Eigen::Matrix3d c = g.Distance(p_W).curvature_per_m;
    const double step = 1e-6;
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d e = step * Eigen::Vector3d::Unit(axis);
      const Eigen::Vector3d dn =
          (g.Distance(p_W + e).normal_W - g.Distance(p_W - e).normal_W) / (2.0 * step);
      CAPTURE(p_P.transpose(), axis);
      // Central differences err by step^2 times the normal's third derivative, ~1e-12 / d^3
      // with d >= 3 mm here: far below 1e-3 of the curvature (~1 / d).
      CHECK((c.col(axis) - dn).norm() < 1e-3 * std::max(1.0, c.norm()));
    }
  }
}

TEST_CASE("A cylinder's rims are closed polygons and its side bears as its axis", "[core]") {
  const scene::Part post = TurnedPost();
  const core::PartGeometry g(post);
  REQUIRE(g.edges().size() == std::size_t(2 * core::kRimSegments + 1));
  CHECK(g.vertices_W().empty());
  const Eigen::Isometry3d X_PW = post.X_WP.inverse();
  for (int k = 0; k < 2 * core::kRimSegments; ++k) {
    const core::PartEdge& e = g.edges()[std::size_t(k)];
    const Eigen::Vector3d a_P = X_PW * e.a_W;
    CHECK(a_P.head<2>().norm() == Approx(6e-3).epsilon(1e-12));
    CHECK(std::abs(a_P.z()) == Approx(20e-3).epsilon(1e-12));
    // Each segment's b end is the next one's a end, which does not bear it again.
    const core::PartEdge& next = g.edges()[std::size_t(k / core::kRimSegments * core::kRimSegments +
                                                       (k + 1) % core::kRimSegments)];
    CHECK((e.b_W - next.a_W).norm() < 1e-15);
    CHECK(e.b_bears);
    CHECK_FALSE(next.a_bears);
    CHECK(e.radius_m == 0.0);
  }
  const core::PartEdge& axis = g.edges().back();
  CHECK(axis.radius_m == 6e-3);
  CHECK((axis.b_W - axis.a_W).norm() == Approx(40e-3).epsilon(1e-12));
  CHECK_FALSE(axis.a_bears);
  CHECK_FALSE(axis.b_bears);
  CHECK(scene::ElementsOf(post, 0)[axis.element].name == "post.side");
  // The tight box: every rim point inside it, and touched along every axis.
  for (int a = 0; a < 3; ++a) {
    double lo = 1.0, hi = -1.0;
    for (const core::PartEdge& e : g.edges()) {
      if (e.radius_m > 0.0) continue;
      lo = std::min(lo, e.a_W[a]);
      hi = std::max(hi, e.a_W[a]);
    }
    // The polygon lies within R (1 - cos(pi / 64)) of the circle the box is made for.
    CHECK(lo >= g.min_W()[a] - 1e-15);
    CHECK(hi <= g.max_W()[a] + 1e-15);
    CHECK(lo - g.min_W()[a] < 6e-3 * (1.0 - std::cos(M_PI / 64)) + 1e-12);
    CHECK(g.max_W()[a] - hi < 6e-3 * (1.0 - std::cos(M_PI / 64)) + 1e-12);
  }
}
