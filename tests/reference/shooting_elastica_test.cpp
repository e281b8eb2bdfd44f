// The shooting reference (reference/shooting_elastica.hpp) judged from outside: Mattiasson's
// table and the elastica's closed forms (elliptic integrals of the standard library, a second
// method), the small-load and pure-moment limits, Euler's loads approached along the
// post-buckling branch, the segment rod of planar_rod.hpp (a third method) on a rim contact, and
// a stick-slip path of the rubber tube checked for equilibrium, the friction law and passivity.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/reference/planar_rod.hpp>
#include <tubeplan/reference/shooting_elastica.hpp>

namespace sh = tubeplan::reference::shooting;
using Eigen::Vector2d;

namespace {

constexpr double kPi = std::numbers::pi;

// Moment about +y of f applied at the lever r (x, z).
double MomentOf(const Vector2d& r, const Vector2d& f) { return r.y() * f.x() - r.x() * f.y(); }
Vector2d Section(double theta) { return {std::cos(theta), -std::sin(theta)}; }

sh::Obstacle MakeObstacle(sh::ObstacleKind kind, const Vector2d& point_m,
                          const Vector2d& normal = Vector2d::UnitY()) {
  sh::Obstacle ob;
  ob.kind = kind;
  ob.point_m = point_m;
  ob.normal = normal;
  return ob;
}

// Bisshopp and Drucker's cantilever under a dead tip load normal to its axis (l = 1): with
// m = (1 + sin theta0) / 2 and sin phi1 = 1 / sqrt(2m), sqrt(alpha) = K(m) - F(phi1 | m) fixes the
// tip rotation theta0, then the deflection and the shortening follow from E.
struct Cantilever {
  double deflection = 0.0, shortening = 0.0, tip_rotation_rad = 0.0;
};
Cantilever BisshoppDrucker(double alpha) {
  const auto terms = [](double theta0, double& k, double& phi1) {
    const double m = 0.5 * (1.0 + std::sin(theta0));
    k = std::sqrt(m);
    phi1 = std::asin(1.0 / std::sqrt(2.0 * m));
  };
  const auto mismatch = [&](double theta0) {
    double k = 0.0, phi1 = 0.0;
    terms(theta0, k, phi1);
    return std::comp_ellint_1(k) - std::ellint_1(k, phi1) - std::sqrt(alpha);
  };
  double lo = 1e-9, hi = kPi / 2 - 1e-12;  // the mismatch rises from - to + on (0, pi/2)
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (mismatch(mid) > 0.0 ? hi : lo) = mid;
  }
  Cantilever c;
  c.tip_rotation_rad = 0.5 * (lo + hi);
  double k = 0.0, phi1 = 0.0;
  terms(c.tip_rotation_rad, k, phi1);
  c.deflection = 1.0 - 2.0 / std::sqrt(alpha) * (std::comp_ellint_2(k) - std::ellint_2(k, phi1));
  c.shortening = 1.0 - std::sqrt(2.0 * std::sin(c.tip_rotation_rad) / alpha);
  return c;
}

// l = 1, EI = 1, held at the origin along +z, a dead load alpha along +x.
sh::Solution TipLoaded(double alpha) {
  sh::Setup setup;
  setup.tip_force_N = {alpha, 0.0};
  return sh::Solve(sh::Rod{1.0, 1.0, 0.0}, setup);
}

// The rubber tube of scenes/groove.yaml.
sh::Rod RubberTube() {
  const double r1 = 8e-3, r2 = 5e-3;
  return sh::Rod{0.15, 3e6 * kPi / 4 * (std::pow(r1, 4) - std::pow(r2, 4)), r1};
}

// A column clamped at the top (phi0 = pi, l = 1, EI = 1, r1 = 0) over the floor z = 0, lowered
// from 2 mm above it: first in steps of `fine_N` of penalty force (K = stiffness) to `fine_steps`
// of them, then `coarse` steps to a travel `travel_m`, and back up along the same holds when
// `unload`.
std::vector<sh::Hold> ColumnHolds(double stiffness, double fine_N, int fine_steps, int coarse,
                                  double travel_m, bool unload) {
  std::vector<double> travel{0.0, 1e-3};
  for (int i = 1; i <= fine_steps; ++i) travel.push_back(1e-3 + i * fine_N / stiffness);
  const double knee = travel.back();
  for (int i = 1; i <= coarse; ++i) travel.push_back(knee + i * (travel_m - knee) / coarse);
  if (unload)
    for (int i = int(travel.size()) - 2; i >= 0; --i) travel.push_back(travel[std::size_t(i)]);
  std::vector<sh::Hold> holds;
  for (const double t : travel) holds.push_back({{0.0, 1.002 - t}, kPi});
  return holds;
}

