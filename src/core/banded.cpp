#include "core/banded.hpp"

#include <algorithm>

namespace tubeplan::core {

void BandMatrix::AddDiagonal(double lambda) {
  for (int i = 0; i < n_; ++i) (*this)(i, i) += lambda;
}

void BandMatrix::Multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  y.setZero();
  for (int i = 0; i < n_; ++i) {
    const int j0 = std::max(0, i - kBandWidth);
    for (int j = j0; j < i; ++j) {
      const double a = (*this)(i, j);
      y[i] += a * x[j];
      y[j] += a * x[i];
    }
    y[i] += (*this)(i, i) * x[i];
  }
}

bool BandLdlt::Factor(const BandMatrix& a, double min_pivot) {
  f_.a_ = a.a_;
  const int n = f_.n_;
  constexpr int w = kBandWidth;
  double* f = f_.a_.data();
  // Row i of the band starts at f + i (w + 1); entry (i, j) is at its offset w - (i - j).
  const auto at = [f](int i, int j) -> double& { return f[i * (w + 1) + w - (i - j)]; };
  // Column by column (Golub & Van Loan, algorithm 4.1.2 restricted to the band): with
  // v_k = L(j, k) D(k), D(j) = A(j, j) - sum_k L(j, k) v_k, then L(i, j) for the rows below.
  std::array<double, w> v{};
  for (int j = 0; j < n; ++j) {
    const int k0 = std::max(0, j - w);
    const double* row_j = &at(j, k0);
    double d = at(j, j);
    for (int k = k0; k < j; ++k) {
      v[std::size_t(k - k0)] = row_j[k - k0] * at(k, k);
      d -= row_j[k - k0] * v[std::size_t(k - k0)];
    }
    if (!(d > min_pivot)) return false;
    at(j, j) = d;
    const int i1 = std::min(n - 1, j + w);
    for (int i = j + 1; i <= i1; ++i) {
      const int kk0 = std::max(k0, i - w);
      const double* row_i = &at(i, kk0);
      double s = at(i, j);
      for (int k = kk0; k < j; ++k) s -= row_i[k - kk0] * v[std::size_t(k - k0)];
      at(i, j) = s / d;
    }
  }
  return true;
}

void BandLdlt::Solve(Eigen::VectorXd& x) const {
  const int n = f_.n_;
  for (int i = 0; i < n; ++i) {
    const int j0 = std::max(0, i - kBandWidth);
    double s = x[i];
    for (int j = j0; j < i; ++j) s -= f_(i, j) * x[j];
    x[i] = s;
  }
  for (int i = 0; i < n; ++i) x[i] /= f_(i, i);
  for (int i = n - 1; i >= 0; --i) {
    const int j1 = std::min(n - 1, i + kBandWidth);
    double s = x[i];
    for (int j = i + 1; j <= j1; ++j) s -= f_(j, i) * x[j];
    x[i] = s;
  }
}

}  // namespace tubeplan::core
