// The beam chain's internals against independent evaluations.
#include "core/beam_chain.hpp"  // private to the core (src/)

#include <cmath>

#include <catch2/catch.hpp>

using namespace tubeplan;

namespace {
scene::Scene RubberTube() {
  scene::Scene s;
  s.tube = {0.008, 0.005, 0.150, 3e6, 0.5};
  return s;
}
}  // namespace

TEST_CASE("Elastica nodes by Hermite interpolation stay within 2 um of the exact shape",
          "[core][beam]") {
  const scene::Scene s = RubberTube();
  const core::BeamChain beam(s);
  const double EI = beam.bending_stiffness_Nm2(), l = s.tube.length_m;
  for (const double alpha : {0.1, 1.0, 5.0, 10.0}) {
    for (const double s_load : {l, 0.6 * l}) {
      std::array<core::BeamLoad, core::kMaxLoads> loads{};
      // A tip load at 30 degrees to the lateral direction, alpha measured on the loaded length.
      const double F = alpha * EI / (s_load * s_load);
      loads[0] = {s_load,
                  F * Eigen::Vector3d(std::cos(0.5), std::sin(0.5) * 0.0, -std::sin(0.5)),
                  Eigen::Vector3d::Zero(),
                  0.0,
                  0,
                  0};
      std::array<bool, core::kMaxLoads> member{};
      member[0] = true;
      std::array<int, core::kMaxLoads> order{};
      int members = 0;
      const int groups = beam.Assign(loads, 1, member, order, members);
      REQUIRE(groups == 1);
      std::array<core::ElasticaSegment, core::kMaxLoads> segments{};
      const int count = beam.SolveElasticaChain(loads, 1, order, segments);
      std::array<Eigen::Vector3d, 49> nodes;
      beam.ElasticaNodes(segments, count, nodes);
      double worst_m = 0.0;
      for (std::size_t k = 0; k < nodes.size(); ++k) {
        const Eigen::Vector3d exact = beam.ElasticaPoint(segments, count, l * double(k) / 48.0);
        worst_m = std::max(worst_m, (nodes[k] - exact).norm());
      }
      INFO("alpha " << alpha << ", load at " << s_load);
      // 2 um: K (1e4 N/m) times it is 0.02 N of contact force, far below what a hand feels.
      CHECK(worst_m < 2e-6);
    }
  }
}
