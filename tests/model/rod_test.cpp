// Tests of the discrete rod (model/rod.hpp), the large-deflection model of loadings the elastica
// does not cover. References from outside the rod: Mattiasson's published table (physics.md),
// the closed-form elastica (elliptic integrals, model/elastica.hpp: another method entirely),
// the textbook beam-column compliances (Timoshenko & Gere) under an axial load, the linear
// cantilever, and invariants of statics (the root moment of the loads, Maxwell-Betti).

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include <tubeplan/model/elastica.hpp>
#include <tubeplan/model/rod.hpp>

namespace {

using tubeplan::model::Rod;
using tubeplan::model::RodLoad;
using tubeplan::model::RodSamples;
using tubeplan::model::RodSolution;

constexpr double kPi = std::numbers::pi;

// A force on the centreline (Eigen's vectors are not zeroed by {}: say it).
RodLoad At(double s_m, const Eigen::Vector3d& f_N) {
  return RodLoad{s_m, f_N, Eigen::Vector3d::Zero()};
}

// Tip of a unit rod (E I = 1, l = 1) under a tip force: centre at s = 1.
Eigen::Vector3d Tip(const Rod& rod, const std::vector<RodLoad>& loads, RodSolution& solution) {
  solution = rod.Solve(loads, Eigen::Matrix3d::Identity());
  std::array<double, 1> s{1.0};
  std::array<Eigen::Vector3d, 1> p;
  rod.Shape(loads, solution, RodSamples{s, p, {}});
  return p[0];
}

// A bent rod under three loads in 3D, the first and last with offsets if asked (the surface
// points of a side contact and a rim): the compliance tests' loading, for the shipped rubber
// tube (E I = 8.2e-3 N m^2, l = 0.15 m).
std::vector<RodLoad> ThreeLoads(bool offsets) {
  return {{0.05, Eigen::Vector3d(0.05, -0.02, 0.01),
           offsets ? Eigen::Vector3d(-0.008, 0, 0) : Eigen::Vector3d::Zero()},
          {0.11, Eigen::Vector3d(-0.02, 0.04, -0.03), Eigen::Vector3d::Zero()},
          {0.15, Eigen::Vector3d(0.03, 0.01, -0.05),
           offsets ? Eigen::Vector3d(0, 0.008, 0) : Eigen::Vector3d::Zero()}};
}

// The shipped rubber tube's rod (steps of l/200) solved under ThreeLoads, and its compliance.
struct ThreeLoadRod {
  explicit ThreeLoadRod(bool offsets, tubeplan::model::RodEndMoment* moment = nullptr)
      : rod(8.2e-3, 0.15 / 200.0),
        loads(ThreeLoads(offsets)),
        solution(rod.Solve(loads, Eigen::Matrix3d::Identity())) {
    REQUIRE(solution.converged);
    REQUIRE(rod.Compliance(loads, solution, w, end_turn, moment));
  }
  Rod rod;
  std::vector<RodLoad> loads;
  RodSolution solution;
  std::array<Eigen::Matrix3d, 9> w;
  std::array<Eigen::Matrix3d, 3> end_turn;
};

// Solves of loads stepped by +step and -step (plus, minus) from the solution's end frame, and
// the end section's turn between them per unit of the load (Q -> Exp(turn) Q).
struct SteppedSolves {
  RodSolution plus, minus;
  Eigen::Vector3d turn;
};
SteppedSolves SolveStepped(const Rod& rod, const std::vector<RodLoad>& plus,
                           const std::vector<RodLoad>& minus, const RodSolution& solution,
                           double step) {
  SteppedSolves out{rod.Solve(plus, solution.end_R), rod.Solve(minus, solution.end_R),
                    Eigen::Vector3d::Zero()};
  REQUIRE(out.plus.converged);
  REQUIRE(out.minus.converged);
  const Eigen::AngleAxisd turned(out.plus.end_R * out.minus.end_R.transpose());
  out.turn = turned.angle() * turned.axis() / (2.0 * step);
  return out;
}

// Load i's surface point's central difference between two solves (plus, minus) of loads whose
// first ones are `loads`, per unit of the step 2 `step`: the offset turned with its section from
// the unperturbed solution's frame.
Eigen::Vector3d SurfaceDifference(const Rod& rod, const std::vector<RodLoad>& loads,
                                  const RodSolution& solution, const std::vector<RodLoad>& plus,
                                  const RodSolution& sp, const std::vector<RodLoad>& minus,
                                  const RodSolution& sm, int i, double step) {
  const auto surface = [&](const std::vector<RodLoad>& ls, const RodSolution& sol) {
    std::array<double, 1> s{ls[std::size_t(i)].s_m};
    std::array<Eigen::Vector3d, 1> p;
    std::array<Eigen::Matrix3d, 1> R;
    rod.Shape(ls, sol, RodSamples{s, p, R});
    return std::pair{p[0], R[0]};
  };
  const auto [p0, R0] = surface(loads, solution);
  const auto [pp, Rp] = surface(plus, sp);
  const auto [pm, Rm] = surface(minus, sm);
  const Eigen::Vector3d r = loads[std::size_t(i)].r_m;
  return ((pp + Rp * R0.transpose() * r) - (pm + Rm * R0.transpose() * r)) / (2.0 * step);
}

}  // namespace