sh::Setup ColumnOnFloor(double stiffness, double static_friction) {
  sh::Setup setup;
  setup.root_angle_rad = kPi;
  setup.law = {stiffness, 1e-3};
  sh::Obstacle floor = MakeObstacle(sh::ObstacleKind::kPlaneRim, {0.0, 0.0});
  floor.friction.static_coefficient = static_friction;
  floor.friction.kinetic_coefficient = 0.5 * static_friction;
  setup.obstacles.push_back(floor);
  return setup;
}

}  // namespace

TEST_CASE("Shooting reference reproduces Mattiasson's table and the closed form", "[shooting]") {
  struct Row {
    double alpha, v, h;
  };
  // Mattiasson 1981, Table 1 (docs/models.md, "Mattiasson's table"), printed to 5 digits.
  for (const Row row : {Row{1, 0.30172, 0.05643}, Row{2, 0.49346, 0.16064},
                        Row{5, 0.71379, 0.38763}, Row{10, 0.81061, 0.55500}}) {
    const sh::Solution s = TipLoaded(row.alpha);
    REQUIRE(s.converged);
    const double v = s.tip_m.x(), h = 1.0 - s.tip_m.y();
    INFO("alpha " << row.alpha << ": v " << v << ", h " << h);
    // Half a unit in the table's last printed digit.
    CHECK(std::abs(v - row.v) <= 0.5e-5);
    CHECK(std::abs(h - row.h) <= 0.5e-5);
    // The closed form, evaluated to ~1e-13: the integration's fourth-order error at the default
    // steps was measured at 6e-11 (alpha 10), below 1e-9.
    const Cantilever exact = BisshoppDrucker(row.alpha);
    CHECK(std::abs(v - exact.deflection) <= 1e-9);
    CHECK(std::abs(h - exact.shortening) <= 1e-9);
    CHECK(std::abs(s.tip_angle_rad - exact.tip_rotation_rad) <= 1e-9);
    // The grip holds the load's moment about the held end.
    CHECK(s.operator_moment_Nm == Approx(-row.alpha * s.tip_m.y()).epsilon(1e-12));
  }
  // Far beyond the table (the tip almost along the load): found by continuation in the load.
  const sh::Solution far = TipLoaded(50.0);
  REQUIRE(far.converged);
  CHECK(std::abs(far.tip_m.x() - BisshoppDrucker(50.0).deflection) <= 1e-8);
}

TEST_CASE("Shooting reference: small-load limit and a pure end moment", "[shooting]") {
  // A steel tube, SI units: v = F l^3 / (3 EI) up to the elastica's next term, -(4/105) alpha^3 l,
  // 1.1e-9 of v at alpha = 1e-4.
  const double EI = 200e9 * kPi / 4 * (std::pow(3e-3, 4) - std::pow(2.5e-3, 4)), l = 0.3;
  const double F = 1e-4 * EI / (l * l);
  sh::Setup setup;
  setup.hand_m = {0.01, -0.02};
  setup.tip_force_N = {F, 0.0};
  const sh::Solution s = sh::Solve(sh::Rod{l, EI, 3e-3}, setup);
  REQUIRE(s.converged);
  CHECK(s.tip_m.x() - 0.01 == Approx(F * l * l * l / (3 * EI)).epsilon(1e-8));
  CHECK((s.operator_force_N + setup.tip_force_N).norm() <= 1e-15);

  // A couple C alone: a circular arc of radius EI / C, here turning the end by 1.5 rad.
  sh::Setup moment;
  moment.tip_moment_Nm = 1.5 * EI / l;
  const sh::Solution arc = sh::Solve(sh::Rod{l, EI, 3e-3}, moment);
  REQUIRE(arc.converged);
  const double R = EI / moment.tip_moment_Nm;
  // Fourth-order integration of an arc: measured below 1e-12 of l.
  CHECK(std::abs(arc.tip_m.x() - R * (1 - std::cos(1.5))) <= 1e-10 * l);
  CHECK(std::abs(arc.tip_m.y() - R * std::sin(1.5)) <= 1e-10 * l);
  CHECK(arc.tip_angle_rad == Approx(1.5).epsilon(1e-10));
  CHECK(arc.operator_moment_Nm == Approx(-moment.tip_moment_Nm).epsilon(1e-10));
}

