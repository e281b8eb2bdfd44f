// Tests of the elastica solver (docs/models.md, "The elastica under a tip load").
//
// The reference values come from outside the solver: Mattiasson's published table, a test-only
// shooting solver (RK4 on the ODE itself plus bisection on the root curvature), finite
// differences of the returned centreline, and the small-alpha expansions in docs/models.md.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>
#include <catch2/catch.hpp>

#include <tubeplan/model/elastica.hpp>

namespace {

using tubeplan::model::ElasticaCentreline;
using tubeplan::model::ElasticaSolution;
using tubeplan::model::SolveElastica;

constexpr double kPi = std::numbers::pi;

double RelativeError(double value, double reference) {
  return std::abs(value - reference) / std::abs(reference);
}

// ---- Test-only shooting solver ------------------------------------------------------------------

// One RK4 integration of theta'' = -alpha cos(theta + psi) with x' = sin(theta),
// h' = 2 sin^2(theta/2) (the shortening 1 - z, integrated directly so that it keeps its relative
// accuracy at small loads) and e' = theta'^2 / 2, from the clamped root with
// theta'(0) = root_curvature.
struct Shot {
  double root_curvature = 0.0;
  double theta = 0.0;
  double slope = 0.0;  // theta'(1): zero at a solution
  double x = 0.0;
  double h = 0.0;
  double energy = 0.0;
  double min_slope = 0.0;            // smallest theta' on [0, 1): >= 0 on the first mode
  std::vector<double> sample_theta;  // at s = 0.25, 0.5, 0.75
  std::vector<double> sample_x;
  std::vector<double> sample_h;
};

Shot Integrate(double alpha, double psi, double root_curvature) {
  constexpr int kSteps = 4000;
  const double h = 1.0 / kSteps;
  using State = std::array<double, 5>;
  const auto rate = [&](const State& y) {
    const double half_sine = std::sin(0.5 * y[0]);
    return State{y[1], -alpha * std::cos(y[0] + psi), std::sin(y[0]), 2.0 * half_sine * half_sine,
                 0.5 * y[1] * y[1]};
  };
  State y{0.0, root_curvature, 0.0, 0.0, 0.0};
  Shot shot;
  shot.root_curvature = root_curvature;
  shot.min_slope = root_curvature;
  for (int step = 1; step <= kSteps; ++step) {
    const State k1 = rate(y);
    State t{};
    for (int i = 0; i < 5; ++i) t[i] = y[i] + 0.5 * h * k1[i];
    const State k2 = rate(t);
    for (int i = 0; i < 5; ++i) t[i] = y[i] + 0.5 * h * k2[i];
    const State k3 = rate(t);
    for (int i = 0; i < 5; ++i) t[i] = y[i] + h * k3[i];
    const State k4 = rate(t);
    for (int i = 0; i < 5; ++i) y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    if (step < kSteps) shot.min_slope = std::min(shot.min_slope, y[1]);
    if (step % (kSteps / 4) == 0 && step < kSteps) {
      shot.sample_theta.push_back(y[0]);
      shot.sample_x.push_back(y[2]);
      shot.sample_h.push_back(y[3]);
    }
  }
  shot.theta = y[0];
  shot.slope = y[1];
  shot.x = y[2];
  shot.h = y[3];
  shot.energy = y[4];
  return shot;
}

// The first-mode solution: among the roots of theta'(1; c), the one whose theta' stays >= 0
// (the pendulum rises monotonically from the root to its turning point at the tip).
Shot ShootFirstMode(double alpha, double psi) {
  const double c_max = 2.0 * std::sqrt(alpha) * 1.001;  // theta'(0) = 2 sqrt(alpha D), D <= 1
  constexpr int kScan = 200;
  double c_prev = c_max * 1e-6;
  double f_prev = Integrate(alpha, psi, c_prev).slope;
  for (int i = 1; i <= kScan; ++i) {
    const double c = c_max * i / kScan;
    const double f = Integrate(alpha, psi, c).slope;
    if ((f_prev < 0.0) != (f < 0.0)) {
      double lo = c_prev;
      double hi = c;
      const bool rising = f_prev < 0.0;
      for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        if ((Integrate(alpha, psi, mid).slope < 0.0) == rising) {
          lo = mid;
        } else {
          hi = mid;
        }
      }
      Shot shot = Integrate(alpha, psi, 0.5 * (lo + hi));
      if (shot.min_slope >= -1e-9) return shot;
    }
    c_prev = c;
    f_prev = f;
  }
  FAIL("no first-mode root found for alpha " << alpha << ", psi " << psi);
  return {};
}