TEST_CASE("Rod: Mattiasson's tip deflections and shortenings under a dead lateral tip load",
          "[rod]") {
  // The published table has 5 decimals (rounding 5e-6); the rod's second-order error at steps
  // of l/2000 is below 1e-6 at alpha = 10 (measured by the order test below): 2e-5 holds both.
  const Rod rod(1.0, 1.0 / 2000.0);
  struct Row {
    double alpha, v, h;
  };
  for (const Row row : {Row{1, 0.30172, 0.05643}, Row{2, 0.49346, 0.16064},
                        Row{5, 0.71379, 0.38763}, Row{10, 0.81061, 0.55500}}) {
    INFO("alpha = " << row.alpha);
    RodSolution solution;
    const Eigen::Vector3d tip = Tip(rod, {At(1.0, Eigen::Vector3d(row.alpha, 0, 0))}, solution);
    REQUIRE(solution.converged);
    CHECK(tip.x() == Approx(row.v).margin(2e-5));
    CHECK(1.0 - tip.z() == Approx(row.h).margin(2e-5));
    CHECK(std::abs(tip.y()) < 1e-12);  // a load along x bends in the xz plane only
  }
}

TEST_CASE("Rod: second-order convergence to the closed-form elastica, any load direction",
          "[rod]") {
  // The exact elastica by elliptic integrals (another method), at alpha = 5 and load angles from
  // a lateral push to a mostly compressive one (the first mode). Halving the step must divide
  // the error by 4 (second order: the midpoint curvature of each arc), within 3.3 .. 4.7 for
  // the higher-order terms at these step sizes.
  for (const double psi : {0.0, 0.6, -0.6, -1.2}) {
    INFO("psi = " << psi);
    const double alpha = 5.0;
    const tubeplan::model::ElasticaSolution exact = tubeplan::model::SolveElastica(alpha, psi);
    // The elastica's load: |F| (cos psi x + sin psi z).
    const std::vector<RodLoad> loads{
        At(1.0, Eigen::Vector3d(alpha * std::cos(psi), 0.0, alpha * std::sin(psi)))};
    std::array<double, 3> error{};
    for (int k = 0; k < 3; ++k) {
      const Rod rod(1.0, 1.0 / (50.0 * (1 << k)));
      RodSolution solution;
      const Eigen::Vector3d tip = Tip(rod, loads, solution);
      REQUIRE(solution.converged);
      error[std::size_t(k)] =
          std::hypot(tip.x() - exact.tip.deflection, (1.0 - tip.z()) - exact.tip.shortening);
      // The energy is the elastica's E I / l * energy (here E I = l = 1).
      CHECK(solution.energy_J == Approx(exact.tip.energy).epsilon(2e-2));
    }
    CHECK(error[0] / error[1] == Approx(4.0).margin(0.7));
    CHECK(error[1] / error[2] == Approx(4.0).margin(0.7));
    CHECK(error[2] < 2e-4);
  }
}

TEST_CASE("Rod: large loads (alpha to 100) by continuation and by warm starts, on the first mode",
          "[rod]") {
  // From the straight rod the solve grows the load in steps (continuation) within its work cap
  // (Rod::kMaxIterations): alpha = 60 fits. At alpha = 100 a cold start may run out of it, and
  // must then say so rather than return another branch; from a nearby solution (a tick's warm
  // start) it converges. Curvature ~14 at the root at alpha = 100: the step's second-order error
  // at l/2000 is below 1e-5 there (2.5e-5 at l/500 in the convergence test's scaling).
  const Rod rod(1.0, 1.0 / 2000.0);
  const auto check = [&](double alpha, const RodSolution& solution) {
    const tubeplan::model::ElasticaSolution exact = tubeplan::model::SolveElastica(alpha, 0.0);
    std::array<double, 1> s{1.0};
    std::array<Eigen::Vector3d, 1> p;
    const std::vector<RodLoad> loads{At(1.0, Eigen::Vector3d(alpha, 0, 0))};
    rod.Shape(loads, solution, RodSamples{s, p, {}});
    CHECK(p[0].x() == Approx(exact.tip.deflection).margin(1e-4));
    CHECK(1.0 - p[0].z() == Approx(exact.tip.shortening).margin(1e-4));
    // Inextensible: the tip can never be further from the clamp than the rod is long.
    CHECK(p[0].norm() <= 1.0);
  };
  const RodSolution cold60 = rod.Solve(std::vector<RodLoad>{At(1.0, Eigen::Vector3d(60.0, 0, 0))},
                                       Eigen::Matrix3d::Identity());
  REQUIRE(cold60.converged);
  check(60.0, cold60);
  const RodSolution cold100 = rod.Solve(std::vector<RodLoad>{At(1.0, Eigen::Vector3d(100.0, 0, 0))},
                                        Eigen::Matrix3d::Identity());
  if (cold100.converged) check(100.0, cold100);
  RodSolution warm = cold60;
  for (double alpha = 65.0; alpha <= 100.0; alpha += 5.0) {
    warm = rod.Solve(std::vector<RodLoad>{At(1.0, Eigen::Vector3d(alpha, 0, 0))}, warm);
    REQUIRE(warm.converged);
    check(alpha, warm);
  }
}

