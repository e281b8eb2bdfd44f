#pragma once
// One entry point to both beam models for a tip load: the figures `tubeplan beam` prints and the
// displacement of any material point. Dimensional (SI), in the tube frame O-xyz of
// linear_beam.hpp.

#include <string_view>

#include <Eigen/Core>

#include <tubeplan/model/tube.hpp>

namespace tubeplan::model {

enum class BeamModel {
  kLinear,    ///< the paper's model: eq. (1)-(2); the axial load neither bends nor shortens
  kElastica,  ///< the inextensible elastica under the full tip load (lateral and axial)
};

std::string_view ToString(BeamModel model);

struct TipLoadResponse {
  Eigen::Vector3d tip_displacement_O_m = Eigen::Vector3d::Zero();  ///< of the tip centre [m]
  double tip_deflection_m = 0.0;  ///< lateral part of the tip displacement [m]
  double tip_shortening_m = 0.0;  ///< shortening along the undeformed axis [m]
  double tip_angle_rad = 0.0;     ///< rotation of the tip section [rad]
  double energy_J = 0.0;          ///< bending energy [J]
  double root_strain = 0.0;       ///< largest bending strain, outer fibre at the root [-]
  double alpha = 0.0;             ///< |F| l^2 / (E I) of the whole tip load [-]
};

/// Response to the tip force f_tip_O_N [N] (tube frame; z is axial). With no lateral force the
/// bending direction is undefined: the linear model does not bend, and the elastica (which can
/// buckle under compression) takes +x as its bending direction.
TipLoadResponse TipResponse(BeamModel model, const TubeSpec& spec,
                            const Eigen::Vector3d& f_tip_O_N);

/// Displacement [m] of the material point p_OP_O (undeformed position, tube frame) under the same
/// load. Linear: corrected eq. (1). Elastica: the centreline moves as solved and the cross-section
/// stays plane and normal to it (Euler-Bernoulli kinematics; no warping).
Eigen::Vector3d PointDisplacement(BeamModel model, const TubeSpec& spec,
                                  const Eigen::Vector3d& f_tip_O_N, const Eigen::Vector3d& p_OP_O);

}  // namespace tubeplan::model