struct Sampled {
  std::vector<double> s;
  std::vector<Eigen::Vector2d> xz;
  std::vector<double> theta;
};

Sampled Sample(const ElasticaSolution& solution, int intervals) {
  Sampled out;
  out.s.resize(intervals + 1);
  for (int i = 0; i <= intervals; ++i) out.s[i] = static_cast<double>(i) / intervals;
  out.s.back() = 1.0;
  out.xz.resize(out.s.size());
  out.theta.resize(out.s.size());
  ElasticaCentreline(solution, out.s, out.xz, out.theta);
  return out;
}

bool AllFinite(const ElasticaSolution& solution) {
  const auto& t = solution.tip;
  return std::isfinite(t.deflection) && std::isfinite(t.shortening) &&
         std::isfinite(t.tip_angle_rad) && std::isfinite(t.root_curvature) &&
         std::isfinite(t.energy) && std::isfinite(solution.modulus_k) &&
         std::isfinite(solution.modulus_kc) && std::isfinite(solution.u0);
}

// The largest position and tangent differences between ElasticaSamples over [s_first, s_last]
// at n points and ElasticaCentreline at the same arc positions (over [0, 1] through the
// whole-length overload).
struct SampleErrors {
  double position = 0.0, tangent = 0.0;
};
SampleErrors SamplesAgainstCentreline(const ElasticaSolution& solution, double s_first,
                                      double s_last, int n) {
  std::vector<double> s(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j)
    s[std::size_t(j)] = j == n - 1 ? s_last : s_first + (s_last - s_first) * (double(j) / (n - 1));
  std::vector<Eigen::Vector2d> xz(s.size()), samples(s.size()), tangents(s.size());
  std::vector<double> theta(s.size());
  ElasticaCentreline(solution, s, xz, theta);
  if (s_first == 0.0 && s_last == 1.0)
    tubeplan::model::ElasticaSamples(solution, samples, tangents);
  else
    tubeplan::model::ElasticaSamples(solution, s_first, s_last, samples, tangents);
  SampleErrors e;
  for (std::size_t j = 0; j < s.size(); ++j) {
    e.position = std::max(e.position, (samples[j] - xz[j]).norm());
    const Eigen::Vector2d expected(std::sin(theta[j]), std::cos(theta[j]));
    e.tangent = std::max(e.tangent, (tangents[j] - expected).norm());
  }
  return e;
}

}  // namespace

TEST_CASE("Elastica matches Mattiasson's table for a lateral tip load", "[elastica]") {
  struct Row {
    double alpha, deflection, shortening;
  };
  // Mattiasson 1981, Table 1 (docs/models.md, "Mattiasson's table").
  const Row rows[] = {{1.0, 0.30172, 0.05643},
                      {2.0, 0.49346, 0.16064},
                      {5.0, 0.71379, 0.38763},
                      {10.0, 0.81061, 0.55500}};
  for (const Row& row : rows) {
    const ElasticaSolution solution = SolveElastica(row.alpha, 0.0);
    INFO("alpha = " << row.alpha);
    // The table is rounded to 5 decimals: half a unit of its last digit.
    CHECK(solution.tip.deflection == Approx(row.deflection).margin(5e-6));
    CHECK(solution.tip.shortening == Approx(row.shortening).margin(5e-6));
  }
}