TEST_CASE("Rod: tangent compliance of the tip under an axial load, against the beam-column",
          "[rod]") {
  // A cantilever under an axial force P has the lateral tip compliance
  //   compression: (tan(k l) - k l) / (k^3 E I),  tension: (k l - tanh(k l)) / (k^3 E I),
  // k = sqrt(P / (E I)) (Timoshenko & Gere, beam-columns), l^3 / (3 E I) without P; the rod is
  // inextensible, so the axial compliance is zero. The compliance is the discrete map's exact
  // derivative (its rounding ~1e-13 relative).
  const double EI = 2.0, l = 0.5;
  const Rod rod(EI, l / 400.0);
  const double euler_N = kPi * kPi * EI / (4.0 * l * l);
  for (const double P : {0.0, 0.5 * euler_N, 0.9 * euler_N, -2.0 * euler_N}) {
    INFO("axial load " << P << " N (compression > 0)");
    const std::vector<RodLoad> loads{At(l, Eigen::Vector3d(0.0, 0.0, -P))};
    const RodSolution solution = rod.Solve(loads, Eigen::Matrix3d::Identity());
    REQUIRE(solution.converged);
    std::array<Eigen::Matrix3d, 1> w;
    REQUIRE(rod.Compliance(loads, solution, w));
    double expected = l * l * l / (3.0 * EI);
    if (P > 0.0) {
      const double k = std::sqrt(P / EI);
      expected = (std::tan(k * l) - k * l) / (k * k * k * EI);
    } else if (P < 0.0) {
      const double k = std::sqrt(-P / EI);
      expected = (k * l - std::tanh(k * l)) / (k * k * k * EI);
    }
    // The discretisation's own error in the compliance is second order: ~1e-5 at l/400.
    CHECK(w[0](0, 0) == Approx(expected).epsilon(1e-4));
    CHECK(w[0](1, 1) == Approx(expected).epsilon(1e-4));
    CHECK(std::abs(w[0](2, 2)) < 1e-6 * expected);
    CHECK(std::abs(w[0](0, 1)) < 1e-6 * expected);
  }
}

