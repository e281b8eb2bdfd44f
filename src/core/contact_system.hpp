#pragma once
// Private to the core: the tick's reduced system (core.cpp, step 6) solved by its structure
// when at most one of its loads moves under the loads' forces.
//
// With the grip rigid, the held end's position is substituted (p = (A + S) / K_c,eff with S the
// forces' sum), and load i's rows read
//     F_i + G_i sum_j W'_ij F_j + C_i S = b_i,   C_i = G_i / K_c,eff,
// W'_ij its compliance to load j (less the stuck spring's one-way turn). A load at the held end
// neither moves nor is moved: its compliance blocks are exactly zero. A tube lying in the groove
// touches floor and walls there and at its tip, so the only block left is the tip's own, and
// the system is block-diagonal plus a rank-3 coupling through S:
//     A_i F_i + C_i S = b_i,   A_i = I but for the moving load's I + G_t W'_tt.
// Then F_i = A_i^-1 (b_i - C_i S), and summing over i,
//     (I + sum_i A_i^-1 C_i) S = sum_i A_i^-1 b_i,
// one 3 x 3 system for S and one for the moving load's block, instead of the 3n x 3n LU (three
// PCs: 9 x 9, ~5 k instructions, the largest single cost of a three-PC tick after the query).
// It is the same system: the forces agree with the dense LU's to its rounding
// (tests/core/contact_system_test.cpp).

#include <array>

#include <Eigen/Core>
#include <Eigen/LU>  // MatrixBase::inverse

#include <tubeplan/core/core.hpp>

namespace tubeplan::core {

/// Solves A_i F_i + C_i S = b_i (i < count, S = sum_i F_i) with A_i = I except A_moving (none
/// when moving < 0). Writes F_i to z.segment<3>(3 i); z must hold 3 count entries. A singular
/// block gives non-finite forces (the caller checks them).
template <class Vector>
void SolveOneMoving(int count, int moving, const Eigen::Matrix3d& A_moving,
                    const std::array<Eigen::Matrix3d, kMaxLoads>& C,
                    const std::array<Eigen::Vector3d, kMaxLoads>& b, Vector& z) {
  Eigen::Matrix3d S_matrix = Eigen::Matrix3d::Identity();
  Eigen::Vector3d S_rhs = Eigen::Vector3d::Zero();
  // Both 3 x 3 systems are solved by Eigen's closed-form inverse (cofactors over the
  // determinant): PartialPivLU<Matrix3d> goes through Eigen's general blocked triangular solver
  // and GEMM packing, ~1.7 k instructions a tick for the two solves against ~0.2 k. Both
  // matrices are the identity plus the loads' couplings; for 3 x 3 the cofactor inverse's error
  // is, like the LU's, within a small multiple of cond eps (tests/core/contact_system_test.cpp
  // holds the forces to the dense LU's within 100 cond eps). A singular one gives non-finite
  // forces, as the LU did.
  Eigen::Matrix<double, 3, 4> AinvCb;
  for (int i = 0; i < count; ++i) {
    if (i == moving) {
      const Eigen::Matrix3d A_inverse = A_moving.inverse();
      AinvCb.leftCols<3>() = A_inverse * C[std::size_t(i)];
      AinvCb.col(3) = A_inverse * b[std::size_t(i)];
      S_matrix += AinvCb.leftCols<3>();
      S_rhs += AinvCb.col(3);
    } else {
      S_matrix += C[std::size_t(i)];
      S_rhs += b[std::size_t(i)];
    }
  }
  const Eigen::Vector3d S = S_matrix.inverse() * S_rhs;
  for (int i = 0; i < count; ++i) {
    if (i == moving)
      z.template segment<3>(3 * i) = AinvCb.col(3) - AinvCb.leftCols<3>() * S;
    else
      z.template segment<3>(3 * i) = b[std::size_t(i)] - C[std::size_t(i)] * S;
  }
}

}  // namespace tubeplan::core
