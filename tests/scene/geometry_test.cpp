// The geometry a scene is checked with: the broad phase finds exactly the overlapping pairs a
// comparison of every pair finds.
#include <cmath>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/scene/geometry.hpp>

namespace {

using tubeplan::scene::BoxPart;

BoxPart Box(const Eigen::Vector3d& size_m, const Eigen::Vector3d& position_m,
            const Eigen::Vector3d& rpy_rad = Eigen::Vector3d::Zero()) {
  BoxPart b;
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
  std::vector<BoxPart> parts;
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

