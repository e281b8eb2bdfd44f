// The quadrature rule both the elastica and the flexure tests rely on.
#include "model/gauss_legendre.hpp"

#include <cmath>

#include <catch2/catch.hpp>

namespace {

// Integral of x^k over [-1, 1]: 2 / (k + 1) for even k, 0 for odd k.
double MonomialIntegral(int k) { return k % 2 == 1 ? 0.0 : 2.0 / (k + 1); }

template <int N>
void CheckExactness() {
  const auto rule = tubeplan::model::MakeGaussLegendreRule<N>();
  CAPTURE(N);
  // Exact up to degree 2N - 1; the sums of N terms of size ~1 round to a few ulps: 1e-14.
  for (int k = 0; k <= 2 * N - 1; ++k) {
    double sum = 0.0;
    for (int i = 0; i < N; ++i)
      sum += rule.weights[static_cast<std::size_t>(i)] *
             std::pow(rule.nodes[static_cast<std::size_t>(i)], k);
    CAPTURE(k);
    CHECK(sum == Approx(MonomialIntegral(k)).margin(1e-14));
  }
  // ... and not beyond: x^(2N) is integrated with an error (that is what makes it Gauss).
  double sum = 0.0;
  for (int i = 0; i < N; ++i)
    sum += rule.weights[static_cast<std::size_t>(i)] *
           std::pow(rule.nodes[static_cast<std::size_t>(i)], 2 * N);
  CHECK(std::abs(sum - MonomialIntegral(2 * N)) > 1e-10);  // 1.8e-7 at N = 12, far above rounding
  for (int i = 1; i < N; ++i)
    CHECK(rule.nodes[static_cast<std::size_t>(i - 1)] < rule.nodes[static_cast<std::size_t>(i)]);
}

}  // namespace

TEST_CASE("Gauss-Legendre rules integrate polynomials of degree 2N - 1 exactly", "[quadrature]") {
  CheckExactness<1>();
  CheckExactness<2>();
  CheckExactness<5>();
  CheckExactness<10>();
  CheckExactness<12>();
}
