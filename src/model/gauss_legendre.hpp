#pragma once
// Private to the model sources and their tests: Gauss-Legendre quadrature nodes and weights
// on [-1, 1], computed once by Newton's method on the Legendre polynomial P_n. Header-only and
// allocation-free: callers keep the rule in arrays of their own size.

#include <array>
#include <cmath>
#include <numbers>

namespace tubeplan::model {

template <int N>
struct GaussLegendreRule {
  std::array<double, N> nodes{};    ///< ascending, in (-1, 1)
  std::array<double, N> weights{};  ///< sum to 2
};

/// The N-point rule, exact for polynomials of degree <= 2N - 1. Nodes converge to rounding level
/// (Newton from the asymptotic start cos(pi (i + 3/4) / (N + 1/2)) needs a handful of steps).
template <int N>
GaussLegendreRule<N> MakeGaussLegendreRule() {
  static_assert(N >= 1);
  GaussLegendreRule<N> rule;
  for (int i = 0; i < (N + 1) / 2; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (N + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p_previous = 1.0;
      double p = x;
      for (int j = 2; j <= N; ++j) {
        const double p_next = ((2.0 * j - 1.0) * x * p - (j - 1.0) * p_previous) / j;
        p_previous = p;
        p = p_next;
      }
      derivative = N * (x * p - p_previous) / (x * x - 1.0);
      const double step = p / derivative;
      x -= step;
      if (std::abs(step) < 1e-16) break;
    }
    const double weight = 2.0 / ((1.0 - x * x) * derivative * derivative);
    // x is the i-th largest root; the rule is symmetric about 0.
    rule.nodes[static_cast<std::size_t>(N - 1 - i)] = x;
    rule.weights[static_cast<std::size_t>(N - 1 - i)] = weight;
    rule.nodes[static_cast<std::size_t>(i)] = -x;
    rule.weights[static_cast<std::size_t>(i)] = weight;
  }
  return rule;
}

}  // namespace tubeplan::model