TEST_CASE("Shooting reference: a column on a frictionless floor buckles at pi^2 EI / (4 l^2)",
          "[shooting]") {
  // Clamped above, its end sliding freely on the floor: the floor's force stays vertical, Euler's
  // first case. Lowered in steps of 0.037 P_cr of penalty force, then well past buckling and back.
  const double p_cr = kPi * kPi / 4, K = 1e4, step_N = 0.037 * p_cr;
  const sh::Setup setup = ColumnOnFloor(K, 0.0);
  sh::PathOptions options;
  options.buckling_seed_rad = 0.3;
  const std::vector<sh::Hold> holds = ColumnHolds(K, step_N, 40, 12, 0.15, true);
  const sh::PathResult path = sh::FollowPath(sh::Rod{1.0, 1.0, 0.0}, setup, holds, options);
  REQUIRE(path.ok);

  double last_straight_N = 0.0;
  int bent = 0;
  std::vector<std::pair<double, double>> unloading;  // (tip rotation^2, P) on the way back
  for (std::size_t k = 0; k < path.holds.size(); ++k) {
    const sh::Solution& s = path.holds[k].solution;
    const sh::ContactResult& c = s.contacts[0];
    const double P = -s.operator_force_N.y();
    CHECK(c.tangential_N == 0.0);
    CHECK(std::abs(s.operator_force_N.x()) <= 1e-12);
    if (s.max_turn_rad < 1e-7) {
      // Straight: the penalty alone, at most one hold past Euler's load.
      if (bent == 0) last_straight_N = P;
      CHECK(P < p_cr + step_N);
      continue;
    }
    ++bent;
    // The elastica of Euler's first case, with k = sin(a / 2), a the end's rotation:
    // P / P_cr = (2 K(k) / pi)^2, height l (2 E(k) / K(k) - 1), sideways 2 k l / K(k).
    const double a = std::abs(s.tip_angle_rad - kPi);
    const double mod = std::sin(a / 2), K1 = std::comp_ellint_1(mod), E2 = std::comp_ellint_2(mod);
    INFO("hold " << k << ": end rotation " << a << ", P " << P);
    // The integration's error, measured at 2.4e-11 of P_cr over the branch.
    CHECK(P / p_cr == Approx(std::pow(2 * K1 / kPi, 2)).epsilon(1e-8));
    CHECK(std::abs(s.held_m.y() - s.tip_m.y() - (2 * E2 / K1 - 1)) <= 1e-8);
    CHECK(std::abs(std::abs(s.tip_m.x()) - 2 * mod / K1) <= 1e-8);
    // The hand's travel is the penalty's depth plus the end's shortening.
    CHECK(s.tip_m.y() == Approx(1e-3 - P / K).margin(1e-12));
    if (k > holds.size() / 2) unloading.emplace_back(a * a, P);
  }
  CHECK(bent > 20);
  // Off the straight branch at the first hold past P_cr.
  CHECK(last_straight_N > p_cr - step_N);
  CHECK(last_straight_N < p_cr);
  // Euler's load from the post-buckling branch near the bifurcation: P = P_cr (1 + a^2 / 8 +
  // O(a^4)), extrapolated linearly in a^2 from the two smallest rotations on the way back
  // (a < 0.03: the a^4 term leaves ~1e-7).
  std::sort(unloading.begin(), unloading.end());
  REQUIRE(unloading.size() >= 2);
  REQUIRE(unloading[1].first < 1e-3);
  const auto [x0, y0] = unloading[0];
  const auto [x1, y1] = unloading[1];
  const double extrapolated = y0 - x0 * (y1 - y0) / (x1 - x0);
  CHECK(extrapolated == Approx(p_cr).epsilon(1e-6));
}

