// Method. With phi = theta + psi + pi/2 the elastica is the pendulum phi'' = -alpha sin(phi),
// released at phi0 = psi + pi/2 and reaching its turning point A = phi(1) at the tip; on the first
// mode phi rises monotonically. With k = sin(A/2), k' = cos(A/2) (ElasticaSolution::modulus_k,
// modulus_kc) and the root amplitude u0, sin(u0) = sin(phi0/2) / k (ElasticaSolution::u0):
// sin(phi/2) = k sn(tau), cos(phi/2) = dn(tau), theta' = 2 sqrt(alpha) k cn(tau) with
// tau = F(u0|k) + sqrt(alpha) s. The end condition sqrt(alpha) = K(k) - F(u0|k), folded into one
// incomplete integral by the addition theorem, reads
//     alpha = D R_F(k'^2 s0^2, k'^2 k^2, k^2 c0^2)^2,   D = k^2 - s0^2 = sin(t/2) sin(phi0 + t/2),
// with t = theta(1), s0 = sin(phi0/2), c0 = cos(phi0/2): products of positive factors only. It is
// solved by a bracketed Newton iteration in log t, or in log(pi - A) when the tip nearly aligns
// with the load, so that k' = sin((pi - A)/2) stays exact down to exp(-sqrt(alpha)) ~ 1e-44. The
// tip angle, root curvature 2 sqrt(alpha D) and bending energy
// (2/3) sqrt(alpha) k^2 k'^2 D^(3/2) R_D(k'^2 s0^2, k^2 c0^2, k'^2 k^2) carry no cancellation.
// The tip position comes from the energy identity (along the load) and the root moment (across);
// those subtract the straight rod, losing ~1e-16 / alpha^2, so for alpha <= 0.5 it is integrated
// instead (10-point Gauss) from sin(theta/2) written without cancellation via the addition
// theorem about the root. Below alpha = 1e-3 a perturbation series in alpha is used (cheap, and
// the elliptic solve would underflow as alpha -> 0). Measured against a 120-digit evaluation the
// tip figures are accurate to ~1e-13 relative (typically a few 1e-15) for all alpha and psi,
// except where the problem itself is ill-conditioned: pure compression within ~1e-8 of Euler's
// load. The shape uses Jacobi functions from descending Landen transformations written in k', at
// arguments <= K/2 only (reflecting the far half), so they stay accurate when k' is tiny.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include <boost/math/special_functions/ellint_rd.hpp>
#include <boost/math/special_functions/ellint_rf.hpp>

#include <tubeplan/model/elastica.hpp>

#include "model/gauss_legendre.hpp"

namespace tubeplan::model {
namespace {

// pi/2 as the double nearest to it: psi = +-kHalfPi is taken as exactly axial, so
// std::numbers::pi / 2 passed by a caller means pure tension or compression.
constexpr double kHalfPi = 1.5707963267948966;
// Euler's load pi^2/4 of the cantilever.
constexpr double kEulerAlpha = 2.4674011002723395;
constexpr double kMaxAlpha = kMaxElasticaAlpha;
// Below this the perturbation series (order kSeriesOrder) replaces the elliptic solution. Both
// agree to the elliptic forms' rounding (<= 1e-14) for 1e-5 <= alpha <= 3e-3 over all psi; the
// truncation error ~(alpha / 2.5)^6 of the series grows past that above ~3e-3.
constexpr double kSeriesMaxAlpha = 1e-3;
constexpr int kSeriesOrder = 6;
// Below this the closed forms for the tip position lose more than ~1e-14 to cancellation and
// quadrature takes over; above it sqrt(alpha) could exceed K/2, the range of the Jacobi functions
// used there.
constexpr double kQuadratureMaxAlpha = 0.5;
constexpr int kSeriesDegree = 2 * kSeriesOrder + 1;  // x(s) and h(s) have degree 2N + 1
// A load within this angle of the axis is treated as axial: the lateral response is then below
// 1e-60 and keeping it would underflow k'^2 at large alpha.
constexpr double kAxialAngle = 1e-60;

// Boost's default promotes double to long double inside the Carlson forms; plain double is
// accurate to a few ulp here and four times faster.
using CarlsonPolicy = boost::math::policies::policy<boost::math::policies::promote_double<false>>;

double Rf(double x, double y, double z) { return boost::math::ellint_rf(x, y, z, CarlsonPolicy()); }
double Rd(double x, double y, double z) { return boost::math::ellint_rd(x, y, z, CarlsonPolicy()); }

[[noreturn]] void ThrowBad(const char* what, double value, const char* range) {
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer), "SolveElastica: %s = %.17g is %s", what, value, range);
  throw std::invalid_argument(buffer);
}

// The load direction in the forms the formulas need, each computed without cancellation.
struct Loading {
  double psi = 0.0;
  double phi0 = 0.0;  // psi + pi/2: angle of the root tangent in the pendulum
  double gap = 0.0;   // pi/2 - psi = pi - phi0: how far the root tangent is from the load
  double s0 = 0.0;    // sin(phi0 / 2)
  double c0 = 0.0;    // cos(phi0 / 2) = sin(gap / 2)
  double cos_psi = 0.0;
  double sin_psi = 0.0;
};

// The angles of MakeLoading, without its sines.
Loading LoadingAngles(double psi_rad) {
  Loading load;
  load.psi = psi_rad;
  // Both sums are exact or rounded relative to their own size, so neither axial end loses digits.
  load.phi0 = psi_rad + kHalfPi;
  load.gap = kHalfPi - psi_rad;
  if (load.phi0 < kAxialAngle) load.phi0 = 0.0;
  if (load.gap < kAxialAngle) load.gap = 0.0;
  return load;
}

Loading MakeLoading(double psi_rad) {
  Loading load = LoadingAngles(psi_rad);
  load.s0 = std::sin(0.5 * load.phi0);
  load.c0 = std::sin(0.5 * load.gap);
  load.cos_psi = std::sin(std::min(load.phi0, load.gap));
  load.sin_psi = std::sin(psi_rad);
  return load;
}

// A solution's loading: its kept sines when they are its direction's (SolveElastica keeps
// them), else made afresh. The same numbers either way.
Loading LoadingOf(const ElasticaSolution& solution) {
  if (!(solution.loading_psi_rad == solution.psi_rad)) return MakeLoading(solution.psi_rad);
  Loading load = LoadingAngles(solution.psi_rad);
  load.s0 = solution.loading_s0;
  load.c0 = solution.loading_c0;
  load.cos_psi = solution.loading_cos_psi;
  load.sin_psi = solution.loading_sin_psi;
  return load;
}

// The pendulum at a trial tip angle t (with y = gap - t, both passed so that whichever is small
// is exact). Arguments of R_F are scaled by 1/c0^2 so that nothing underflows near tension.
struct Trial {
  double t = 0.0;
  double y = 0.0;
  double k = 0.0;   // sin(A/2)
  double kc = 0.0;  // cos(A/2) = sin(y/2)
  double d = 0.0;   // k^2 - s0^2
  double r = 0.0;   // kc / c0 = dn at the root (<= 1)
  double rf = 0.0;  // R_F(r^2 s0^2, r^2 k^2, k^2) = c0 R_F(k'^2 s0^2, k'^2 k^2, k^2 c0^2)
};