TEST_CASE("Elastica agrees with an independent shooting solver", "[elastica]") {
  struct Case {
    double alpha, psi;
  };
  const Case cases[] = {
      {5e-4, 0.4},             // small load: the series branch
      {2e-3, -1.1},            // small load: the elliptic branch with quadrature
      {0.01, 0.3},             // small load, slightly tensile
      {0.05, -1.0},            // small load, mostly compressive
      {0.3, 0.0},              // lateral
      {1.0, -0.5},             // oblique compression
      {2.0, 1.0},              // oblique tension
      {5.0, -1.2},             // near-axial compression
      {4.0, -kPi / 2.0},       // pure compression above Euler's load: buckled
      {15.0, -kPi / 2.0},      // pure compression, far into the post-buckling range
      {10.0, kPi / 2 - 0.05},  // near-axial tension
      {30.0, 0.7},             // large load, tension side
      {50.0, -0.3},            // large load, compression side
  };
  for (const Case& c : cases) {
    INFO("alpha = " << c.alpha << ", psi = " << c.psi);
    const ElasticaSolution solution = SolveElastica(c.alpha, c.psi);
    const Shot shot = ShootFirstMode(c.alpha, c.psi);
    // RK4 with 4000 steps and a bisected root curvature agree with the solver to 2e-11 here
    // (measured, alpha <= 50); 1e-9 leaves a margin while still catching any formula error.
    constexpr double kTol = 1e-9;
    CHECK(RelativeError(solution.tip.tip_angle_rad, shot.theta) < kTol);
    CHECK(RelativeError(solution.tip.deflection, shot.x) < kTol);
    CHECK(RelativeError(solution.tip.shortening, shot.h) < kTol);
    CHECK(RelativeError(solution.tip.root_curvature, shot.root_curvature) < kTol);
    const Shot at_solver_curvature = Integrate(c.alpha, c.psi, solution.tip.root_curvature);
    // The solver's root curvature must itself shoot to theta'(1) = 0; the slope at the tip
    // scales like the curvature, so compare relative to it.
    CHECK(std::abs(at_solver_curvature.slope) < kTol * solution.tip.root_curvature);
    CHECK(RelativeError(solution.tip.energy, shot.energy) < kTol);
    // Moment balance at the root: E I theta'(0) = F_x z(1) - F_z x(1), i.e.
    // theta'(0) = alpha (cos psi z(1) - sin psi x(1)); rounding relative to the larger term.
    const double z1 = 1.0 - solution.tip.shortening;
    const double moment_x = c.alpha * std::cos(c.psi) * z1;
    const double moment_z = c.alpha * std::sin(c.psi) * solution.tip.deflection;
    CHECK(std::abs(solution.tip.root_curvature - (moment_x - moment_z)) <=
          1e-13 * (std::abs(moment_x) + std::abs(moment_z)));

    // The shape at interior points, against the shot's samples at s = 1/4, 1/2, 3/4.
    const std::vector<double> s = {0.25, 0.5, 0.75};
    std::vector<Eigen::Vector2d> xz(3);
    std::vector<double> theta(3);
    ElasticaCentreline(solution, s, xz, theta);
    for (int i = 0; i < 3; ++i) {
      // Positions and angles are O(1): an absolute tolerance at the shooting accuracy.
      CHECK(std::abs(theta[i] - shot.sample_theta[i]) < kTol);
      CHECK(std::abs(xz[i].x() - shot.sample_x[i]) < kTol);
      CHECK(std::abs(xz[i].y() - (s[i] - shot.sample_h[i])) < kTol);
    }
  }
}

TEST_CASE("Elastica energy equals the bending energy of its own centreline", "[elastica]") {
  const double cases[][2] = {{0.5, 0.0}, {3.0, -1.0}, {8.0, 0.9}, {20.0, -kPi / 2.0}, {1e-4, 0.4}};
  for (const auto& c : cases) {
    const double alpha = c[0];
    const double psi = c[1];
    INFO("alpha = " << alpha << ", psi = " << psi);
    const ElasticaSolution solution = SolveElastica(alpha, psi);
    constexpr int kIntervals = 20000;
    const Sampled shape = Sample(solution, kIntervals);
    // 1/2 int theta'^2 by the midpoint rule on difference quotients of theta, and the virial
    // identity int theta'^2 = alpha int theta cos(theta + psi) by the trapezoidal rule: both are
    // O(ds^2) ~ 1e-9 accurate relative to the energy for these loads.
    const double ds = 1.0 / kIntervals;
    double energy = 0.0;
    double virial = 0.0;
    for (int i = 0; i < kIntervals; ++i) {
      const double slope = (shape.theta[i + 1] - shape.theta[i]) / ds;
      energy += 0.5 * slope * slope * ds;
      const double left = shape.theta[i] * std::cos(shape.theta[i] + psi);
      const double right = shape.theta[i + 1] * std::cos(shape.theta[i + 1] + psi);
      virial += 0.5 * (left + right) * ds;
    }
    virial *= 0.5 * alpha;
    // Both quadratures are second order with ds = 5e-5: ~1e-9 relative.
    CHECK(RelativeError(solution.tip.energy, energy) < 1e-7);
    CHECK(RelativeError(solution.tip.energy, virial) < 1e-7);

    // The centreline's positions are the integrals of its own tangent (trapezoidal, O(ds^2)).
    double x = 0.0;
    double z = 0.0;
    double max_gap = 0.0;
    for (int i = 0; i < kIntervals; ++i) {
      x += 0.5 * (std::sin(shape.theta[i]) + std::sin(shape.theta[i + 1])) * ds;
      z += 0.5 * (std::cos(shape.theta[i]) + std::cos(shape.theta[i + 1])) * ds;
      max_gap = std::max(max_gap, (shape.xz[i + 1] - Eigen::Vector2d(x, z)).norm());
    }
    // Positions are O(1); the trapezoidal rule over 2e4 intervals is good to ~1e-9.
    CHECK(max_gap < 1e-7);
  }
}

