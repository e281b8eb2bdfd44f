// The accuracy study's reference rod (reference/planar_rod.hpp) judged from outside: Mattiasson's
// published table (docs/models.md), the closed-form elastica of model/ (elliptic integrals, a
// different method), its own order of convergence, and the penalty contact law at equilibrium.
#include <cmath>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/model/elastica.hpp>
#include <tubeplan/reference/planar_rod.hpp>

using namespace tubeplan;

namespace {

// Dimensionless cantilever (l = 1, EI = 1) held at the origin along +z, a dead load alpha along +x.
reference::RodSolution TipLoaded(double alpha, int segments) {
  const reference::PlanarRod rod{1.0, 1.0, 0.0, segments};
  reference::Loading loading;
  loading.tip_force_N = {alpha, 0.0};
  return reference::SolveRod(rod, loading);
}

}  // namespace

TEST_CASE("Reference rod reproduces Mattiasson's table", "[reference]") {
  struct Row {
    double alpha, v, h;
  };
  // Mattiasson 1981, Table 1 (docs/models.md, "Mattiasson's table"), printed to 5 digits.
  for (const Row row : {Row{1, 0.30172, 0.05643}, Row{2, 0.49346, 0.16064},
                        Row{5, 0.71379, 0.38763}, Row{10, 0.81061, 0.55500}}) {
    const reference::RodSolution coarse = TipLoaded(row.alpha, 128);
    const reference::RodSolution fine = TipLoaded(row.alpha, 256);
    REQUIRE(coarse.converged);
    REQUIRE(fine.converged);
    const double v = reference::Richardson2(coarse.tip_m.x(), fine.tip_m.x());
    const double h = reference::Richardson2(1.0 - coarse.tip_m.y(), 1.0 - fine.tip_m.y());
    INFO("alpha " << row.alpha << ": v " << v << ", h " << h);
    // Half a unit in the table's last printed digit.
    CHECK(std::abs(v - row.v) <= 0.5e-5 + 1e-9);
    CHECK(std::abs(h - row.h) <= 0.5e-5 + 1e-9);
  }
}

TEST_CASE("Reference rod converges at second order to the closed-form elastica", "[reference]") {
  for (const double alpha : {0.5, 5.0, 50.0}) {
    const model::ElasticaSolution exact = model::SolveElastica(alpha, 0.0);
    std::vector<double> err_v, err_h, err_angle;
    for (const int N : {32, 64, 128, 256}) {
      const reference::RodSolution s = TipLoaded(alpha, N);
      REQUIRE(s.converged);
      err_v.push_back(std::abs(s.tip_m.x() - exact.tip.deflection));
      err_h.push_back(std::abs(1.0 - s.tip_m.y() - exact.tip.shortening));
      err_angle.push_back(std::abs(s.tip_angle_rad - exact.tip.tip_angle_rad));
    }
    for (std::size_t i = 1; i < err_v.size(); ++i) {
      INFO("alpha " << alpha << " N " << (32 << i) << ": errors " << err_v[i] << " " << err_h[i]
                    << " " << err_angle[i]);
      // Halving h divides a second-order error by 4; the observed order lies within 0.15 of 2
      // once N >= 64 (the next term of the error expansion, O(h^4), is below 4 % of it there).
      CHECK(std::log2(err_v[i - 1] / err_v[i]) == Approx(2.0).margin(0.15));
      CHECK(std::log2(err_h[i - 1] / err_h[i]) == Approx(2.0).margin(0.15));
      CHECK(std::log2(err_angle[i - 1] / err_angle[i]) == Approx(2.0).margin(0.15));
    }
  }
}

TEST_CASE("Reference rod: a side on an edge, penalty law and coupling at equilibrium",
          "[reference]") {
  // Steel tube, edge at a = 0.2 m on the +x side, the hand moved towards it: small deflection,
  // so the force follows the springs in series (coupling, 3EI/a^3 bending, contact K).
  const double EI = 200e9 * M_PI / 4 * (std::pow(3e-3, 4) - std::pow(2.5e-3, 4));
  const reference::PlanarRod rod{0.3, EI, 3e-3, 128};
  reference::Loading loading;
  loading.coupling_N_per_m = 400.0;
  loading.law = {1e4, 1e-3};
  const double a = 0.2, d0 = 0.5e-3;
  loading.obstacles.push_back({reference::ObstacleKind::kEdge, {3e-3 + d0, a}, {}, 0.0, 0.0});
  const double delta = 1e-3;
  loading.hand_m = {delta, 0.0};
  const reference::RodSolution s = reference::SolveRod(rod, loading);
  REQUIRE(s.converged);
  const double k_series = 1.0 / (1.0 / 400.0 + a * a * a / (3.0 * EI) + 1.0 / 1e4);
  const double expected = (delta + 1e-3 - d0) * k_series;
  // Geometric nonlinearity at a slope of ~3e-3 rad: relative 1e-5; the discretisation of the
  // rod at N = 128 (the edge's arc position is resolved exactly): 1e-4.
  CHECK(-s.contact_force_N.x() == Approx(expected).epsilon(2e-4));
  // The penalty law at the solved distance, and equilibrium with the coupling spring.
  CHECK(s.obstacle_force_N[0].norm() ==
        Approx(1e4 * (1e-3 - s.obstacle_distance_m[0])).epsilon(1e-9));
  CHECK((400.0 * (loading.hand_m - s.state.held_m) + s.contact_force_N).norm() < 1e-9);
}