Trial MakeTrial(const Loading& load, double t, double y) {
  Trial trial;
  trial.t = t;
  trial.y = y;
  trial.k = std::sin(0.5 * (load.phi0 + t));
  trial.kc = std::sin(0.5 * y);
  // sin(phi0 + t/2) = sin(y + t/2): take the smaller angle so the sine keeps its relative digits.
  trial.d = std::sin(0.5 * t) * std::sin(std::min(load.phi0, y) + 0.5 * t);
  trial.r = trial.kc / load.c0;
  const double r_sq = trial.r * trial.r;
  const double k_sq = trial.k * trial.k;
  trial.rf = Rf(r_sq * load.s0 * load.s0, r_sq * k_sq, k_sq);
  return trial;
}

// log(alpha(t)) - log(alpha): increasing in t.
double Residual(const Loading& load, const Trial& trial, double log_alpha) {
  return std::log(trial.d / (load.c0 * load.c0)) + 2.0 * std::log(trial.rf) - log_alpha;
}

// d Residual / dt, from dk^2/dt = k k', dk'^2/dt = -k k' and dR_F/dx = -R_D(y, z, x) / 6.
double ResidualSlope(const Loading& load, const Trial& trial) {
  const double kkc = trial.k * trial.kc;
  const double r_sq = trial.r * trial.r;
  const double k_sq = trial.k * trial.k;
  const double x = r_sq * load.s0 * load.s0;
  const double y = r_sq * k_sq;
  const double z = k_sq;
  const double c0_sq = load.c0 * load.c0;
  const double dy = kkc * (trial.kc * trial.kc - k_sq) / c0_sq;
  const double dz = kkc;
  const double rd_y = Rd(x, z, y);
  const double rd_z = Rd(x, y, z);
  double sum = rd_y * dy + rd_z * dz;
  // With s0 = 0 the first argument is identically zero and its term vanishes. Otherwise its R_D
  // comes from the other two by Carlson's identity (DLMF 19.21.13; R_D is symmetric in its first
  // two arguments) R_D(y, z, x) + R_D(z, x, y) + R_D(x, y, z) = 3 / sqrt(x y z), which saves
  // one of the three R_D a slope (a long chain of square roots). No digits are lost: x <= y <= z
  // (s0 < k as d > 0, and r <= 1), and R_D decreases fastest in its third argument, so R_D(y, z, x)
  // is the largest of the three, at least a third of the sum it is taken from. sqrt(x y z) is
  // formed from its factors' roots r s0, r k and k, so the product cannot underflow before x does.
  if (load.s0 > 0.0) {
    const double rd_x = 3.0 / (r_sq * load.s0 * k_sq) - rd_y - rd_z;
    sum += rd_x * (-load.s0 * load.s0 * kkc / c0_sq);
  }
  return kkc / trial.d - sum / (3.0 * trial.rf);
}

struct RootResult {
  Trial trial;
  int iterations = 0;
  bool straight = false;  // pure compression within rounding of Euler's load: no buckle found
};

// Newton on an increasing residual(v), kept inside the bracket residual(lo) < 0 < residual(hi)
// by bisection whenever a step would leave it or fails to halve.
template <typename Eval>
Trial BracketedNewton(Eval&& eval, double lo, double hi, double residual_lo, double residual_hi,
                      double start, int& iterations) {
  double v = start;
  double step_prev = hi - lo;
  double residual = 0.0;
  double slope = 0.0;
  Trial trial = eval(v, residual, slope);
  for (int i = 0; i < 200 && residual != 0.0; ++i) {
    ++iterations;
    if (residual < 0.0) {
      lo = v;
      residual_lo = residual;
    } else {
      hi = v;
      residual_hi = residual;
    }
    const double step = residual / slope;
    double next = v - step;
    // Newton must stay inside the bracket and must at least halve the step; otherwise bisect.
    const bool newton =
        slope > 0.0 && next >= lo && next <= hi && std::abs(step) <= 0.5 * std::abs(step_prev);
    // After a Newton step this small, quadratic convergence has reached rounding level.
    if (newton && std::abs(step) <= 1e-9 * std::max(1.0, std::abs(v))) {
      if (next != v) trial = eval(next, residual, slope);
      break;
    }
    if (!newton) {
      // Just above Euler's load the residual is flat and its rounding noise (a few 1e-15) hides
      // the root; once the whole bracket is within that noise, bisecting further is pointless.
      if (residual_hi - residual_lo <= 1e-14) break;
      next = 0.5 * (lo + hi);
    }
    step_prev = next - v;
    v = next;
    trial = eval(v, residual, slope);
    if (hi - lo <= 4e-16 * std::max(1.0, std::abs(v))) break;
  }
  return trial;
}

// The trial, and with it the residual and its slope, in the two unknowns SolveAmplitude uses:
// p = log t while the tip angle t is below half its range, q = -log y (y = gap - t, exact from
// k') above it.
Trial TrialLowAngle(const Loading& load, double p) {
  const double t = std::exp(p);
  return MakeTrial(load, t, load.gap - t);
}
Trial TrialHighAngle(const Loading& load, double q) {
  const double y = std::exp(-q);
  return MakeTrial(load, load.gap - y, y);
}
Trial EvalLowAngle(const Loading& load, double log_alpha, double p, double& residual,
                   double& slope) {
  const Trial trial = TrialLowAngle(load, p);
  residual = Residual(load, trial, log_alpha);
  slope = trial.t * ResidualSlope(load, trial);
  return trial;
}
Trial EvalHighAngle(const Loading& load, double log_alpha, double q, double& residual,
                    double& slope) {
  const Trial trial = TrialHighAngle(load, q);
  residual = Residual(load, trial, log_alpha);
  slope = trial.y * ResidualSlope(load, trial);
  return trial;
}

// Newton from a nearby solution's tip angle (the last tick's, a finite difference's base):
// the residual increases in t over (0, gap) and has one root there, so where Newton converges
// it finds the root SolveAmplitude's bracketed search finds, to rounding, in two or three
// evaluations instead of six to eight. It gives up (false) after kWarmIterations, on a
// non-positive slope or on leaving (0, gap); the caller then searches from scratch.
constexpr int kWarmIterations = 6;
bool SolveAmplitudeFrom(const Loading& load, double alpha, double t_near, double y_near,
                        RootResult& result) {
  const double gap = load.gap;
  const bool low = t_near < 0.5 * gap;
  // (t rounds to gap where y is below its ulp: only y is checked on that side.)
  if (low ? !(t_near > 0.0) : !(y_near > 0.0 && y_near < gap)) return false;
  const double log_alpha = std::log(alpha);
  double v = low ? std::log(t_near) : -std::log(y_near);
  const double v_max = low ? std::log(gap) : 1e300;  // t < gap; y > 0 always
  const double v_min = low ? -1e300 : -std::log(gap);
  for (int i = 0; i < kWarmIterations; ++i) {
    double residual = 0.0, slope = 0.0;
    Trial trial = low ? EvalLowAngle(load, log_alpha, v, residual, slope)
                      : EvalHighAngle(load, log_alpha, v, residual, slope);
    ++result.iterations;
    if (residual == 0.0) {
      result.trial = trial;
      return true;
    }
    if (!(slope > 0.0) || !std::isfinite(residual)) return false;
    const double step = residual / slope;
    const double next = v - step;
    if (!(next > v_min && next < v_max)) return false;
    // The same end as BracketedNewton's: after a step this small, the trial at the step's end.
    // Its residual and slope would not be used: only the trial is formed (the slope's three R_D
    // and the residual's logarithms are saved; the numbers are the same).
    if (std::abs(step) <= 1e-9 * std::max(1.0, std::abs(v))) {
      if (next != v) {
        trial = low ? TrialLowAngle(load, next) : TrialHighAngle(load, next);
        ++result.iterations;
      }
      result.trial = trial;
      return true;
    }
    v = next;
  }
  return false;
}