TEST_CASE("Rod: a tip held sideways under an eccentric push: the propped beam-column", "[rod]") {
  // A cantilever pushed along its axis by P at an offset e (the moment M0 = P e) and held at its
  // tip sideways: the lateral force that holds it is, by the beam-column (Timoshenko & Gere),
  //   H = M0 (cos kl - 1) / (sin(kl) / k - l cos kl),  k = sqrt(P / (E I)),
  // 3 M0 / (2 l) as P -> 0, singular at the propped column's buckling load tan(kl) = kl
  // (20.19 E I / l^2, 8.2 times the free end's Euler load). Past the free end's load the
  // dead-load solve has no straight branch to follow; held, the rod stays straight to there.
  const double EI = 2.0, l = 0.5, e = 1e-4 * l;
  const Rod rod(EI, l / 400.0);
  const double euler_N = kPi * kPi * EI / (4.0 * l * l);
  for (const double times : {0.5, 1.0, 1.5, 3.0, 6.0}) {
    const double P = times * euler_N, k = std::sqrt(P / EI);
    INFO("P = " << times << " times the free end's Euler load");
    std::vector<RodLoad> loads{
        RodLoad{l, Eigen::Vector3d(0.0, 0.0, -P), Eigen::Vector3d(0.0, e, 0.0)}};
    const std::array<Eigen::Vector2d, 1> pinned{Eigen::Vector2d::Zero()};
    std::array<double, 1> s{l};
    std::array<Eigen::Vector3d, 1> tip;
    RodSolution start;  // the straight rod
    const RodSolution solution = rod.SolvePinned(loads, start, pinned, RodSamples{s, tip, {}});
    REQUIRE(solution.converged);
    // Held within the solve's tolerance (1e-10 of the end's arc position), the push unchanged.
    CHECK(tip[0].head<2>().norm() <= 1e-10 * l);
    CHECK(loads[0].f_N.z() == -P);
    const double M0 = P * e;
    const double expected =
        M0 * (std::cos(k * l) - 1.0) / (std::sin(k * l) / k - l * std::cos(k * l));
    // The discretisation's error is second order (~1e-5 at l/400, as the compliance's); the
    // offset moment's nonlinearity is of the deflection squared, ~1e-8.
    CHECK(std::abs(loads[0].f_N.y()) == Approx(std::abs(expected)).epsilon(1e-4));
    CHECK(std::abs(loads[0].f_N.x()) <= 1e-9 * std::abs(expected));
    // The held forces as dead loads, solved from the held solution's end: the same tip.
    const RodSolution dead = rod.Solve(loads, solution);
    REQUIRE(dead.converged);
    std::array<Eigen::Vector3d, 1> tip_dead;
    rod.Shape(loads, dead, RodSamples{s, tip_dead, {}});
    CHECK((tip_dead[0] - tip[0]).norm() <= 1e-9 * l);
  }
  // Three loads given out of arc order, each held at its own (x, y): every centre lands on its
  // own target (a mix-up of the caller's order and the arc order would put them on another's),
  // and the held forces as dead loads give the same shape.
  {
    std::vector<RodLoad> three{At(l, Eigen::Vector3d(0.0, 0.0, -2.0 * euler_N)),
                               At(0.3 * l, Eigen::Vector3d(0.0, 0.0, 0.0)),
                               At(0.6 * l, Eigen::Vector3d(0.0, 0.0, -0.5 * euler_N))};
    const std::array<Eigen::Vector2d, 3> at{Eigen::Vector2d(1e-3 * l, 0.0),
                                            Eigen::Vector2d(0.0, 2e-4 * l),
                                            Eigen::Vector2d(-3e-4 * l, 1e-4 * l)};
    std::array<double, 3> s3{0.3 * l, 0.6 * l, l};
    std::array<Eigen::Vector3d, 3> p3;
    const RodSolution held = rod.SolvePinned(three, RodSolution{}, at, RodSamples{s3, p3, {}});
    REQUIRE(held.converged);
    // The drawn shape steps through its samples too: within the discretisation's error of the
    // solve's own rod (~1e-7 l here), far below the core's eps / 10.
    CHECK((p3[0].head<2>() - at[1]).norm() <= 1e-6 * l);
    CHECK((p3[1].head<2>() - at[2]).norm() <= 1e-6 * l);
    CHECK((p3[2].head<2>() - at[0]).norm() <= 1e-6 * l);
    const RodSolution dead = rod.Solve(three, held);
    REQUIRE(dead.converged);
    std::array<Eigen::Vector3d, 3> q3;
    rod.Shape(three, dead, RodSamples{s3, q3, {}});
    for (int k = 0; k < 3; ++k) CHECK((q3[std::size_t(k)] - p3[std::size_t(k)]).norm() <= 1e-6 * l);
  }
  // Offered a target no shape reaches (the end held 1.5 l sideways: beyond the rod's length), it
  // says so and leaves the loads as given.
  std::vector<RodLoad> loads{At(l, Eigen::Vector3d(0.0, 0.0, -1e-3))};
  const std::array<Eigen::Vector2d, 1> far{Eigen::Vector2d(1.5 * l, 0.0)};
  std::array<double, 1> s{l};
  std::array<Eigen::Vector3d, 1> tip;
  const RodSolution refused = rod.SolvePinned(loads, RodSolution{}, far, RodSamples{s, tip, {}});
  CHECK_FALSE(refused.converged);
  CHECK(loads[0].f_N == Eigen::Vector3d(0.0, 0.0, -1e-3));
}