TEST_CASE("Elastica centreline ends match the tip figures", "[elastica]") {
  const double alphas[] = {1e-6, 5e-4, 2e-3, 0.3, 2.0, 40.0, 1e3, 1e4};
  const double psis[] = {-kPi / 2.0, -1.3, -0.4, 0.0, 0.6, 1.4, kPi / 2.0 - 1e-6};
  for (const double alpha : alphas) {
    for (const double psi : psis) {
      INFO("alpha = " << alpha << ", psi = " << psi);
      const ElasticaSolution solution = SolveElastica(alpha, psi);
      const std::vector<double> s = {0.0, 1.0};
      std::vector<Eigen::Vector2d> xz(2);
      std::vector<double> theta(2);
      ElasticaCentreline(solution, s, xz, theta);
      CHECK(xz[0].norm() == 0.0);
      CHECK(theta[0] == 0.0);
      // The shape's end agrees with the tip figures.
      const double scale = std::max(solution.tip.deflection, 1e-300);
      CHECK(std::abs(xz[1].x() - solution.tip.deflection) <= 1e-10 * scale);
      // z = 1 - h itself is stored near 1, so it only carries h to one ulp of 1 (1.1e-16).
      CHECK(std::abs(1.0 - xz[1].y() - solution.tip.shortening) <=
            1e-10 * solution.tip.shortening + 2.3e-16);
      CHECK(std::abs(theta[1] - solution.tip.tip_angle_rad) <=
            1e-10 * std::max(solution.tip.tip_angle_rad, 1e-300));
    }
  }
}

TEST_CASE("Evenly spaced elastica samples agree with the centreline evaluated point by point",
          "[elastica]") {
  // ElasticaSamples carries the Jacobi functions from sample to sample by their addition
  // theorems; ElasticaCentreline evaluates each point on its own by Landen transformations. The
  // point-by-point figures are good to a few 1e-15; each addition step loses at most
  // exp(2 * step) <= e^2 ulp of cn and dn (the step is kept <= 1), so 48 steps stay below
  // ~5e-14 and 1e-12 is a margin of 20. Loads span the series, the quadrature and the closed
  // forms, the switch to point-by-point evaluation (alpha > (n - 1)^2) and both sides of it.
  const double alphas[] = {1e-6, 5e-4, 2e-3, 0.3, 2.0, 13.8, 40.0, 255.0, 260.0, 1e3, 1e4};
  const double psis[] = {-kPi / 2.0, -1.3, -0.4, 0.0, 0.6, 1.4, kPi / 2.0 - 1e-6};
  for (const int n : {2, 3, 17, 49}) {
    for (const double alpha : alphas) {
      for (const double psi : psis) {
        INFO("n = " << n << ", alpha = " << alpha << ", psi = " << psi);
        const SampleErrors e = SamplesAgainstCentreline(SolveElastica(alpha, psi), 0.0, 1.0, n);
        CHECK(e.position <= 1e-12);
        CHECK(e.tangent <= 1e-12);
      }
    }
  }
  std::vector<Eigen::Vector2d> one(1), two(2);
  CHECK_THROWS_AS(tubeplan::model::ElasticaSamples(SolveElastica(1.0, 0.0), 0.5, 0.4, two, two),
                  std::invalid_argument);
  CHECK_THROWS_AS(tubeplan::model::ElasticaSamples(SolveElastica(1.0, 0.0), -0.1, 0.4, two, two),
                  std::invalid_argument);
  CHECK_THROWS_AS(tubeplan::model::ElasticaSamples(SolveElastica(1.0, 0.0), 0.5, 1.5, two, two),
                  std::invalid_argument);
  CHECK_THROWS_AS(tubeplan::model::ElasticaSamples(SolveElastica(1.0, 0.0), one, one),
                  std::invalid_argument);
  CHECK_THROWS_AS(tubeplan::model::ElasticaSamples(SolveElastica(1.0, 0.0), two, one),
                  std::invalid_argument);
}