RootResult SolveAmplitude(const Loading& load, double alpha) {
  RootResult result;
  const double log_alpha = std::log(alpha);
  const double gap = load.gap;
  const Trial middle = MakeTrial(load, 0.5 * gap, 0.5 * gap);
  const double middle_residual = Residual(load, middle, log_alpha);
  ++result.iterations;
  if (middle_residual == 0.0) {
    result.trial = middle;
    return result;
  }
  if (middle_residual > 0.0) {
    // Tip angle below half its range: unknown p = log t, residual increasing in p.
    auto eval = [&](double p, double& residual, double& slope) {
      return EvalLowAngle(load, log_alpha, p, residual, slope);
    };
    const double hi = std::log(0.5 * gap);
    // Linear theory t = alpha cos(psi) / 2 is a good start; compression amplifies it (so it is
    // then a lower end already), tension shrinks it, and the slope in p is about 1 for small t.
    double lo = std::min(hi - 1e-3, std::log(std::max(0.5 * alpha * load.cos_psi, 1e-3 * gap)));
    const double lowest = std::log(gap) - 300.0;
    double residual = 0.0;
    double slope = 0.0;
    for (;;) {
      eval(lo, residual, slope);
      ++result.iterations;
      if (residual < 0.0) break;
      if (lo <= lowest) {
        // Only pure compression within rounding of Euler's load gets here (its residual tends
        // to log(pi^2/4 / alpha) >= 0 as t -> 0): the straight rod is the answer.
        result.straight = true;
        return result;
      }
      lo = std::max(lowest, lo - (residual + 1.0));
    }
    const double start = (residual > -1.0) ? lo : 0.5 * (lo + hi);
    result.trial =
        BracketedNewton(eval, lo, hi, residual, middle_residual, start, result.iterations);
  } else {
    // Tip nearly along the load: unknown v = -log y, in which the residual increases.
    auto eval = [&](double q, double& residual, double& slope) {
      return EvalHighAngle(load, log_alpha, q, residual, slope);
    };
    const double lo = -std::log(0.5 * gap);  // residual < 0 here (the middle)
    // Large-alpha asymptotics k' ~ 4 exp(-sqrt(alpha) - atanh(s0)) give the start.
    const double guess_y = 8.0 * load.c0 / (1.0 + load.s0) * std::exp(-std::sqrt(alpha));
    double hi = std::max(lo + 1.0, -std::log(guess_y) + 3.0);
    double residual = 0.0;
    double slope = 0.0;
    for (int i = 0; i < 60; ++i) {
      eval(hi, residual, slope);
      ++result.iterations;
      if (residual > 0.0) break;
      // The residual grows only like 2 log(q): double q until it turns positive.
      hi = std::min(2.0 * hi + 1.0, -std::log(gap) + 300.0);
    }
    result.trial = BracketedNewton(eval, lo, hi, middle_residual, residual, 0.5 * (lo + hi),
                                   result.iterations);
  }
  return result;
}

// ---- Jacobi elliptic functions --------------------------------------------------------------

// sn, cn, dn of z for modulus k with complement kc, for 0 <= z <= K(k)/2: descending Landen
// transformations in the complement, which only multiply and add positive numbers, down to a
// modulus below 1e-9 where they are sin, cos, 1; at z <= K/2 that bottom angle is <= pi/4.
struct Jacobi {
  double sn = 0.0;
  double cn = 1.0;
  double dn = 1.0;
};

// The descending Landen moduli of k (with their complements): they depend on k only, so a
// caller that evaluates many arguments at one modulus (the quadrature nodes, the shape's samples)
// computes them once.
struct LandenChain {
  static constexpr int kMaxLevels = 24;
  // Left uninitialised: MakeLandenChain writes the levels it uses (1 to `levels`) and nothing
  // reads past them. Level 0 is k and kc below; of the complements k_n' only their
  // squares are read (kcs_sq).
  std::array<double, kMaxLevels> ks;
  // Per level, the terms JacobiFunctions forms of the modulus alone: 1 + k_n, k_n^2 and k_n'^2,
  // each the same rounding as formed there, so once per chain instead of once per argument.
  std::array<double, kMaxLevels> one_plus_ks;
  std::array<double, kMaxLevels> ks_sq;
  std::array<double, kMaxLevels> kcs_sq;
  // The product of 1 + k_n over the levels: the descent's one division of the argument.
  double descent = 1.0;
  int levels = 0;
  double k = 0.0, kc = 1.0;
  double k_sq = 0.0, kc_sq = 1.0;
};

LandenChain MakeLandenChain(double k, double kc) {
  LandenChain chain;
  chain.k = k;
  chain.kc = kc;
  // A level's terms are formed in the descent's own loop, as soon as its modulus is.
  int n = 0;
  double k_n = k, kc_n = kc;
  double descent = 1.0;
  while (k_n > 1e-9 && n + 1 < LandenChain::kMaxLevels) {
    const double one_plus = 1.0 + kc_n;
    const double k_next = k_n * k_n / (one_plus * one_plus);
    const double kc_next = 2.0 * std::sqrt(kc_n) / one_plus;
    const double one_plus_next = 1.0 + k_next;
    const std::size_t i = std::size_t(++n);
    chain.ks[i] = k_next;
    chain.one_plus_ks[i] = one_plus_next;
    chain.ks_sq[i] = k_next * k_next;
    chain.kcs_sq[i] = kc_next * kc_next;
    descent *= one_plus_next;
    k_n = k_next;
    kc_n = kc_next;
  }
  chain.levels = n;
  chain.descent = descent;
  chain.k_sq = k * k;
  chain.kc_sq = kc * kc;
  return chain;
}

Jacobi JacobiFunctions(double z, const LandenChain& chain) {
  const auto& ks = chain.ks;
  const int n = chain.levels;
  // One division for the descent and one a level for the ascent:
  // the divider is the slowest unit here, and a tick with a small-alpha segment evaluates these
  // a dozen times (the tip's quadrature). Each product rounds once more than the quotient it
  // replaces: a few ulp over the levels, as the rest of the chain (elastica_test.cpp).
  z /= chain.descent;
  double sn = std::sin(z);
  double cn = std::cos(z);
  for (int level = n; level >= 1; --level) {
    const std::size_t i = std::size_t(level);
    const double dn = std::sqrt(chain.kcs_sq[i] + chain.ks_sq[i] * cn * cn);
    const double inv_den = 1.0 / (1.0 + ks[i] * sn * sn);
    sn = chain.one_plus_ks[i] * sn * inv_den;
    cn = cn * dn * inv_den;
  }
  return {sn, cn, std::sqrt(chain.kc_sq + chain.k_sq * cn * cn)};
}