TEST_CASE("Rod: compliance equals differences of full solves, and is symmetric (Maxwell-Betti)",
          "[rod]") {
  // A bent rod under three loads in 3D, two with offsets (the surface points of a side contact and
  // a rim). The compliance formula (derivatives of the shooting map with the root moment
  // eliminated) against central differences of complete solves: another computation of the same
  // derivative. Without offsets the loads are conservative and the compliance is symmetric.
  for (const bool offsets : {false, true}) {
    INFO((offsets ? "with offsets" : "centreline loads"));
    const ThreeLoadRod bent(offsets);
    const Rod& rod = bent.rod;
    const std::vector<RodLoad>& loads = bent.loads;
    const RodSolution& solution = bent.solution;
    const auto& w = bent.w;
    const auto& end_turn = bent.end_turn;
    double largest_turn = 0.0;
    for (const Eigen::Matrix3d& b : end_turn)
      largest_turn = std::max(largest_turn, b.cwiseAbs().maxCoeff());
    double largest = 0.0;
    for (const Eigen::Matrix3d& b : w) largest = std::max(largest, b.cwiseAbs().maxCoeff());
    const double dF = 1e-5;
    for (int j = 0; j < 3; ++j)
      for (int c = 0; c < 3; ++c) {
        std::vector<RodLoad> plus = loads, minus = loads;
        plus[std::size_t(j)].f_N[c] += dF;
        minus[std::size_t(j)].f_N[c] -= dF;
        const auto [sp, sm, turn] = SolveStepped(rod, plus, minus, solution, dF);
        // The end section's turn per force (the solve's predictor).
        CHECK((end_turn[std::size_t(j)].col(c) - turn).norm() < 2e-5 * largest_turn);
        for (int i = 0; i < 3; ++i) {
          const Eigen::Vector3d dp =
              SurfaceDifference(rod, loads, solution, plus, sp, minus, sm, i, dF);
          // The central differences' truncation (dF^2 / 6 of third derivatives) and the solves'
          // tolerance; the formula itself is exact to rounding (it once held forward differences
          // of relative step 1e-6, for which this tolerance was set).
          CHECK((w[std::size_t(i * 3 + j)].col(c) - dp).norm() < 2e-5 * largest);
        }
      }
    if (!offsets)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          CHECK((w[std::size_t(i * 3 + j)] - w[std::size_t(j * 3 + i)].transpose())
                    .cwiseAbs()
                    .maxCoeff() < 2e-5 * largest);
  }
}

TEST_CASE("Rod: an end moment's response equals differences of full solves under a couple",
          "[rod]") {
  // The moment directions of Rod::Compliance (the end section's turn, and each load's surface
  // point, per moment on the end) against central differences of complete solves with a couple
  // added at the end: two opposite forces, one at an offset, whose net force is zero and whose
  // moment a x g the solve applies as given. The same bent rod under three loads as above. For
  // centreline loads the response is the transpose of the end's turn per force (Maxwell-Betti).
  const double l = 0.15;
  for (const bool offsets : {false, true}) {
    INFO((offsets ? "with offsets" : "centreline loads"));
    tubeplan::model::RodEndMoment moment;
    const ThreeLoadRod bent(offsets, &moment);
    const Rod& rod = bent.rod;
    const std::vector<RodLoad>& loads = bent.loads;
    const RodSolution& solution = bent.solution;
    const auto& w = bent.w;
    const auto& end_turn = bent.end_turn;
    // The moment directions leave the force directions as they were, to the bit.
    std::array<Eigen::Matrix3d, 9> w_alone;
    std::array<Eigen::Matrix3d, 3> end_turn_alone;
    REQUIRE(rod.Compliance(loads, solution, w_alone, end_turn_alone));
    for (std::size_t k = 0; k < w.size(); ++k) CHECK(w[k] == w_alone[k]);
    for (std::size_t k = 0; k < end_turn.size(); ++k) CHECK(end_turn[k] == end_turn_alone[k]);
    const double largest_turn = moment.turn_per_Nm.cwiseAbs().maxCoeff();
    double largest = 0.0;
    for (int i = 0; i < 3; ++i)
      largest = std::max(largest, moment.w_per_Nm[std::size_t(i)].cwiseAbs().maxCoeff());
    const double dM = 1e-6, r = 0.008;  // N m; the couple's arm
    for (int c = 0; c < 3; ++c) {
      // a x g = dM e_c with a = r e_{c+1}, g = dM / r e_{c+2}.
      const Eigen::Vector3d a = r * Eigen::Vector3d::Unit((c + 1) % 3);
      const Eigen::Vector3d g = dM / r * Eigen::Vector3d::Unit((c + 2) % 3);
      std::vector<RodLoad> plus = loads, minus = loads;
      plus.push_back({l, g, a});
      plus.push_back({l, -g, Eigen::Vector3d::Zero()});
      minus.push_back({l, -g, a});
      minus.push_back({l, g, Eigen::Vector3d::Zero()});
      const auto [sp, sm, turn] = SolveStepped(rod, plus, minus, solution, dM);
      // As for the forces above: the differences' truncation and the solves' tolerance.
      CHECK((moment.turn_per_Nm.col(c) - turn).norm() < 2e-5 * largest_turn);
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d dp =
            SurfaceDifference(rod, loads, solution, plus, sp, minus, sm, i, dM);
        CHECK((moment.w_per_Nm[std::size_t(i)].col(c) - dp).norm() < 2e-5 * largest);
      }
    }
    // The discrete chain is in equilibrium at its nodes but not derived from an energy: its
    // asymmetry is 3.6e-7 of the largest coefficient at these steps (measured).
    if (!offsets)
      for (int i = 0; i < 3; ++i)
        CHECK((moment.w_per_Nm[std::size_t(i)] - end_turn[std::size_t(i)].transpose())
                  .cwiseAbs()
                  .maxCoeff() < 2e-5 * largest);
  }
}