TEST_CASE("Elastica samples over a part of the length agree with the centreline point by point",
          "[elastica]") {
  // ElasticaSamples over [s_first, s_last]: the walk starts afresh past the root and short of
  // the tip. Ranges on the root side of K/2 only,
  // the tip side only, across it, a single point twice, and the whole; the same 1e-12 as the
  // whole length's samples (the walk is no longer, so it loses no more).
  const double alphas[] = {1e-6, 2e-3, 2.0, 13.8, 260.0, 1e3, 1e4};
  const double psis[] = {-1.3, 0.0, 0.6, kPi / 2.0 - 1e-6};
  const std::array<std::array<double, 2>, 6> ranges{
      {{0.0, 0.2}, {0.05, 0.35}, {0.3, 0.95}, {0.7, 1.0}, {0.4, 0.4}, {0.0, 1.0}}};
  for (const int n : {2, 5, 21}) {
    for (const double alpha : alphas) {
      for (const double psi : psis) {
        const ElasticaSolution solution = SolveElastica(alpha, psi);
        for (const auto& [s_first, s_last] : ranges) {
          INFO("n = " << n << ", alpha = " << alpha << ", psi = " << psi << ", [" << s_first << ", "
                      << s_last << "]");
          const SampleErrors e = SamplesAgainstCentreline(solution, s_first, s_last, n);
          CHECK(e.position <= 1e-12);
          CHECK(e.tangent <= 1e-12);
        }
      }
    }
  }
  // Short ranges of many points: one anchor spacing holding hundreds of steps
  // (alpha = 5000 near k = 1: the tangent drifted 2.6e-12 in 64 steps, 4.1e-11 in 1000), and a
  // root made apart from the walk's D(K) (alpha = 0.002: 1.1e-12 of l).
  struct Short {
    double alpha, psi, s_first, s_last;
  };
  for (const Short& c :
       {Short{5000.0, -1.3, 0.0197, 0.0211}, Short{0.002, kPi / 2.0 - 1e-6, 0.124, 0.169},
        Short{0.3, kPi / 2.0 - 1e-6, 0.124, 0.169}}) {
    for (const int n : {64, 300, 1000}) {
      INFO("n = " << n << ", alpha = " << c.alpha << ", [" << c.s_first << ", " << c.s_last << "]");
      const SampleErrors e =
          SamplesAgainstCentreline(SolveElastica(c.alpha, c.psi), c.s_first, c.s_last, n);
      CHECK(e.position <= 1e-12);
      CHECK(e.tangent <= 1e-12);
    }
  }
}

TEST_CASE("An elastica solved from a nearby solution is the one solved from scratch",
          "[elastica]") {
  // The residual has one root in the tip angle, so Newton from a nearby solution must land on
  // the root the bracketed search finds, to rounding: the tip figures agree to 1e-13 (the
  // solver's own accuracy, docs/models.md), the shape's modulus k' to 1e-13 relative. Near loads
  // (1 % and 0.01 rad away, as tick to tick or a finite difference) must take fewer iterations
  // than the search from scratch; far ones (alpha 100 times off, psi across its range) may
  // take more, never another answer.
  const double alphas[] = {2e-3, 0.3, 2.0, 13.8, 40.0, 300.0, 1e3, 9e3};
  const double psis[] = {-kPi / 2.0 + 1e-3, -1.3, -0.4, 0.0, 0.6, 1.4, kPi / 2.0 - 1e-3};
  int near_iterations = 0, cold_iterations = 0;
  for (const double alpha : alphas) {
    for (const double psi : psis) {
      const ElasticaSolution cold = SolveElastica(alpha, psi);
      struct Start {
        double alpha, psi;
        bool near;
      };
      const Start starts[] = {{alpha * 1.001, psi, true},
                              {alpha * 0.999, std::clamp(psi + 0.001, -kPi / 2.0, kPi / 2.0), true},
                              {std::min(alpha * 100.0, 1e4), -psi, false},
                              {alpha / 100.0, 0.0, false}};
      for (const Start& start : starts) {
        INFO("alpha = " << alpha << ", psi = " << psi << ", from alpha = " << start.alpha
                        << ", psi = " << start.psi);
        const ElasticaSolution from = SolveElastica(start.alpha, start.psi);
        const ElasticaSolution warm = SolveElastica(alpha, psi, &from);
        const auto close = [](double a, double b) {
          return std::abs(a - b) <= 1e-13 * std::max(std::abs(b), 1e-300);
        };
        CHECK(close(warm.tip.tip_angle_rad, cold.tip.tip_angle_rad));
        CHECK(close(warm.tip.deflection, cold.tip.deflection));
        CHECK(close(warm.tip.shortening, cold.tip.shortening));
        CHECK(close(warm.tip.root_curvature, cold.tip.root_curvature));
        CHECK(close(warm.tip.energy, cold.tip.energy));
        CHECK(close(warm.modulus_kc, cold.modulus_kc));
        if (start.near && !cold.series) {
          near_iterations += warm.iterations;
          cold_iterations += cold.iterations;
        }
      }
    }
  }
  INFO("iterations from near solutions " << near_iterations << ", from scratch "
                                         << cold_iterations);
  CHECK(2 * near_iterations < cold_iterations);  // measured: 313 against 784
  CHECK(SolveElastica(2.0, 0.3, nullptr).tip.tip_angle_rad ==
        SolveElastica(2.0, 0.3).tip.tip_angle_rad);
}