// ---- Tip displacement by quadrature (moderate alpha) ---------------------------------------

// Gauss-Legendre rule on [0, 1]. The integrands are analytic well beyond [0, 1] for
// alpha <= kQuadratureMaxAlpha: 8 points already reach rounding level there, 6 lose 1e-11 at
// alpha = 0.4 (measured); 10 leave a margin.
constexpr int kGaussPoints = 10;
static_assert(kGaussPoints % 2 == 0, "the quadrature pairs its nodes about 1/2");

struct GaussRule {
  std::array<double, kGaussPoints> node{};
  std::array<double, kGaussPoints> weight{};
};

const GaussRule& Gauss() {
  static const GaussRule rule = [] {
    // Mapped from [-1, 1] to [0, 1]: nodes (1 + x) / 2, weights halved.
    const auto legendre = MakeGaussLegendreRule<kGaussPoints>();
    GaussRule r;
    for (std::size_t i = 0; i < kGaussPoints; ++i) {
      r.node[i] = 0.5 * (1.0 + legendre.nodes[i]);
      r.weight[i] = 0.5 * legendre.weights[i];
    }
    return r;
  }();
  return rule;
}

// x(1) and h(1) as integrals of sin(theta) and 2 sin^2(theta/2). The closed forms for them
// subtract the straight rod (losing ~1e-16 / alpha^2 at small alpha); here sin(theta/2) and
// cos(theta/2) come from the addition theorem about the root, tau = tau0 + sigma, which leaves
// sums of positive terms except one benign difference (a factor <= ~2).
void TipDisplacementByQuadrature(const Loading& load, const Trial& trial, double sqrt_alpha,
                                 double& deflection, double& shortening) {
  const GaussRule& rule = Gauss();
  const double root_d = std::sqrt(trial.d);  // k cn(tau0)
  const double s0 = load.s0;
  const double c0 = load.c0;
  const LandenChain chain = MakeLandenChain(trial.k, trial.kc);
  // The rule is symmetric about 1/2: the nodes above it are sqrt(alpha) - sigma for the nodes
  // sigma below it, whose functions come from those at sqrt(alpha) and at sigma by the addition
  // theorem (sums of positive terms but sn's difference, over half its larger term as sigma <=
  // 0.43 sqrt(alpha), and a denominator within 4 % of 1 for sqrt(alpha) <= 0.71). Six descents
  // instead of ten.
  std::array<Jacobi, kGaussPoints> at{};
  const Jacobi end = JacobiFunctions(sqrt_alpha, chain);
  for (int i = 0; i < kGaussPoints / 2; ++i) {
    const Jacobi j = JacobiFunctions(sqrt_alpha * rule.node[std::size_t(i)], chain);
    const double sn_sn = end.sn * j.sn;
    const double den = 1.0 - chain.k_sq * sn_sn * sn_sn;
    at[std::size_t(i)] = j;
    at[std::size_t(kGaussPoints - 1 - i)] = {
        (end.sn * j.cn * j.dn - j.sn * end.cn * end.dn) / den,
        (end.cn * j.cn + sn_sn * end.dn * j.dn) / den,
        (end.dn * j.dn + chain.k_sq * sn_sn * end.cn * j.cn) / den};
  }
  double sum_x = 0.0;
  double sum_h = 0.0;
  for (int i = 0; i < kGaussPoints; ++i) {
    const Jacobi& j = at[std::size_t(i)];
    const double sn_sq = j.sn * j.sn;
    const double den = 1.0 - s0 * s0 * sn_sq;
    const double mix = c0 * c0 + s0 * s0 * j.cn;
    const double one_minus_cn = sn_sq / (1.0 + j.cn);
    const double sin_half = (root_d * j.sn * mix - s0 * c0 * j.dn * one_minus_cn) / den;
    const double cos_half = (j.dn * mix + s0 * c0 * root_d * j.sn * one_minus_cn) / den;
    sum_x += rule.weight[std::size_t(i)] * 2.0 * sin_half * cos_half;
    sum_h += rule.weight[std::size_t(i)] * 2.0 * sin_half * sin_half;
  }
  deflection = sum_x;
  shortening = sum_h;
}

// ---- Small-alpha series ----------------------------------------------------------------------

// theta = sum_n alpha^n theta_n(s), each theta_n a polynomial of degree 2n in s, built from
// theta_n'' = -(cos psi C_{n-1} - sin psi S_{n-1}) with cos(theta) = sum C_n alpha^n,
// sin(theta) = sum S_n alpha^n, then summed into polynomials in s for the given alpha.
struct SeriesShape {
  std::array<double, kSeriesDegree + 1> theta{};  // theta(s)
  std::array<double, kSeriesDegree + 1> x{};      // x(s) = int_0^s sin(theta)
  std::array<double, kSeriesDegree + 1> h{};      // s - z(s) = int_0^s 2 sin^2(theta/2)
};

using SeriesTable = std::array<std::array<double, kSeriesDegree + 1>, kSeriesOrder + 1>;

SeriesShape BuildSeries(double alpha, const Loading& load) {
  SeriesTable theta{};  // theta[n], degree 2n
  SeriesTable cosine{};
  SeriesTable sine{};
  cosine[0][0] = 1.0;
  for (int n = 1; n <= kSeriesOrder; ++n) {
    // Load term g = cos(psi) C_{n-1} - sin(psi) S_{n-1} (degree 2n - 2); theta_n'' = -g with
    // theta_n(0) = 0, theta_n'(1) = 0.
    const int deg_g = 2 * n - 2;
    double slope_root = 0.0;  // theta_n'(0) = int_0^1 g
    for (int i = 0; i <= deg_g; ++i) {
      const double g = load.cos_psi * cosine[n - 1][i] - load.sin_psi * sine[n - 1][i];
      slope_root += g / (i + 1);
      theta[n][i + 2] = -g / ((i + 1.0) * (i + 2.0));
    }
    theta[n][1] = slope_root;
    // Composition recurrences n S_n = sum_j j theta_j C_{n-j}, n C_n = -sum_j j theta_j S_{n-j},
    // accumulated per output coefficient.
    for (int m = 0; m <= 2 * n; ++m) {
      double sum_sine = 0.0;
      double sum_cosine = 0.0;
      for (int j = 1; j <= n; ++j) {
        const int i_lo = std::max(0, m - 2 * (n - j));
        const int i_hi = std::min(2 * j, m);
        double part_sine = 0.0;
        double part_cosine = 0.0;
        for (int i = i_lo; i <= i_hi; ++i) {
          part_sine += theta[j][i] * cosine[n - j][m - i];
          part_cosine += theta[j][i] * sine[n - j][m - i];
        }
        sum_sine += j * part_sine;
        sum_cosine += j * part_cosine;
      }
      sine[n][m] = sum_sine / n;
      cosine[n][m] = -sum_cosine / n;
    }
  }
  SeriesShape shape;
  double power = 1.0;
  for (int n = 1; n <= kSeriesOrder; ++n) {
    power *= alpha;
    for (int p = 0; p <= 2 * n; ++p) {
      shape.theta[p] += power * theta[n][p];
      shape.x[p + 1] += power * sine[n][p] / (p + 1);
      shape.h[p + 1] -= power * cosine[n][p] / (p + 1);
    }
  }
  return shape;
}