TEST_CASE("Rod: an end moment on the straight rod is the linear cantilever's, exactly", "[rod]") {
  const double EI = 8.2e-3, l = 0.15;
  const Rod rod(EI, l / 200.0);
  // No force: a moment M on the end turns it by M l / (E I) and moves the point at s by
  // M s^2 / (2 E I) across (the steps' chords are exact for a turn linear in s); the rod does
  // not twist, so a moment along its axis does nothing.
  const std::vector<RodLoad> none{At(0.06, Eigen::Vector3d::Zero()),
                                  At(l, Eigen::Vector3d::Zero())};
  const RodSolution straight = rod.Solve(none, Eigen::Matrix3d::Identity());
  REQUIRE(straight.converged);
  std::array<Eigen::Matrix3d, 4> w;
  tubeplan::model::RodEndMoment moment;
  REQUIRE(rod.Compliance(none, straight, w, {}, &moment));
  const Eigen::Matrix3d turn = Eigen::Vector3d(l / EI, l / EI, 0.0).asDiagonal();
  CHECK((moment.turn_per_Nm - turn).cwiseAbs().maxCoeff() < 1e-12 * l / EI);
  for (int i = 0; i < 2; ++i) {
    const double s = none[std::size_t(i)].s_m, u = s * s / (2.0 * EI);
    Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
    expected(0, 1) = u;   // about +y: towards +x
    expected(1, 0) = -u;  // about +x: towards -y
    CHECK((moment.w_per_Nm[std::size_t(i)] - expected).cwiseAbs().maxCoeff() < 1e-12 * l * l / EI);
  }
}

TEST_CASE("Rod: statics and length hold exactly on the discrete chain", "[rod]") {
  // The root moment of the solution is the loads' moment about the clamp at their deformed
  // points (the moment update is exact for each chord), and the chain keeps its length: no
  // sample is further along the rod than its arc position allows.
  const double EI = 8.2e-3, l = 0.15;
  const Rod rod(EI, l / 48.0);
  const std::vector<RodLoad> loads{
      {0.09, Eigen::Vector3d(1.5, -0.4, -2.0), Eigen::Vector3d(0.008, 0, 0)},
      {0.15, Eigen::Vector3d(-0.3, 1.0, -1.0), Eigen::Vector3d(0, -0.008, 0)}};
  const RodSolution solution = rod.Solve(loads, Eigen::Matrix3d::Identity());
  REQUIRE(solution.converged);
  std::array<double, 2> s{0.09, 0.15};
  std::array<Eigen::Vector3d, 2> p;
  rod.Shape(loads, solution, RodSamples{s, p, {}});
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (int j = 0; j < 2; ++j)
    moment += (p[std::size_t(j)] + loads[std::size_t(j)].r_m).cross(loads[std::size_t(j)].f_N);
  const double scale = 2.5 * 0.15;  // |F| l
  CHECK((moment - solution.root_moment_Nm).norm() < 1e-9 * scale);
  // Length: sampled densely, consecutive points are never further apart than their arc.
  std::vector<double> dense(301);
  std::vector<Eigen::Vector3d> q(301);
  for (std::size_t k = 0; k < dense.size(); ++k) dense[k] = l * double(k) / 300.0;
  rod.Shape(loads, solution, RodSamples{dense, q, {}});
  double length = 0.0;
  for (std::size_t k = 1; k < q.size(); ++k) {
    const double chord = (q[k] - q[k - 1]).norm();
    CHECK(chord <= (l / 300.0) * (1.0 + 1e-12));
    length += chord;
  }
  CHECK(length > 0.99 * l);  // and it is bent (a chord falls short of its arc) by ~1 % at most
  CHECK(solution.max_moment_Nm > 0.0);
}

TEST_CASE("Rod: no load, no bending; small loads give the linear cantilever", "[rod]") {
  const double EI = 1.0, l = 1.0;
  // Steps of l/1000: the trapezoid in the deflection's integral errs by h^2/12 of F l^3/(E I),
  // 2.5e-7 of the deflection, inside the 1e-6 asked.
  const Rod rod(EI, l / 1000.0);
  const RodSolution none = rod.Solve({}, Eigen::Matrix3d::Identity());
  CHECK(none.converged);
  CHECK(none.energy_J == 0.0);
  // A lateral tip force F at alpha = 1e-4: deflection F l^3 / (3 E I) to the series' next term,
  // (4/105) alpha^3, far below the 1e-9 asked; a couple M at the tip (as an offset force
  // pair would give): M l^2 / (2 E I).
  const double F = 1e-4;
  RodSolution solution;
  const Eigen::Vector3d tip = Tip(rod, {At(1.0, Eigen::Vector3d(0, F, 0))}, solution);
  CHECK(tip.y() == Approx(F / 3.0).epsilon(1e-6));
  const double r = 0.01;  // a force F along -x at offset +z r: moment r z x (-F x) = -r F y
  const std::vector<RodLoad> couple{{1.0, Eigen::Vector3d(-F, 0, 0), Eigen::Vector3d(0, 0, r)},
                                    {1.0, Eigen::Vector3d(F, 0, 0), Eigen::Vector3d::Zero()}};
  const RodSolution c = rod.Solve(couple, Eigen::Matrix3d::Identity());
  std::array<double, 1> s{1.0};
  std::array<Eigen::Vector3d, 1> p;
  rod.Shape(couple, c, RodSamples{s, p, {}});
  // Moment -r F about y bends the tip towards -x: x = -r F l^2 / (2 E I).
  CHECK(p[0].x() == Approx(-r * F / 2.0).epsilon(1e-6));
}