TEST_CASE("A solution's kept load sines give the shape and warm start fresh ones give",
          "[elastica]") {
  // SolveElastica keeps its loading's four sines in the solution, for the shape evaluations
  // and a warm start from it; the same solution without them (loading_psi_rad NaN, as a
  // solution made by hand) makes them afresh. Both must give the same bits. So must a solution
  // whose psi_rad was changed after the solve: its kept sines are then not its direction's.
  using tubeplan::model::ElasticaSamples;
  const auto samples_of = [](const ElasticaSolution& solution) {
    std::array<Eigen::Vector2d, 17> xz{}, tangent{};
    ElasticaSamples(solution, xz, tangent);
    std::array<double, 4 * 17> flat{};
    for (std::size_t j = 0; j < xz.size(); ++j) {
      flat[4 * j] = xz[j].x();
      flat[4 * j + 1] = xz[j].y();
      flat[4 * j + 2] = tangent[j].x();
      flat[4 * j + 3] = tangent[j].y();
    }
    return flat;
  };
  const double alphas[] = {0.05, 2.0, 13.8, 300.0};
  const double psis[] = {-1.3, -0.4, 0.0, 0.6, 1.4};
  for (const double alpha : alphas) {
    for (const double psi : psis) {
      INFO("alpha = " << alpha << ", psi = " << psi);
      const ElasticaSolution kept = SolveElastica(alpha, psi);
      CHECK(kept.loading_psi_rad == psi);
      ElasticaSolution bare = kept;
      bare.loading_psi_rad = std::numeric_limits<double>::quiet_NaN();
      CHECK(samples_of(kept) == samples_of(bare));
      const ElasticaSolution warm_kept = SolveElastica(alpha * 1.01, psi + 0.01, &kept);
      const ElasticaSolution warm_bare = SolveElastica(alpha * 1.01, psi + 0.01, &bare);
      CHECK(warm_kept.tip.tip_angle_rad == warm_bare.tip.tip_angle_rad);
      CHECK(warm_kept.tip.deflection == warm_bare.tip.deflection);
      CHECK(warm_kept.iterations == warm_bare.iterations);
      ElasticaSolution moved = kept;
      moved.psi_rad = -psi + 0.1;
      ElasticaSolution moved_bare = moved;
      moved_bare.loading_psi_rad = std::numeric_limits<double>::quiet_NaN();
      CHECK(samples_of(moved) == samples_of(moved_bare));
    }
  }
}

TEST_CASE("Elastica series and elliptic branches agree across the switch", "[elastica]") {
  // Locate the switch from the outside (the 'series' flag) instead of copying the constant.
  double lo = 1e-6;  // series here
  double hi = 0.1;   // elliptic here
  REQUIRE(SolveElastica(lo, 0.0).series);
  REQUIRE_FALSE(SolveElastica(hi, 0.0).series);
  for (int i = 0; i < 200 && std::nextafter(lo, hi) < hi; ++i) {
    const double mid = std::sqrt(lo * hi);
    const double next = (mid > lo && mid < hi) ? mid : std::nextafter(lo, hi);
    (SolveElastica(next, 0.0).series ? lo : hi) = next;
  }
  const double psis[] = {-kPi / 2.0 + 1e-3, -1.2, -0.5, 0.0, 0.3, 1.0, 1.5, kPi / 2.0 - 1e-3};
  for (const double psi : psis) {
    INFO("switch between " << lo << " and " << hi << ", psi = " << psi);
    const ElasticaSolution below = SolveElastica(lo, psi);
    const ElasticaSolution above = SolveElastica(hi, psi);
    REQUIRE(below.series);
    REQUIRE_FALSE(above.series);
    // The load differs by one ulp; both branches are accurate to ~1e-14 there (measured against
    // a 120-digit reference), so a jump above 1e-12 would be a defect.
    constexpr double kTol = 1e-12;
    CHECK(RelativeError(below.tip.deflection, above.tip.deflection) < kTol);
    CHECK(RelativeError(below.tip.shortening, above.tip.shortening) < kTol);
    CHECK(RelativeError(below.tip.tip_angle_rad, above.tip.tip_angle_rad) < kTol);
    CHECK(RelativeError(below.tip.root_curvature, above.tip.root_curvature) < kTol);
    CHECK(RelativeError(below.tip.energy, above.tip.energy) < kTol);
  }
}

