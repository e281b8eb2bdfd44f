#pragma once
// The paper's linear (Euler-Bernoulli / Saint-Venant flexure) cantilever model, with eq. (1)
// corrected (docs/models.md, "The linear cantilever").
//
// Frame O-xyz ("the tube frame"): origin at the centre of the held end, z along the undeformed
// axis towards the free end at z = l. The *bending frame* is the tube frame turned about z so that
// x points along the lateral tip force.

#include <Eigen/Core>

#include <tubeplan/model/tube.hpp>

namespace tubeplan::model {

class LinearBeam {
 public:
  /// Throws std::invalid_argument when the spec is not valid (see ValidateTubeSpec).
  explicit LinearBeam(const TubeSpec& spec);

  const TubeSpec& spec() const { return spec_; }
  const TubeSection& section() const { return section_; }

  /// Corrected eq. (1): displacement (u, v, w) [m] of the material point whose undeformed
  /// position in the bending frame is p_OP_B [m], under a tip force force_x_N [N] along +x.
  /// On the axis (x^2 + y^2 -> 0) the r1^2 r2^2 x / rho^2 term is taken as its value along x = 0,
  /// zero, rather than evaluated as 0/0.
  Eigen::Vector3d DisplacementInBendingFrame(const Eigen::Vector3d& p_OP_B, double force_x_N) const;

  /// Displacement [m], expressed in the tube frame, of the material point p_OP_O [m] (tube frame)
  /// under a lateral tip force f_lateral_O_N = (fx, fy) [N]. A zero force gives zero displacement
  /// (the bending frame is undefined there; this is the defined branch). A NaN force gives NaN.
  Eigen::Vector3d Displacement(const Eigen::Vector3d& p_OP_O,
                               const Eigen::Vector2d& f_lateral_O_N) const;

  /// Lateral deflection of the tip centre, F l^3 / (3 E I) [m] (paper eq. 2).
  double TipDeflection(double force_N) const { return force_N / section_.tip_stiffness_N_per_m; }
  /// Rotation of the tip section, F l^2 / (2 E I) [rad].
  double TipAngle(double force_N) const {
    return force_N * spec_.length_m * spec_.length_m / (2.0 * section_.bending_stiffness_Nm2);
  }
  /// Bending energy 1/2 F^2 / k [J].
  double BendingEnergy(double force_N) const {
    return 0.5 * force_N * force_N / section_.tip_stiffness_N_per_m;
  }
  /// Largest bending strain, at the root's outer fibre: r1 F l / (E I) [-].
  double RootStrain(double force_N) const {
    return spec_.outer_radius_m * force_N * spec_.length_m / section_.bending_stiffness_Nm2;
  }

 private:
  TubeSpec spec_;
  TubeSection section_;
  double inv_EI_ = 0.0;     // 1 / (E I) [1/(N m^2)]
  double warp_r_ = 0.0;     // kappa (r1^2 + r2^2) [m^2], kappa = (3 + 2 nu) / 4
  double warp_r1r2_ = 0.0;  // kappa r1^2 r2^2 [m^4]
};

}  // namespace tubeplan::model