TEST_CASE("Rod: the shooting map's Jacobian (forward sensitivities) equals its central differences",
          "[rod]") {
  // Newton's Jacobian is carried through the integration (the derivative of each discrete step)
  // and handed on, inverted, in RodSolution::jacobian_inv, at the solution: a solve from a
  // nearby end frame without a Jacobian (no chord steps, no continuation) is Newton's alone.
  // The shooting map
  // itself is reachable through Shape: the section frame at s = 0 for a given end frame, the
  // residual twice its quaternion's vector part. Central differences of that map: with turns of
  // 1e-5 their truncation (delta^2 / 6 times third derivatives of order alpha <= 10) is ~2e-10
  // and their rounding (1e-16 per step, <= 200 steps, over 1e-5) ~2e-9 of |J| ~ 1 (measured:
  // 4e-12 and 7e-10): 1e-7 holds both. Two rods: the rubber tube under three loads in 3D with
  // offsets (steps of l/200, the small-turn series), and a unit rod at alpha = 9.5 in 20 steps
  // (turns of ~0.4 rad a step: the trigonometric branches), where a term left out of the
  // linearisation shows (measured: the chord's change of length 3e-4, the second-order term of
  // the turn's Jacobian 2e-3).
  const auto residual = [](const Rod& rod, const std::vector<RodLoad>& loads,
                           const RodSolution& solution, const Eigen::Matrix3d& end_R) {
    RodSolution moved = solution;
    moved.end_R = end_R;
    std::array<double, 1> s{0.0};
    std::array<Eigen::Vector3d, 1> p;
    std::array<Eigen::Matrix3d, 1> R;
    rod.Shape(loads, moved, RodSamples{s, p, R});
    Eigen::Quaterniond q(R[0]);
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    return Eigen::Vector3d(2.0 * q.vec());
  };
  const double l = 0.15;
  struct Case {
    Rod rod;
    std::vector<RodLoad> loads;
  };
  const std::array<Case, 2> cases{
      Case{Rod(8.2e-3, l / 200.0),
           {{0.05, Eigen::Vector3d(0.05, -0.02, 0.01), Eigen::Vector3d(-0.008, 0, 0)},
            {0.11, Eigen::Vector3d(-0.02, 0.04, -0.03), Eigen::Vector3d::Zero()},
            {0.15, Eigen::Vector3d(0.03, 0.01, -0.05), Eigen::Vector3d(0, 0.008, 0)}}},
      Case{Rod(1.0, 1.0 / 20.0), {At(1.0, Eigen::Vector3d(9.0, 0.0, 3.0))}}};
  for (const Case& c : cases) {
    INFO("steps of " << c.rod.max_step_m() << " m");
    std::vector<RodLoad> nearby = c.loads;
    for (RodLoad& load : nearby) load.f_N *= 0.98;
    const RodSolution start = c.rod.Solve(nearby, Eigen::Matrix3d::Identity());
    REQUIRE(start.converged);
    const RodSolution solution = c.rod.Solve(c.loads, start.end_R);
    REQUIRE(solution.converged);
    REQUIRE(solution.iterations > 0);  // Newton ran: the Jacobian is its own
    REQUIRE(std::abs(solution.jacobian_inv.determinant()) > 0.0);
    const Eigen::Matrix3d J = solution.jacobian_inv.inverse();
    constexpr double kDelta_rad = 1e-5;
    Eigen::Matrix3d J_differences;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d turn = kDelta_rad * Eigen::Vector3d::Unit(k);
      const Eigen::Matrix3d plus =
          Eigen::AngleAxisd(turn.norm(), turn.normalized()).toRotationMatrix() * solution.end_R;
      const Eigen::Matrix3d minus =
          Eigen::AngleAxisd(-turn.norm(), turn.normalized()).toRotationMatrix() * solution.end_R;
      J_differences.col(k) =
          (residual(c.rod, c.loads, solution, plus) - residual(c.rod, c.loads, solution, minus)) /
          (2.0 * kDelta_rad);
    }
    INFO("J\n" << J << "\ndifferences\n" << J_differences);
    CHECK((J - J_differences).cwiseAbs().maxCoeff() < 1e-7 * J.cwiseAbs().maxCoeff());
  }
}