TEST_CASE("Elastica series reproduces the small-load expansions for a lateral load", "[elastica]") {
  const double alpha = 1e-3;
  const ElasticaSolution solution = SolveElastica(alpha, 0.0);
  REQUIRE(solution.series);
  const auto& tip = solution.tip;
  // v/l = a/3 - 4 a^3/105 + O(a^5): the a^3 coefficient to ~a^2 relative, plus rounding of the
  // subtraction (~1e-9): 1e-5 tests it to five digits.
  CHECK((tip.deflection - alpha / 3.0) / (alpha * alpha * alpha) ==
        Approx(-4.0 / 105.0).epsilon(1e-5));
  // theta0 = a/2 - 11 a^3/240 + O(a^5): same reasoning.
  CHECK((tip.tip_angle_rad - alpha / 2.0) / (alpha * alpha * alpha) ==
        Approx(-11.0 / 240.0).epsilon(1e-5));
  // h/l = a^2/15 + O(a^4): relative error ~a^2 = 1e-6.
  CHECK(tip.shortening / (alpha * alpha) == Approx(1.0 / 15.0).epsilon(1e-5));
  // theta'(0) = a z(1) = a (1 - h): exact moment balance for a lateral load.
  CHECK(tip.root_curvature == Approx(alpha * (1.0 - tip.shortening)).epsilon(1e-14));
}

TEST_CASE("Elastica reduces to linear beam theory as the load vanishes", "[elastica]") {
  const double psis[] = {-1.5, -0.8, 0.0, 0.5, 1.2, 1.55};
  for (const double psi : psis) {
    for (const double alpha : {1e-2, 1e-4, 1e-6}) {
      INFO("alpha = " << alpha << ", psi = " << psi);
      const ElasticaSolution solution = SolveElastica(alpha, psi);
      const double cos_psi = std::cos(psi);
      // The first correction is the alpha^2 term theta_2 (theta_2'' = sin(psi) theta_1), a
      // relative change of |sin psi| alpha / (pi^2/4 - ...) < alpha for these angles; the
      // compressive amplification near psi = -pi/2 is 1 / (1 - alpha / 2.47) - 1 ~ 0.4 alpha.
      CHECK(RelativeError(solution.tip.deflection / alpha, cos_psi / 3.0) < alpha);
      CHECK(RelativeError(solution.tip.tip_angle_rad / alpha, cos_psi / 2.0) < alpha);
      // Root moment F_x l for the linear cantilever.
      CHECK(RelativeError(solution.tip.root_curvature / alpha, cos_psi) < alpha);
      // U = F_x^2 l^3 / (6 E I).
      CHECK(RelativeError(solution.tip.energy / (alpha * alpha), cos_psi * cos_psi / 6.0) <
            2.0 * alpha);
    }
  }
}

TEST_CASE("Elastica degenerate loads take their explicit branches", "[elastica]") {
  SECTION("no load") {
    const ElasticaSolution solution = SolveElastica(0.0, 0.3);
    CHECK(solution.tip.deflection == 0.0);
    CHECK(solution.tip.shortening == 0.0);
    CHECK(solution.tip.tip_angle_rad == 0.0);
    CHECK(solution.tip.root_curvature == 0.0);
    CHECK(solution.tip.energy == 0.0);
  }
  SECTION("pure tension stays straight") {
    const ElasticaSolution solution = SolveElastica(500.0, kPi / 2.0);
    CHECK(solution.tip.deflection == 0.0);
    CHECK(solution.tip.shortening == 0.0);
    CHECK(solution.tip.energy == 0.0);
  }
  SECTION("pure compression up to Euler's load stays straight") {
    for (const double alpha : {0.5, 2.0, kPi * kPi / 4.0}) {
      const ElasticaSolution solution = SolveElastica(alpha, -kPi / 2.0);
      CHECK(solution.tip.deflection == 0.0);
      CHECK(solution.tip.tip_angle_rad == 0.0);
    }
  }
  SECTION("pure compression buckles towards +x just above Euler's load") {
    const double euler = kPi * kPi / 4.0;
    double previous = 0.0;
    for (const double excess : {1e-8, 1e-6, 1e-4, 1e-2}) {
      const ElasticaSolution solution = SolveElastica(euler * (1.0 + excess), -kPi / 2.0);
      INFO("alpha / euler - 1 = " << excess);
      REQUIRE(AllFinite(solution));
      CHECK(solution.tip.deflection > 0.0);
      // Koiter's post-buckling law for the cantilever: theta(1)^2 = 8 (alpha / euler - 1) to
      // first order (K(k) = pi/2 (1 + k^2 / 4)); the next term is O(excess) relative, and near
      // 1e-8 the problem's own conditioning (~1e-16 / excess) dominates.
      const double koiter = std::sqrt(8.0 * excess);
      CHECK(RelativeError(solution.tip.tip_angle_rad, koiter) < 2.0 * excess + 1e-4);
      CHECK(solution.tip.tip_angle_rad > previous);
      previous = solution.tip.tip_angle_rad;
    }
  }
}

