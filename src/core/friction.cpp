#include <cmath>

#include <tubeplan/core/friction.hpp>

namespace tubeplan::core {

double FrictionLimit(const scene::Friction& friction, double coefficient, double normal_N) {
  if (!(normal_N > 0.0)) return 0.0;
  if (friction.exponent == 1.0) return coefficient * normal_N;  // Coulomb: exact, no pow
  const double n0 = friction.reference_load_N;
  return coefficient * n0 * std::pow(normal_N / n0, friction.exponent);
}

double FrictionShare(const scene::Friction& friction, double coefficient, double normal_N,
                     double pc_normal_N) {
  if (!(pc_normal_N > normal_N) || friction.exponent == 1.0)
    return FrictionLimit(friction, coefficient, normal_N);
  if (!(normal_N > 0.0)) return 0.0;
  return FrictionLimit(friction, coefficient, pc_normal_N) * (normal_N / pc_normal_N);
}

double FrictionShare(const scene::Friction& friction, double coefficient, double normal_N,
                     double pc_normal_N, double pc_limit_N) {
  if (!(pc_normal_N > normal_N) || friction.exponent == 1.0)
    return FrictionLimit(friction, coefficient, normal_N);
  if (!(normal_N > 0.0)) return 0.0;
  return pc_limit_N * (normal_N / pc_normal_N);
}

FrictionResult ReturnMap(const scene::Friction& friction, const Eigen::Vector3d& trial_force_N,
                         double normal_N, double pc_normal_N, double tangential_stiffness_N_per_m) {
  FrictionResult result;
  const double trial_N = trial_force_N.norm();
  if (friction.IsFrictionless()) {
    result.sliding = trial_N > 0.0;
    result.slip_m = trial_force_N / tangential_stiffness_N_per_m;
    return result;
  }
  const double static_limit_N =
      FrictionShare(friction, friction.static_coefficient, normal_N, pc_normal_N);
  if (trial_N <= static_limit_N) {
    result.force_N = trial_force_N;
    return result;
  }
  // trial_N > static_limit_N >= 0, so the direction is defined.
  const Eigen::Vector3d direction = trial_force_N / trial_N;
  const double kinetic_limit_N =
      FrictionShare(friction, friction.kinetic_coefficient, normal_N, pc_normal_N);
  result.sliding = true;
  result.force_N = kinetic_limit_N * direction;
  result.slip_m = ((trial_N - kinetic_limit_N) / tangential_stiffness_N_per_m) * direction;
  return result;
}

}  // namespace tubeplan::core