double EvalPolynomial(const std::array<double, kSeriesDegree + 1>& c, double s) {
  double value = 0.0;
  for (int p = kSeriesDegree; p >= 0; --p) value = value * s + c[p];
  return value;
}

double SumCoefficients(const std::array<double, kSeriesDegree + 1>& c) {
  double sum = 0.0;
  for (int p = kSeriesDegree; p >= 0; --p) sum += c[p];
  return sum;
}

void SolveSeries(const Loading& load, ElasticaSolution& solution) {
  const SeriesShape shape = BuildSeries(solution.alpha, load);
  ElasticaTip& tip = solution.tip;
  tip.tip_angle_rad = SumCoefficients(shape.theta);
  tip.deflection = SumCoefficients(shape.x);
  tip.shortening = SumCoefficients(shape.h);
  tip.root_curvature = shape.theta[1];
  // U = 1/2 int theta'^2 with theta' = sum_p p theta_p s^(p-1).
  double energy = 0.0;
  for (int p = 1; p <= kSeriesDegree; ++p) {
    for (int q = 1; q <= kSeriesDegree; ++q) {
      energy += p * shape.theta[p] * q * shape.theta[q] / (p + q - 1);
    }
  }
  tip.energy = 0.5 * energy;
  solution.series = true;
  // The pendulum parameters, for information only (the shape comes from the series).
  const double amplitude = load.phi0 + tip.tip_angle_rad;
  solution.modulus_k = std::sin(0.5 * amplitude);
  solution.modulus_kc = std::sin(0.5 * (load.gap - tip.tip_angle_rad));
  const double d = std::sin(0.5 * tip.tip_angle_rad) *
                   std::sin(std::min(load.phi0, load.gap) + 0.5 * tip.tip_angle_rad);
  solution.u0 = std::atan2(load.s0, std::sqrt(std::max(d, 0.0)));
}

void SolveElliptic(const Loading& load, ElasticaSolution& solution, const ElasticaSolution* near) {
  const double alpha = solution.alpha;
  RootResult root;
  // A start from a nearby solution, unless it is a series answer or straight (no pendulum), or
  // the load is pure compression (straight or buckled is decided near Euler's load by the
  // search from scratch).
  bool warm = false;
  if (near && !near->series && near->tip.tip_angle_rad > 0.0 && load.phi0 > 0.0) {
    // Its tip angle t, and its distance y from the load's direction (from k' = sin(y / 2), exact
    // where t rounds to gap), each scaled by how its first-order estimate changes between the
    // two loads: t by linear theory's alpha cos(psi) / 2, y by the large-alpha asymptote
    // 8 c0 / (1 + s0) e^-sqrt(alpha) (SolveAmplitude's starts), so that a change of the load's
    // direction is followed as well.
    const Loading near_load = LoadingOf(*near);
    const double t_near =
        near->tip.tip_angle_rad * (alpha * load.cos_psi) / (near->alpha * near_load.cos_psi);
    // y is SolveAmplitudeFrom's unknown only where t is above half its range: below it (the
    // tick's warm starts, as a rule) its asin, exp and two roots would be formed for nothing.
    const double y_near = t_near < 0.5 * load.gap
                              ? 0.0
                              : 2.0 * std::asin(std::min(near->modulus_kc, 1.0)) *
                                    (load.c0 / near_load.c0) *
                                    ((1.0 + near_load.s0) / (1.0 + load.s0)) *
                                    std::exp(std::sqrt(near->alpha) - std::sqrt(alpha));
    warm = SolveAmplitudeFrom(load, alpha, t_near, y_near, root);
  }
  if (!warm) {
    const int tried = root.iterations;
    root = SolveAmplitude(load, alpha);
    root.iterations += tried;
  }
  solution.iterations = root.iterations;
  if (root.straight) return;
  const Trial& tr = root.trial;
  const double sqrt_alpha = std::sqrt(alpha);
  const double c0 = load.c0;
  const double r_sq = tr.r * tr.r;
  const double k_sq = tr.k * tr.k;
  const double d_scaled = tr.d / (c0 * c0);
  ElasticaTip& tip = solution.tip;
  tip.tip_angle_rad = tr.t;
  tip.root_curvature = 2.0 * sqrt_alpha * std::sqrt(tr.d);
  tip.energy = (2.0 / 3.0) * sqrt_alpha * k_sq * r_sq * c0 * c0 * d_scaled * std::sqrt(d_scaled) *
               Rd(r_sq * load.s0 * load.s0, k_sq, r_sq * k_sq);
  if (alpha <= kQuadratureMaxAlpha) {
    TipDisplacementByQuadrature(load, tr, sqrt_alpha, tip.deflection, tip.shortening);
  } else {
    // Tip displacement from the straight rod along the load, from the energy identity
    // U = alpha (sin(theta(1) + psi) - r(1).e_F), and across it, from the root moment
    // theta'(0) = alpha r(1).e_P with e_F = (cos psi, sin psi), e_P = (-sin psi, cos psi).
    const double along = 2.0 * tr.d - tip.energy / alpha;
    const double across = 2.0 * c0 * (1.0 - load.s0 * tr.rf) / tr.rf;
    tip.deflection = along * load.cos_psi - across * load.sin_psi;
    tip.shortening = -(along * load.sin_psi + across * load.cos_psi);
  }
  solution.modulus_k = tr.k;
  solution.modulus_kc = tr.kc;
  solution.u0 = std::atan2(load.s0, std::sqrt(tr.d));
}

// ---- Shape -----------------------------------------------------------------------------------

// Position of the tip relative to the point at arc length s, in the load frame (along e_F,
// across e_P), and theta(s), from the Jacobi functions at w = sqrt(alpha) (1 - s) measured from
// the tip.
struct FromTip {
  double along = 0.0;
  double across = 0.0;
  // A/2 - phi/2 = atan2(gap_y, gap_x), so theta = theta(1) - 2 atan2(gap_y, gap_x); kept as the
  // pair so that a caller wanting the tangent's sine and cosine needs no atan2 and no sincos.
  double gap_x = 1.0;
  double gap_y = 0.0;
};

double Theta(const ElasticaSolution& solution, const FromTip& f) {
  return solution.tip.tip_angle_rad - 2.0 * std::atan2(f.gap_y, f.gap_x);
}

// (sin theta, cos theta) = the unit tangent (dx/ds, dz/ds), by the double-angle formulas.
Eigen::Vector2d Tangent(double sin_tip, double cos_tip, double gap_x, double gap_y) {
  const double m = std::max(std::abs(gap_x), std::abs(gap_y));  // > 0: gap_x >= k'^2 > 0
  const double x = gap_x / m, y = gap_y / m;
  const double r_sq = x * x + y * y;
  const double cos_2h = (x * x - y * y) / r_sq;
  const double sin_2h = 2.0 * x * y / r_sq;
  return {sin_tip * cos_2h - cos_tip * sin_2h, cos_tip * cos_2h + sin_tip * sin_2h};
}

