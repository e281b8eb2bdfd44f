#pragma once
// Geometry and material of the elastic tube, and the section quantities derived from them.
// Units are SI throughout (m, Pa, N, J).

#include <string>
#include <vector>

namespace tubeplan::model {

/// A homogeneous, isotropic, linear elastic hollow circular tube (docs/models.md, "The tube").
/// inner_radius_m == 0 is a solid rod.
struct TubeSpec {
  double outer_radius_m = 0.0;     ///< r1 [m], > 0
  double inner_radius_m = 0.0;     ///< r2 [m], 0 <= r2 < r1
  double length_m = 0.0;           ///< l [m], > 0
  double youngs_modulus_Pa = 0.0;  ///< E [Pa], > 0
  double poisson_ratio = 0.0;      ///< nu [-], in [0, 0.5]
};

/// Every problem with a spec, as plain sentences naming the field; empty when the spec is usable.
std::vector<std::string> ValidateTubeSpec(const TubeSpec& spec);

/// Section quantities computed once from a valid spec.
struct TubeSection {
  double second_moment_m4 = 0.0;       ///< I = pi (r1^4 - r2^4) / 4 [m^4]
  double bending_stiffness_Nm2 = 0.0;  ///< EI [N m^2]
  double tip_stiffness_N_per_m = 0.0;  ///< k = 3 E I / l^3 [N/m] (paper eq. 2)
};

/// Throws std::invalid_argument listing every problem when the spec is not valid.
TubeSection ComputeSection(const TubeSpec& spec);

/// Load parameter alpha = F l^2 / (E I) of a tip force of magnitude force_N [N]; dimensionless.
double LoadParameter(const TubeSpec& spec, double force_N);

}  // namespace tubeplan::model