TEST_CASE("Shooting reference: a column on a stuck end buckles at 20.19 EI / l^2", "[shooting]") {
  // Clamped above, its end held by static friction (mu_s 100: never slides): a pin, Euler's
  // clamped-pinned case, beta l = 4.4934 (tan beta l = beta l). The pin is the stuck contact's
  // spring K: a lateral spring kappa = K l^3 / EI = 1e6 lowers the load by about 2 / kappa.
  const double beta = 4.493409457909064, p_cr = beta * beta, K = 1e6, step_N = 0.037 * p_cr;
  const sh::Setup setup = ColumnOnFloor(K, 100.0);
  sh::PathOptions options;
  options.buckling_seed_rad = 0.3;
  const std::vector<sh::Hold> holds = ColumnHolds(K, step_N, 30, 10, 1e-3 + 31e-6, false);
  const sh::PathResult path = sh::FollowPath(sh::Rod{1.0, 1.0, 0.0}, setup, holds, options);
  REQUIRE(path.ok);
  std::vector<std::pair<double, double>> branch;  // (end rotation^2, P)
  for (const sh::HoldResult& h : path.holds) {
    const sh::ContactResult& c = h.solution.contacts[0];
    if (!c.active) continue;
    CHECK(h.phase[0] == sh::ContactPhase::kStuck);
    CHECK(c.friction_ratio <= 1.0);
    // Pinned: the end moves sideways only by the spring's stretch, T / K.
    CHECK(std::abs(h.solution.tip_m.x()) <= std::abs(c.tangential_N) / K + 1e-12);
    const double P = -h.solution.operator_force_N.y();
    if (h.solution.max_turn_rad < 1e-7) {
      CHECK(P < p_cr + step_N);  // at most one hold past Euler's load
    } else {
      branch.emplace_back(std::pow(h.solution.tip_angle_rad - kPi, 2), P);
    }
  }
  REQUIRE(branch.size() >= 5);
  std::sort(branch.begin(), branch.end());
  const auto [x0, y0] = branch[0];
  const auto [x1, y1] = branch[1];
  INFO("smallest end rotations " << std::sqrt(x0) << ", " << std::sqrt(x1));
  const double extrapolated = y0 - x0 * (y1 - y0) / (x1 - x0);
  // 2 / kappa = 2e-6 from the spring, the a^4 term of the extrapolation below 1e-6.
  CHECK(extrapolated == Approx(p_cr).epsilon(1e-5));
}

TEST_CASE("Shooting reference agrees with the segment rod on a rim contact", "[shooting]") {
  // The rubber tube inclined over a floor, its end pressed 8 mm past touching, on the coupling.
  // planar_rod (reference/planar_rod.hpp) solves the same law by another method, started here
  // from this solution's angles.
  namespace pr = tubeplan::reference;
  const sh::Rod tube = RubberTube();
  const double l = tube.length_m;
  for (const double r1 : {0.0, tube.radius_m}) {
    for (const double inclination_deg : {10.0, 30.0, 45.0, 60.0}) {
      const double phi0 = kPi - inclination_deg * kPi / 180;
      const Vector2d t(std::sin(phi0), std::cos(phi0));
      const double lowest = l * t.y() - r1 * std::abs(Section(phi0).y());
      sh::Setup setup;
      setup.hand_m = {0.0, -lowest - 8e-3};
      setup.root_angle_rad = phi0;
      setup.coupling_N_per_m = 400;
      setup.obstacles.push_back(MakeObstacle(sh::ObstacleKind::kPlaneRim, {0, 0}));
      const sh::Solution s = sh::Solve(sh::Rod{l, tube.bending_stiffness_Nm2, r1}, setup);
      REQUIRE(s.converged);

      pr::Loading loading;
      loading.hand_m = setup.hand_m;
      loading.root_angle_rad = phi0;
      loading.coupling_N_per_m = 400;
      loading.obstacles.push_back({pr::ObstacleKind::kPlaneEnd, {0, 0}, {0, 1}, 0.0, 0.0});
      Vector2d force[2], tip[2];
      for (int q = 0; q < 2; ++q) {
        const int N = 128 << q;
        pr::RodState start;
        start.held_m = s.held_m;
        start.theta_rad.resize(N);
        for (int k = 0; k < N; ++k)
          start.theta_rad(k) = sh::At(s.centreline, (k + 0.5) * l / N).angle_rad;
        const pr::RodSolution d =
            pr::SolveRod(pr::PlanarRod{l, tube.bending_stiffness_Nm2, r1, N}, loading, start);
        REQUIRE(d.converged);
        force[q] = -d.contact_force_N;
        tip[q] = d.tip_m;
      }
      const double F = s.operator_force_N.norm();
      INFO("r1 " << r1 << ", inclination " << inclination_deg << " deg, force " << F << " N");
      if (r1 == 0.0) {
        // The segment rod's error is O(h^2) (measured: a factor 4.000 per halving), so
        // Richardson's extrapolation from N = 128 and 256 leaves O(h^4): measured 2e-10 of F and
        // 5e-12 of l.
        const Vector2d f = (4.0 * force[1] - force[0]) / 3.0, p = (4.0 * tip[1] - tip[0]) / 3.0;
        CHECK((f - s.operator_force_N).norm() <= 1e-8 * F);
        CHECK((p - s.tip_m).norm() <= 1e-10 * l);
      } else {
        // With a radius the segment rod places the corner with the last segment's angle, off
        // the end's by half a segment's turn: an O(h) error (measured: factor 1.95-2.01 per
        // halving). First-order extrapolation leaves 4e-7 of l; the force at N = 256 is within
        // 1.3e-5 of F.
        const double e128 = (tip[0] - s.tip_m).norm(), e256 = (tip[1] - s.tip_m).norm();
        CHECK(e128 / e256 == Approx(2.0).margin(0.1));
        CHECK((2.0 * tip[1] - tip[0] - s.tip_m).norm() <= 1e-6 * l);
        CHECK((force[1] - s.operator_force_N).norm() <= 3e-5 * F);
      }
    }
  }
}

