#pragma once
// A symmetric band matrix and its LDL^T factorisation, for the tick's Newton system: the rod's
// unknowns are ordered along the tube, and every energy term couples at most three consecutive
// nodes, so the Hessian is a band of half-width kBandWidth. Eigen has no band solver, and its
// sparse LDL^T allocates in factorize() and costs several times more at this size; this one is
// the textbook algorithm on fixed storage sized once.

#include <array>
#include <vector>

#include <Eigen/Core>

namespace tubeplan::core {

/// Half-bandwidth in scalars: three nodes of 3 coordinates, the band holding entries (i, j) with
/// i - kBandWidth <= j <= i.
inline constexpr int kBandWidth = 8;

class BandMatrix {
 public:
  BandMatrix() = default;
  /// Allocates n rows of the lower band, set to zero.
  explicit BandMatrix(int n) : n_(n), a_(std::size_t(n) * (kBandWidth + 1), 0.0) {}

  int size() const { return n_; }
  void SetZero() { std::fill(a_.begin(), a_.end(), 0.0); }
  /// Entry (i, j) of the lower band, i - kBandWidth <= j <= i.
  double& operator()(int i, int j) { return a_[Index(i, j)]; }
  double operator()(int i, int j) const { return a_[Index(i, j)]; }
  /// Adds a 3 x 3 block at block rows (bi, bj), scalar rows 3 bi and 3 bj, bi >= bj; of a block
  /// on the diagonal only the lower half is read.
  template <typename Block>
  void AddBlock(int bi, int bj, const Eigen::MatrixBase<Block>& block) {
    for (int r = 0; r < 3; ++r) {
      double* row = &a_[Index(3 * bi + r, 3 * bj)];
      const int columns = bi == bj ? r + 1 : 3;
      for (int c = 0; c < columns; ++c) row[c] += block(r, c);
    }
  }
  /// Adds lambda to every diagonal entry.
  void AddDiagonal(double lambda);
  /// y = A x for the symmetric matrix.
  void Multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;

 private:
  friend class BandLdlt;
  std::size_t Index(int i, int j) const {
    return std::size_t(i) * (kBandWidth + 1) + std::size_t(kBandWidth - (i - j));
  }
  int n_ = 0;
  std::vector<double> a_;
};

/// A = L D L^T without pivoting, which is stable for the positive definite matrices it accepts:
/// Factor() stops at the first pivot that is not above min_pivot (the matrix is then not
/// positive definite, or too close to singular to trust) and says so.
class BandLdlt {
 public:
  BandLdlt() = default;
  explicit BandLdlt(int n) : f_(n) {}

  /// False when a pivot is <= min_pivot; then Solve must not be called.
  bool Factor(const BandMatrix& a, double min_pivot);
  /// x = A^-1 x, in place; only after a Factor that returned true.
  void Solve(Eigen::VectorXd& x) const;
  int size() const { return f_.n_; }

 private:
  BandMatrix f_;  // L below the diagonal (unit diagonal implied), D on it
};

}  // namespace tubeplan::core