TEST_CASE("Elastica is finite and physical over the whole load range", "[elastica]") {
  std::vector<double> alphas = {0.0, kPi * kPi / 4.0, std::nextafter(kPi * kPi / 4.0, 3.0), 1e4};
  for (int i = 0; i < 16 * 8; ++i) alphas.push_back(std::pow(10.0, -12.0 + i / 8.0));
  std::sort(alphas.begin(), alphas.end());
  std::vector<double> psis = {-kPi / 2.0, std::nextafter(-kPi / 2.0, 0.0), -kPi / 2.0 + 1e-9,
                              kPi / 2.0,  std::nextafter(kPi / 2.0, 0.0),  kPi / 2.0 - 1e-9};
  for (int i = 0; i <= 24; ++i) psis.push_back(-kPi / 2.0 + kPi * i / 24.0);
  const std::vector<double> s = {0.0, 0.1, 0.37, 0.5, 0.9, 1.0};
  std::vector<Eigen::Vector2d> xz(s.size());
  std::vector<double> theta(s.size());
  for (const double psi : psis) {
    double previous_deflection = -1.0;
    double previous_alpha = -1.0;
    for (const double alpha : alphas) {
      INFO("alpha = " << alpha << ", psi = " << psi);
      const ElasticaSolution solution = SolveElastica(alpha, psi);
      REQUIRE(AllFinite(solution));
      ElasticaCentreline(solution, s, xz, theta);
      for (std::size_t i = 0; i < s.size(); ++i) {
        REQUIRE(std::isfinite(xz[i].x()));
        REQUIRE(std::isfinite(xz[i].y()));
        REQUIRE(std::isfinite(theta[i]));
      }
      // Physical bounds: the tip moves towards +x, never lengthens, stays within reach.
      CHECK(solution.tip.deflection >= 0.0);
      CHECK(solution.tip.shortening >= 0.0);
      CHECK(solution.tip.energy >= 0.0);
      CHECK(solution.tip.tip_angle_rad >= 0.0);
      CHECK(solution.tip.tip_angle_rad <= kPi / 2.0 - psi + 1e-15);
      CHECK(solution.tip.deflection * solution.tip.deflection +
                (1.0 - solution.tip.shortening) * (1.0 - solution.tip.shortening) <=
            1.0 + 1e-15);
      if (psi == 0.0) {
        // The lateral deflection grows strictly with the load. Euler's load and the next double
        // are both in the list: one ulp of load is below the solver's rounding (~1e-15).
        if (alpha > previous_alpha * (1.0 + 1e-12)) {
          CHECK(solution.tip.deflection > previous_deflection);
        }
        previous_deflection = solution.tip.deflection;
        previous_alpha = alpha;
      }
    }
  }
}

TEST_CASE("Elastica rejects invalid arguments", "[elastica]") {
  using Catch::Matchers::Contains;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(SolveElastica(nan, 0.0), Contains("alpha"));
  CHECK_THROWS_WITH(SolveElastica(inf, 0.0), Contains("alpha"));
  CHECK_THROWS_WITH(SolveElastica(-1e-300, 0.0), Contains("alpha"));
  CHECK_THROWS_WITH(SolveElastica(std::nextafter(1e4, 2e4), 0.0), Contains("alpha"));
  CHECK_THROWS_WITH(SolveElastica(1.0, nan), Contains("psi"));
  CHECK_THROWS_WITH(SolveElastica(1.0, -inf), Contains("psi"));
  CHECK_THROWS_WITH(SolveElastica(1.0, std::nextafter(kPi / 2.0, 2.0)), Contains("psi"));
  CHECK_THROWS_WITH(SolveElastica(1.0, -2.0), Contains("psi"));
  CHECK_THROWS_AS(SolveElastica(nan, 0.0), std::invalid_argument);
  CHECK_NOTHROW(SolveElastica(1e4, kPi / 2.0));
  CHECK_NOTHROW(SolveElastica(1e4, -kPi / 2.0));

  const ElasticaSolution solution = SolveElastica(1.0, 0.0);
  std::vector<double> s = {0.0, 0.5};
  std::vector<Eigen::Vector2d> xz(1);
  std::vector<double> theta(2);
  CHECK_THROWS_AS(ElasticaCentreline(solution, s, xz, theta), std::invalid_argument);
  xz.resize(2);
  s[1] = 1.5;
  CHECK_THROWS_WITH(ElasticaCentreline(solution, s, xz, theta), Contains("1.5"));
}
