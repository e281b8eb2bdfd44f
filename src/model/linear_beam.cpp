#include <cmath>

#include <tubeplan/model/linear_beam.hpp>

namespace tubeplan::model {

LinearBeam::LinearBeam(const TubeSpec& spec) : spec_(spec), section_(ComputeSection(spec)) {
  inv_EI_ = 1.0 / section_.bending_stiffness_Nm2;
  const double kappa = (3.0 + 2.0 * spec.poisson_ratio) / 4.0;
  const double r1_sq = spec.outer_radius_m * spec.outer_radius_m;
  const double r2_sq = spec.inner_radius_m * spec.inner_radius_m;
  warp_r_ = kappa * (r1_sq + r2_sq);
  warp_r1r2_ = kappa * r1_sq * r2_sq;
}

Eigen::Vector3d LinearBeam::DisplacementInBendingFrame(const Eigen::Vector3d& p_OP_B,
                                                       double force_x_N) const {
  const double x = p_OP_B.x();
  const double y = p_OP_B.y();
  const double z = p_OP_B.z();
  const double l = spec_.length_m;
  const double nu = spec_.poisson_ratio;
  const double c = force_x_N * inv_EI_;
  const double rho_sq = x * x + y * y;
  // The hollow-section term is x / rho^2; on the axis its numerator is exactly zero, and for a
  // solid rod (r2 = 0) the coefficient is zero: both give 0 without dividing by zero.
  const double hollow = (warp_r1r2_ != 0.0 && rho_sq > 0.0) ? warp_r1r2_ * x / rho_sq : 0.0;
  const double u = c * (z * z * (l / 2.0 - z / 6.0) + 0.5 * nu * (l - z) * (x * x - y * y));
  const double v = c * nu * (l - z) * x * y;
  const double w = c * (-x * z * (l - z / 2.0) - 0.25 * x * rho_sq + warp_r_ * x + hollow);
  return {u, v, w};
}

Eigen::Vector3d LinearBeam::Displacement(const Eigen::Vector3d& p_OP_O,
                                         const Eigen::Vector2d& f_lateral_O_N) const {
  // hypot, not norm(): squaring under- or overflows for |F| below 1e-154 N or above 1e154 N.
  const double force_N = std::hypot(f_lateral_O_N.x(), f_lateral_O_N.y());
  // Zero force is the defined branch. A NaN force is not turned into a harmless-looking zero: it
  // propagates, and the callers that must never emit NaN (the core's step) check their inputs.
  if (force_N == 0.0) return Eigen::Vector3d::Zero();
  // Bending frame B: x_B along the force, y_B = z x x_B; rotation about the shared z axis.
  const double cos_a = f_lateral_O_N.x() / force_N;
  const double sin_a = f_lateral_O_N.y() / force_N;
  const Eigen::Vector3d p_OP_B(cos_a * p_OP_O.x() + sin_a * p_OP_O.y(),
                               -sin_a * p_OP_O.x() + cos_a * p_OP_O.y(), p_OP_O.z());
  const Eigen::Vector3d d_B = DisplacementInBendingFrame(p_OP_B, force_N);
  return {cos_a * d_B.x() - sin_a * d_B.y(), sin_a * d_B.x() + cos_a * d_B.y(), d_B.z()};
}

}  // namespace tubeplan::model