// The shape figures from sn, cn, dn at w and D(w) = w - E(w) = int_0^w k^2 sn^2 (Jacobi's
// epsilon function E): every sample of the shape comes through here, however those were found.
// The modulus k and its complement kc come as values, not in the solution.
FromTip FromJacobi(double k, double kc, double sqrt_alpha, double s, double sn, double cn,
                   double dn, double big_d) {
  FromTip out;
  // int_s^1 sin(phi) = 2 k k' sd(w) / sqrt(alpha);
  // int_s^1 -cos(phi) = (2 int_0^w k^2 cd^2 - w) / sqrt(alpha) with
  // int_0^w k^2 cd^2 = D(w) + k^2 sn cd.
  out.across = 2.0 * k * kc * sn / (dn * sqrt_alpha);
  const double cd_integral = big_d + k * k * sn * cn / dn;
  out.along = 2.0 * cd_integral / sqrt_alpha - (1.0 - s);
  // A/2 - phi/2 = atan(k k' (1 - cn) / (k'^2 + k^2 cn)) with 1 - cn = sn^2 / (1 + cn).
  out.gap_y = k * kc * sn * sn / (1.0 + cn);
  out.gap_x = kc * kc + k * k * cn;
  return out;
}

// D(z) = z - E(z) = (k^2 / 3) sn^3 R_D(cn^2, dn^2, 1).
double EpsilonDefect(double k, const Jacobi& j) {
  return k * k * j.sn * j.sn * j.sn * Rd(j.cn * j.cn, j.dn * j.dn, 1.0) / 3.0;
}

// sn, cn, dn at w from those at tau = K - w: sn(K - tau) = cd(tau), cn(K - tau) = k' sd(tau),
// dn(K - tau) = k' nd(tau); and D(K - tau) = D(K) - D(tau) - k^2 sn(tau) cd(tau) (the addition
// theorem of E), D(K) = (k^2 / 3) R_D(0, k'^2, 1).
Jacobi ReflectedJacobi(double kc, const Jacobi& at_tau) {
  return {at_tau.cn / at_tau.dn, kc * at_tau.sn / at_tau.dn, kc / at_tau.dn};
}
struct Reflected {
  Jacobi at_w;
  double big_d = 0.0;
};
Reflected Reflect(double k, double kc, const Jacobi& at_tau, double d_tau, double d_complete) {
  Reflected r;
  r.at_w = ReflectedJacobi(kc, at_tau);
  r.big_d = d_complete - d_tau - k * k * at_tau.sn * r.at_w.sn;
  return r;
}

FromTip ShapeFromTip(const ElasticaSolution& solution, const LandenChain& chain, double sqrt_alpha,
                     double tau0, double s) {
  const double k = solution.modulus_k;
  const double w = sqrt_alpha * (1.0 - s);
  const double tau = tau0 + sqrt_alpha * s;  // = K - w
  if (w <= tau) {
    const Jacobi j = JacobiFunctions(w, chain);
    return FromJacobi(k, solution.modulus_kc, sqrt_alpha, s, j.sn, j.cn, j.dn, EpsilonDefect(k, j));
  }
  // Reflection about K/2 keeps the Landen forms at arguments <= K/2. D(w) straight from R_D at
  // the reflected sn, cn, dn: accurate, and one R_D as the direct branch.
  const Jacobi j = ReflectedJacobi(solution.modulus_kc, JacobiFunctions(tau, chain));
  return FromJacobi(k, solution.modulus_kc, sqrt_alpha, s, j.sn, j.cn, j.dn, EpsilonDefect(k, j));
}

// sn, cn, dn and D at u + v from those at u and v (the addition theorems). The denominator
// 1 - k^2 sn^2(u) sn^2(v) is written as cn^2(u) + sn^2(u) dn^2(v), a sum of positive terms; the
// numerators of cn and dn subtract, losing a factor up to ~exp(2 v) of their relative accuracy
// as k -> 1, so callers keep v <= 1.
struct Stepped {
  Jacobi j;
  double big_d = 0.0;
};
Stepped AddArgument(double k_sq, const Stepped& u, const Stepped& v) {
  const double su = u.j.sn, cu = u.j.cn, du = u.j.dn;
  const double sv = v.j.sn, cv = v.j.cn, dv = v.j.dn;
  const double den = cu * cu + su * su * dv * dv;
  Stepped out;
  out.j.sn = (su * cv * dv + sv * cu * du) / den;
  out.j.cn = (cu * cv - su * sv * du * dv) / den;
  out.j.dn = (du * dv - k_sq * su * sv * cu * cv) / den;
  out.big_d = u.big_d + v.big_d + k_sq * su * sv * out.j.sn;
  return out;
}

// The addition theorems step functions that decay like exp(-u) as k -> 1 (cn, dn): an error
// made in them grows like exp(2 u) along the walk (measured: 1e-9 of l after a walk of K/2 ~ 8
// at alpha = 260). So sn, cn and dn are evaluated afresh (Landen) once the walk since the last
// fresh evaluation reaches kJacobiAnchor, which bounds the growth by exp(2 * 0.5) ~ 2.7; D only
// adds positive terms made of sn and needs no anchor.
constexpr double kJacobiAnchor = 0.5;

// tau0 = F(u0|k) with sin u0 = s0/k, cos u0 = sqrt(D)/k and Delta(u0) = c0: the root's argument.
double RootArgument(const ElasticaSolution& solution, const Loading& load) {
  const double sin_u0 = std::sin(solution.u0);
  const double cos_u0 = std::cos(solution.u0);
  return sin_u0 * Rf(cos_u0 * cos_u0, load.c0 * load.c0, 1.0);
}

// The series' centreline point at s.
Eigen::Vector2d SeriesPoint(const SeriesShape& shape, double s) {
  return {EvalPolynomial(shape.x, s), s - EvalPolynomial(shape.h, s)};
}

// Positions from the tip-relative figures: the closed forms give the whole tip position
// relative to the root too; its tiny difference from the tip figures (rounding) is spread
// linearly so that s = 0 and s = 1 are both exact.
struct FromRoot {
  FromRoot(const ElasticaSolution& solution, const Loading& load, double root_along,
           double root_across)
      : cos_psi(load.cos_psi), sin_psi(load.sin_psi), along0(root_along), across0(root_across) {
    const ElasticaTip& tip = solution.tip;
    error_x = tip.deflection - (along0 * cos_psi - across0 * sin_psi);
    error_z = (1.0 - tip.shortening) - (along0 * sin_psi + across0 * cos_psi);
  }
  Eigen::Vector2d At(double s, double along_here, double across_here) const {
    const double along = along0 - along_here;
    const double across = across0 - across_here;
    return {along * cos_psi - across * sin_psi + s * error_x,
            along * sin_psi + across * cos_psi + s * error_z};
  }
  double cos_psi, sin_psi, along0, across0, error_x = 0.0, error_z = 0.0;
};