TEST_CASE("Rod: a solve given samples draws the shape Shape draws at its solution, to the bit",
          "[rod]") {
  // Solve with samples steps every integration through them, so the iterate it accepts last has
  // drawn exactly what Shape, integrating once more at the solution with the same samples, draws.
  // Any other iterate's samples (a rejected trial, an earlier accepted one, a step of the
  // continuation) differ from it by the solve's progress: far above the last bit.
  const Rod rod(1.0, 1.0 / 48.0);
  std::array<double, 49> s{};
  for (std::size_t k = 0; k < s.size(); ++k) s[k] = double(k) / 48.0;
  struct Case {
    const char* what;
    std::vector<RodLoad> loads;
    bool cold;  // from the straight rod (at alpha > 10: the continuation)
  };
  const std::vector<Case> cases = {
      {"tip load, alpha 2, warm", {At(1.0, Eigen::Vector3d(2.0, 0.5, -0.3))}, false},
      {"tip load, alpha 30, cold: continuation", {At(1.0, Eigen::Vector3d(30.0, 0.0, 0.0))}, true},
      {"line contact: two loads with offsets, and an axial push",
       {RodLoad{0.55, Eigen::Vector3d(0.0, -3.0, 0.4), Eigen::Vector3d(0.0, 0.05, 0.0)},
        RodLoad{0.97, Eigen::Vector3d(0.2, -2.0, -1.5), Eigen::Vector3d(0.0, 0.05, 0.0)}},
       false},
      {"last load short of the tip: samples beyond it straight",
       {At(0.6, Eigen::Vector3d(4.0, 1.0, 0.0))},
       true},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    // Warm: from a solution of loads 5 % smaller, as from last tick (chord steps, then Newton).
    RodSolution previous;
    if (!c.cold) {
      std::vector<RodLoad> smaller = c.loads;
      for (RodLoad& load : smaller) load.f_N *= 0.95;
      previous = rod.Solve(smaller, Eigen::Matrix3d::Identity());
      REQUIRE(previous.converged);
    }
    // NaN first: a sample left unwritten fails the comparison (NaN equals nothing).
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::array<Eigen::Vector3d, 49> drawn, shaped;
    std::array<Eigen::Matrix3d, 49> drawn_R, shaped_R;
    for (auto* p : {&drawn, &shaped}) p->fill(Eigen::Vector3d::Constant(nan));
    for (auto* R : {&drawn_R, &shaped_R}) R->fill(Eigen::Matrix3d::Constant(nan));
    const RodSolution solution = rod.Solve(c.loads, previous, RodSamples{s, drawn, drawn_R});
    REQUIRE(solution.converged);
    rod.Shape(c.loads, solution, RodSamples{s, shaped, shaped_R});
    int differing = 0;
    for (std::size_t k = 0; k < s.size(); ++k)
      if (drawn[k] != shaped[k] || drawn_R[k] != shaped_R[k]) ++differing;
    CHECK(differing == 0);
    // And it is a shape, not the straight rod.
    CHECK((drawn.back() - Eigen::Vector3d(0.0, 0.0, 1.0)).norm() > 0.05);
    // The breakpoints move the discrete rod only within its discretisation error (~1e-4 l at
    // steps of l/48, the order test above): the same loads solved without samples (measured:
    // 2.5e-16 where the two grids coincide, a tip load at s = l; 4.6e-6 l for the line contact).
    const RodSolution plain = rod.Solve(c.loads, previous);
    REQUIRE(plain.converged);
    CHECK((plain.end_p_m - solution.end_p_m).norm() < 1e-4);
  }
}

TEST_CASE("Rod: a solve refuses samples it would not draw", "[rod]") {
  // Integrate records only ascending samples from 0: anything else would leave the caller's
  // entries unwritten (Shape leaves them as they were; a solve copied scratch over them).
  const Rod rod(1.0, 1.0 / 48.0);
  const std::vector<RodLoad> loads = {At(1.0, Eigen::Vector3d(2.0, 0.0, 0.0))};
  std::array<Eigen::Vector3d, 3> p;
  for (const std::array<double, 3> s :
       {std::array<double, 3>{-0.1, 0.5, 1.0}, std::array<double, 3>{0.0, 0.6, 0.5},
        std::array<double, 3>{0.0, std::nan(""), 1.0}}) {
    CHECK_THROWS_AS(rod.Solve(loads, RodSolution{}, RodSamples{s, p, {}}), std::invalid_argument);
  }
  const std::array<double, 3> fine{0.0, 0.5, 1.0};
  CHECK(rod.Solve(loads, RodSolution{}, RodSamples{fine, p, {}}).converged);
}