TEST_CASE("Shooting reference: a side on an edge at small deflection", "[shooting]") {
  // Steel tube, edge at a = 0.2 m on the +x side, the hand moved towards it: the force follows the
  // springs in series (coupling, 3EI/a^3 bending, contact K), exact up to the geometric
  // nonlinearity at a slope of ~3e-3 rad (relative 1e-5).
  const double EI = 200e9 * kPi / 4 * (std::pow(3e-3, 4) - std::pow(2.5e-3, 4));
  sh::Setup setup;
  setup.coupling_N_per_m = 400.0;
  const double a = 0.2, d0 = 0.5e-3, delta = 1e-3;
  setup.obstacles.push_back(MakeObstacle(sh::ObstacleKind::kEdge, {3e-3 + d0, a}));
  setup.hand_m = {delta, 0.0};
  const sh::Solution s = sh::Solve(sh::Rod{0.3, EI, 3e-3}, setup);
  REQUIRE(s.converged);
  const double k_series = 1.0 / (1.0 / 400.0 + a * a * a / (3.0 * EI) + 1.0 / 1e4);
  CHECK(s.operator_force_N.x() == Approx((delta + 1e-3 - d0) * k_series).epsilon(2e-5));
  // The contact sits where the centreline is nearest the edge, the force along the line to it.
  const sh::ContactResult& c = s.contacts[0];
  const sh::CentrelinePoint q = sh::At(s.centreline, c.arc_m);
  const Vector2d away = q.position_m - setup.obstacles[0].point_m;
  CHECK(std::abs(away.dot(Vector2d(std::sin(q.angle_rad), std::cos(q.angle_rad)))) <= 1e-9 * a);
  CHECK(c.force_N.normalized().dot(away.normalized()) == Approx(1.0).epsilon(1e-12));
  CHECK(c.normal_N == Approx(1e4 * (1e-3 - (away.norm() - 3e-3))).epsilon(1e-6));
  CHECK((400.0 * (setup.hand_m - s.held_m) - s.operator_force_N).norm() <= 1e-12);
}