// The arc length of sample j of n spread over [first, last]. (Over [0, 1]: 0 + 1 * (j / last),
// the same bits as j / last.)
struct SampleArcs {
  SampleArcs(double s_first, double s_last, std::size_t n)
      : first(s_first), last(s_last), count(n), span(s_last - s_first), last_index(double(n - 1)) {}
  double operator()(std::size_t j) const {
    return j + 1 == count ? last : first + span * (double(j) / last_index);
  }
  double first, last;
  std::size_t count;
  double span, last_index;
};

// D(K) = (k^2 / 3) R_D(0, k'^2, 1), formed when a reflection first needs it (a whole segment
// whose root lies within K/2 of its tip reflects none).
class CompleteDefect {
 public:
  CompleteDefect(double k_sq, double kc) : k_sq_(k_sq), kc_(kc) {}
  double operator()() {
    if (kept_ < 0.0) kept_ = k_sq_ * Rd(0.0, kc_ * kc_, 1.0) / 3.0;
    return kept_;
  }

 private:
  double k_sq_, kc_;
  double kept_ = -1.0;  // D(K) >= 0: negative while not formed
};

// The step's functions, at delta <= K (beyond K/2 by reflection, n = 2 only); big_k = K.
Stepped StepFunctions(double delta, double big_k, double k, double kc, const LandenChain& chain,
                      CompleteDefect& d_complete) {
  Stepped step;
  if (delta <= 0.5 * big_k) {
    step.j = JacobiFunctions(delta, chain);
    step.big_d = EpsilonDefect(k, step.j);
  } else {
    Stepped other;
    other.j = JacobiFunctions(big_k - delta, chain);
    other.big_d = EpsilonDefect(k, other.j);
    const Reflected r = Reflect(k, kc, other.j, other.big_d, d_complete());
    step.j = r.at_w;
    step.big_d = r.big_d;
  }
  return step;
}

// The root's figures from the tip: the first sample's when it is the root (`first_sample`).
// A root past the first sample is made as the walk would make it: on the root side of K/2 by
// reflection with the same D(K), whose rounding then cancels between the root and the samples
// there (a direct R_D would leave it in: 1.1e-12 of l at alpha = 0.002).
FromTip RootFromTip(const ElasticaSolution& solution, const LandenChain& chain, double sqrt_alpha,
                    double tau0, double s_first, const Eigen::Vector2d& first_sample,
                    CompleteDefect& d_complete) {
  const double k = solution.modulus_k, kc = solution.modulus_kc;
  if (s_first == 0.0) return FromTip{first_sample.x(), first_sample.y()};
  if (sqrt_alpha > tau0) {
    Stepped at_root;
    at_root.j = JacobiFunctions(tau0, chain);
    at_root.big_d = EpsilonDefect(k, at_root.j);
    const Reflected r = Reflect(k, kc, at_root.j, at_root.big_d, d_complete());
    return FromJacobi(k, kc, sqrt_alpha, 0.0, r.at_w.sn, r.at_w.cn, r.at_w.dn, r.big_d);
  }
  return ShapeFromTip(solution, chain, sqrt_alpha, tau0, 0.0);
}

// The elliptic shape's samples: the figures from the tip, (along, across) into xz_out and
// (gap_x, gap_y) into tangent_out, then turned into positions and tangents.
void EllipticSamples(const ElasticaSolution& solution, const Loading& load, const SampleArcs& s_of,
                     std::span<Eigen::Vector2d> xz_out, std::span<Eigen::Vector2d> tangent_out) {
  const std::size_t n = s_of.count;
  const double sqrt_alpha = std::sqrt(solution.alpha);
  const double tau0 = RootArgument(solution, load);
  const LandenChain chain = MakeLandenChain(solution.modulus_k, solution.modulus_kc);
  const auto store = [&](std::size_t j, const FromTip& f) {
    xz_out[j] = Eigen::Vector2d(f.along, f.across);
    tangent_out[j] = Eigen::Vector2d(f.gap_x, f.gap_y);
  };
  // The arguments w = sqrt(alpha) (1 - s) (from the tip) and tau = tau0 + sqrt(alpha) s (from the
  // root) both step by sqrt(alpha) / (n - 1) from sample to sample: the addition theorems carry
  // sn, cn, dn and D from one sample to the next, so a segment costs two Landen evaluations and
  // three R_D instead of one of each per sample. Samples with w <= tau step w up from the tip
  // (w = 0: sn 0, cn 1, dn 1, D 0), the others tau up from the root and are reflected, as in
  // ShapeFromTip.
  const double delta = sqrt_alpha * s_of.span / s_of.last_index;
  const double k = solution.modulus_k, kc = solution.modulus_kc, k_sq = k * k;
  CompleteDefect d_complete(k_sq, kc);
  const Stepped step = StepFunctions(delta, tau0 + sqrt_alpha, k, kc, chain, d_complete);
  // One step forward from `at`, or afresh at `argument()` (<= K/2) when the walk since the last
  // fresh evaluation has reached the anchor spacing (always, for steps longer than it). The
  // argument is formed only then.
  // Also afresh after kAnchorSteps steps: the step's own functions carry a relative error (~5e-14
  // in cn and dn near k = 1) that each step adds again, and a short range of many points (a
  // segment's mesh) walks hundreds of steps within one anchor spacing (2.6e-12 of the tangent
  // at 64 steps). 16 steps: a walk over the whole length (n = 17 samples, the
  // tick's) never reaches it, so the tick keeps its bits.
  constexpr int kAnchorSteps = 16;
  double walked = 0.0;
  int steps = 0;
  const auto advance = [&](const Stepped& at, const auto& argument) {
    Stepped next = AddArgument(k_sq, at, step);
    walked += delta;
    if (walked >= kJacobiAnchor || ++steps > kAnchorSteps) {
      next.j = JacobiFunctions(argument(), chain);
      walked = 0.0;
      steps = 0;
    }
    return next;
  };
  std::size_t first_tip_side = 0;
  const double tau_first = tau0 + sqrt_alpha * s_of(0);
  if (sqrt_alpha * (1.0 - s_of(0)) > tau_first) {  // the first sample lies beyond K/2 from the tip
    Stepped at_tau;
    at_tau.j = JacobiFunctions(tau_first, chain);  // tau < K/2 here, as w + tau = K
    at_tau.big_d = EpsilonDefect(k, at_tau.j);
    std::size_t& i = first_tip_side;
    for (; i < n && sqrt_alpha * (1.0 - s_of(i)) > tau0 + sqrt_alpha * s_of(i); ++i) {
      if (i > 0) at_tau = advance(at_tau, [&] { return tau0 + sqrt_alpha * s_of(i); });
      const Reflected r = Reflect(k, kc, at_tau.j, at_tau.big_d, d_complete());
      store(i, FromJacobi(k, kc, sqrt_alpha, s_of(i), r.at_w.sn, r.at_w.cn, r.at_w.dn, r.big_d));
    }
  }
  walked = 0.0;
  steps = 0;
  Stepped at_w;  // w = 0 at the tip: sn 0, cn 1, dn 1, D 0
  if (s_of.last < 1.0 && first_tip_side < n) {
    // The last sample short of the tip, on the tip side (w <= K/2): evaluated afresh.
    at_w.j = JacobiFunctions(sqrt_alpha * (1.0 - s_of.last), chain);
    at_w.big_d = EpsilonDefect(k, at_w.j);
  }
  for (std::size_t i = n; i-- > first_tip_side;) {
    if (i + 1 < n) at_w = advance(at_w, [&] { return sqrt_alpha * (1.0 - s_of(i)); });
    store(i, FromJacobi(k, kc, sqrt_alpha, s_of(i), at_w.j.sn, at_w.j.cn, at_w.j.dn, at_w.big_d));
  }
  // As in ElasticaCentreline: positions from the root.
  const FromTip root =
      RootFromTip(solution, chain, sqrt_alpha, tau0, s_of.first, xz_out[0], d_complete);
  const FromRoot from_root(solution, load, root.along, root.across);
  // The tip angle's sine and cosine as the caller kept them, else formed.
  const ElasticaTip& tip = solution.tip;
  double sin_tip = solution.tip_sin, cos_tip = solution.tip_cos;
  if (!(solution.tip_trig_angle_rad == tip.tip_angle_rad)) {
    sin_tip = std::sin(tip.tip_angle_rad);
    cos_tip = std::cos(tip.tip_angle_rad);
  }
  for (std::size_t j = 0; j < n; ++j) {
    const double s = s_of(j);
    xz_out[j] = from_root.At(s, xz_out[j].x(), xz_out[j].y());
    tangent_out[j] = s == 0.0 ? Eigen::Vector2d(0.0, 1.0)
                              : Tangent(sin_tip, cos_tip, tangent_out[j].x(), tangent_out[j].y());
  }
}

}  // namespace

