// The geometry a scene is checked with: the broad phase finds exactly the overlapping pairs a
// comparison of every pair finds, and the straight tube's overlap with a box is exact against
// figures worked by hand.
#include <cmath>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/scene/geometry.hpp>

namespace {

using tubeplan::scene::Part;

Part Box(const Eigen::Vector3d& size_m, const Eigen::Vector3d& position_m,
            const Eigen::Vector3d& rpy_rad = Eigen::Vector3d::Zero()) {
  Part b;
  b.size_m = size_m;
  b.X_WP = Eigen::Isometry3d::Identity();
  b.X_WP.linear() = tubeplan::scene::RotationFromRpy(rpy_rad);
  b.X_WP.translation() = position_m;
  return b;
}

}  // namespace

TEST_CASE("The broad phase finds exactly the pairs every pair's test finds", "[scene]") {
  // Random turned boxes, dense enough that many touch or overlap: 300 parts, 44 850 pairs.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> at(0.0, 0.2), size(0.002, 0.03), turn(-3.0, 3.0);
  std::vector<Part> parts;
  for (int i = 0; i < 300; ++i)
    parts.push_back(Box({size(random), size(random), size(random)},
                        {at(random), at(random), at(random)},
                        i % 3 == 0 ? Eigen::Vector3d(turn(random), turn(random), turn(random))
                                   : Eigen::Vector3d::Zero()));
  // Two that only touch face to face: not an overlap.
  parts.push_back(Box({0.01, 0.01, 0.01}, {1.0, 1.0, 1.0}));
  parts.push_back(Box({0.01, 0.01, 0.01}, {1.01, 1.0, 1.0}));
  std::vector<std::pair<std::size_t, std::size_t>> every;
  for (std::size_t i = 0; i < parts.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (tubeplan::scene::BoxesOverlap(parts[j], parts[i], 1e-9)) every.emplace_back(i, j);
  REQUIRE(every.size() > 20);  // the test means something
  CHECK(tubeplan::scene::OverlappingParts(parts, 1e-9) == every);
}

TEST_CASE("The straight tube's overlap with a box is exact", "[scene]") {
  using tubeplan::scene::StraightTubeOverlap;
  // The tube along world +y from the origin: roll -90 deg turns the held frame's z onto +y.
  Eigen::Isometry3d X_WH = Eigen::Isometry3d::Identity();
  X_WH.linear() = tubeplan::scene::RotationFromRpy({-std::numbers::pi / 2, 0.0, 0.0});
  const double r = 0.008, l = 0.150;
  // A floor whose top is 5 mm below the axis: 3 mm into the tube.
  CHECK(StraightTubeOverlap(X_WH, r, l, Box({0.1, 0.3, 0.01}, {0, 0, -0.010}), 1e-9).value() ==
        Approx(0.003).margin(1e-12));
  // Its top exactly at the tube's side: touching, not overlapping.
  CHECK_FALSE(StraightTubeOverlap(X_WH, r, l, Box({0.1, 0.3, 0.01}, {0, 0, -0.013}), 1e-9));
  // A box beyond the tip's flat end (but within a capsule's round end) does not reach it; one
  // behind the held end neither.
  CHECK_FALSE(StraightTubeOverlap(X_WH, r, l, Box({0.02, 0.02, 0.02}, {0, 0.161, 0}), 1e-9));
  CHECK_FALSE(StraightTubeOverlap(X_WH, r, l, Box({0.02, 0.02, 0.02}, {0, -0.0101, 0}), 1e-9));
  // A box the axis passes through: the whole radius.
  CHECK(StraightTubeOverlap(X_WH, r, l, Box({0.02, 0.02, 0.02}, {0, 0.1, 0}), 1e-9).value() == r);
  // A bar turned 45 deg about the axis, an edge towards it and 6 mm from it: 2 mm into the tube.
  const double half_diagonal = 0.005 * std::sqrt(2.0);
  const Part turned =
      Box({0.01, 0.3, 0.01}, {0.006 + half_diagonal, 0, 0}, {0.0, std::numbers::pi / 4, 0.0});
  CHECK(StraightTubeOverlap(X_WH, r, l, turned, 1e-9).value() == Approx(0.002).margin(1e-12));
  // Only a corner region of a box near the tip counts: its piece between the end planes.
  CHECK(StraightTubeOverlap(X_WH, r, l, Box({0.02, 0.02, 0.02}, {0, 0.150 + 0.0099, 0.015}), 1e-9)
            .value() == Approx(0.003).margin(1e-12));
}