TEST_CASE("Shooting reference: the rubber tube lowered and pushed on a floor, stuck then sliding",
          "[shooting]") {
  // scenes/groove.yaml's tube and law, held at 45 deg over a floor: lowered 30 mm, then pushed
  // 30 mm along +x, in 0.5 mm holds.
  const sh::Rod tube = RubberTube();
  const double l = tube.length_m, r1 = tube.radius_m, K = 1e4, eps = 1e-3, Kc = 400;
  // The solver's tolerance on a force: 1e-10 of its force unit EI / l^2.
  const double force_tolerance = 1e-10 * tube.bending_stiffness_Nm2 / (l * l);
  sh::Setup setup;
  setup.coupling_N_per_m = Kc;
  setup.law = {K, eps};
  sh::Obstacle floor = MakeObstacle(sh::ObstacleKind::kPlaneRim, {0, 0});
  floor.friction = {0.7, 0.08, 2.0 / 3.0, 1.0, false};
  setup.obstacles.push_back(floor);
  const double phi0 = 3 * kPi / 4;
  const Vector2d start(0, -(l * std::cos(phi0) - r1 * std::sin(phi0)) + 5e-3);
  std::vector<sh::Hold> holds;
  for (int k = 0; k <= 60; ++k) holds.push_back({start + Vector2d(0, -0.5e-3 * k), phi0});
  for (int k = 1; k <= 60; ++k) holds.push_back({holds[60].hand_m + Vector2d(0.5e-3 * k, 0), phi0});
  const sh::PathResult path = sh::FollowPath(tube, setup, holds);
  REQUIRE(path.ok);

  const Vector2d tau(1, 0);
  int stuck = 0, sliding = 0, first_contact = -1;
  double work_J = 0.0;
  for (std::size_t k = 0; k < path.holds.size(); ++k) {
    const sh::HoldResult& h = path.holds[k];
    const sh::Solution& s = h.solution;
    const sh::ContactResult& c = s.contacts[0];
    INFO("hold " << k);
    REQUIRE(h.settled);
    // The operator's work (trapezoids) bounds the energy stored: bending, penalty, the stuck
    // spring, the coupling (friction only dissipates); 1 % for the quadrature where a contact
    // engages between two holds (measured 6e-4).
    if (k > 0) {
      const sh::Solution& before = path.holds[k - 1].solution;
      work_J += 0.5 * (before.operator_force_N + s.operator_force_N)
                          .dot(h.hold.hand_m - path.holds[k - 1].hold.hand_m);
    }
    CHECK(s.potential_energy_J <= 1.01 * work_J + 1e-15);
    // The coupling, and the balance of forces and moments about the held end, from the end's
    // corners rebuilt here from the end's centre and angle.
    CHECK((Kc * (h.hold.hand_m - s.held_m) - s.operator_force_N).norm() <= 1e-12);
    CHECK((s.operator_force_N + c.force_N).norm() <= 1e-12);
    const Vector2d g = Section(s.tip_angle_rad);
    const Vector2d lo = s.tip_m - r1 * g, hi = s.tip_m + r1 * g;
    const Vector2d corner = lo.y() <= hi.y() ? lo : hi;
    const double d = corner.y();
    CHECK(std::abs(s.operator_moment_Nm + MomentOf(corner - s.held_m, c.force_N)) <= 1e-9 * l);
    if (d >= eps) {
      CHECK(h.phase[0] == sh::ContactPhase::kOpen);
      continue;
    }
    if (first_contact < 0) first_contact = int(k);
    // The penalty law at the rebuilt corner, and the friction law.
    CHECK(c.normal_N == Approx(K * (eps - d)).epsilon(1e-9));
    CHECK((c.force_N - c.normal_N * Vector2d(0, 1) - c.tangential_N * tau).norm() <=
          force_tolerance);
    const double f_max = 0.7 * std::pow(c.normal_N, 2.0 / 3.0);
    CHECK(std::abs(c.tangential_N) <= f_max * (1 + 1e-9));
    const sh::SlotFriction& anchor_before = path.holds[k - 1].friction[0];
    if (h.phase[0] == sh::ContactPhase::kStuck) {
      ++stuck;
      // Held by the spring to the anchor carried from the last hold (set on first touch).
      if (int(k) > first_contact)
        CHECK(c.tangential_N ==
              Approx(-K * tau.dot(corner - anchor_before.anchor_m)).margin(1e-10));
    } else {
      ++sliding;
      REQUIRE(h.phase[0] == sh::ContactPhase::kSliding);
      // Kinetic friction against the slip, and the anchor returned so that the spring carries
      // exactly that force into the next hold.
      CHECK(std::abs(c.tangential_N) == Approx(0.08 * c.normal_N).epsilon(1e-12));
      CHECK(c.tangential_N * tau.dot(corner - anchor_before.anchor_m) < 0.0);
      CHECK(-K * tau.dot(corner - h.friction[0].anchor_m) == Approx(c.tangential_N).epsilon(1e-9));
    }
  }
  // First touch sticks; the push makes it slide and stick again.
  REQUIRE(first_contact > 0);
  CHECK(path.holds[std::size_t(first_contact)].phase[0] == sh::ContactPhase::kStuck);
  CHECK(stuck > 20);
  CHECK(sliding > 5);
}

TEST_CASE("Shooting reference refuses a bad rod with every problem named", "[shooting]") {
  sh::Setup setup;
  setup.obstacles.push_back(MakeObstacle(sh::ObstacleKind::kPlaneRim, {0, 0}, {0, 2}));
  try {
    sh::Solve(sh::Rod{0.0, -1.0, 0.0}, setup);
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK(what.find("length_m 0 must be > 0") != std::string::npos);
    CHECK(what.find("bending_stiffness_Nm2 -1 must be > 0") != std::string::npos);
    CHECK(what.find("obstacle 0: normal (0 2) is not unit") != std::string::npos);
  }
}