ElasticaSolution SolveElastica(double alpha, double psi_rad) {
  return SolveElastica(alpha, psi_rad, nullptr);
}

ElasticaSolution SolveElastica(double alpha, double psi_rad, const ElasticaSolution* near) {
  if (!std::isfinite(alpha)) ThrowBad("alpha", alpha, "not finite");
  if (!std::isfinite(psi_rad)) ThrowBad("psi_rad", psi_rad, "not finite");
  if (alpha < 0.0 || alpha > kMaxAlpha) ThrowBad("alpha", alpha, "outside [0, 1e4]");
  if (psi_rad < -kHalfPi || psi_rad > kHalfPi) {
    ThrowBad("psi_rad", psi_rad, "outside [-pi/2, pi/2]");
  }
  ElasticaSolution solution;
  solution.alpha = alpha;
  solution.psi_rad = psi_rad;
  const Loading load = MakeLoading(psi_rad);
  solution.loading_psi_rad = psi_rad;
  solution.loading_s0 = load.s0;
  solution.loading_c0 = load.c0;
  solution.loading_cos_psi = load.cos_psi;
  solution.loading_sin_psi = load.sin_psi;
  // Straight answers: no load, pure tension, and pure compression up to and including Euler's
  // load (the double nearest pi^2/4 counts as "not yet buckled").
  if (alpha == 0.0 || load.gap == 0.0) return solution;
  if (load.phi0 == 0.0 && alpha <= kEulerAlpha) return solution;
  if (alpha <= kSeriesMaxAlpha) {
    SolveSeries(load, solution);
  } else {
    SolveElliptic(load, solution, near);
  }
  return solution;
}

void ElasticaCentreline(const ElasticaSolution& solution, std::span<const double> s,
                        std::span<Eigen::Vector2d> xz_out, std::span<double> theta_out) {
  if (xz_out.size() != s.size() || theta_out.size() != s.size()) {
    throw std::invalid_argument("ElasticaCentreline: s, xz_out and theta_out differ in size");
  }
  for (const double si : s) {
    if (!(si >= 0.0 && si <= 1.0)) {
      char buffer[120];
      std::snprintf(buffer, sizeof(buffer), "ElasticaCentreline: s = %.17g is outside [0, 1]", si);
      throw std::invalid_argument(buffer);
    }
  }
  const ElasticaTip& tip = solution.tip;
  if (tip.tip_angle_rad == 0.0 && tip.deflection == 0.0) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      xz_out[i] = Eigen::Vector2d(0.0, s[i]);
      theta_out[i] = 0.0;
    }
    return;
  }
  const Loading load = MakeLoading(solution.psi_rad);
  if (solution.series) {
    const SeriesShape shape = BuildSeries(solution.alpha, load);
    for (std::size_t i = 0; i < s.size(); ++i) {
      xz_out[i] = SeriesPoint(shape, s[i]);
      theta_out[i] = EvalPolynomial(shape.theta, s[i]);
    }
    return;
  }
  const double sqrt_alpha = std::sqrt(solution.alpha);
  const double tau0 = RootArgument(solution, load);
  const LandenChain chain = MakeLandenChain(solution.modulus_k, solution.modulus_kc);
  const FromTip root = ShapeFromTip(solution, chain, sqrt_alpha, tau0, 0.0);
  const FromRoot from_root(solution, load, root.along, root.across);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const FromTip here = ShapeFromTip(solution, chain, sqrt_alpha, tau0, s[i]);
    xz_out[i] = from_root.At(s[i], here.along, here.across);
    theta_out[i] = (s[i] == 0.0) ? 0.0 : Theta(solution, here);
  }
}

void ElasticaSamples(const ElasticaSolution& solution, std::span<Eigen::Vector2d> xz_out,
                     std::span<Eigen::Vector2d> tangent_out) {
  ElasticaSamples(solution, 0.0, 1.0, xz_out, tangent_out);
}

void ElasticaSamples(const ElasticaSolution& solution, double s_first, double s_last,
                     std::span<Eigen::Vector2d> xz_out, std::span<Eigen::Vector2d> tangent_out) {
  const std::size_t n = xz_out.size();
  if (tangent_out.size() != n || n < 2) {
    throw std::invalid_argument(
        "ElasticaSamples: xz_out and tangent_out must have the same size, at least 2");
  }
  if (!(s_first >= 0.0 && s_first <= s_last && s_last <= 1.0)) {
    char buffer[160];
    std::snprintf(buffer, sizeof(buffer),
                  "ElasticaSamples: the range [%.17g, %.17g] is not within [0, 1] in order",
                  s_first, s_last);
    throw std::invalid_argument(buffer);
  }
  const SampleArcs s_of(s_first, s_last, n);
  const ElasticaTip& tip = solution.tip;
  if (tip.tip_angle_rad == 0.0 && tip.deflection == 0.0) {
    for (std::size_t j = 0; j < n; ++j) {
      xz_out[j] = Eigen::Vector2d(0.0, s_of(j));
      tangent_out[j] = Eigen::Vector2d(0.0, 1.0);
    }
    return;
  }
  const Loading load = LoadingOf(solution);
  if (solution.series) {
    const SeriesShape shape = BuildSeries(solution.alpha, load);
    for (std::size_t j = 0; j < n; ++j) {
      const double s = s_of(j);
      xz_out[j] = SeriesPoint(shape, s);
      const double theta = EvalPolynomial(shape.theta, s);
      tangent_out[j] = Eigen::Vector2d(std::sin(theta), std::cos(theta));
    }
    return;
  }
  EllipticSamples(solution, load, s_of, xz_out, tangent_out);
}

}  // namespace tubeplan::model
