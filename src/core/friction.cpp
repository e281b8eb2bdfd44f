#include <bit>
#include <cmath>
#include <cstdint>

#include <tubeplan/core/friction.hpp>

namespace tubeplan::core {
namespace {

// std::pow(base, exponent), the last result kept per thread. A tick asks for the same power
// several times (a load point's static and kinetic shares, its PC's limit at the PC's load), and
// pow costs a hundred instructions or more. The same bits in, the same bits out: pow is a function
// of its arguments alone.
double LoadPower(double base, double exponent) {
  thread_local std::uint64_t last_base = 0, last_exponent = 0;
  thread_local double last_power = 1.0;  // std::pow(0.0, 0.0), for the bits above
  const auto base_bits = std::bit_cast<std::uint64_t>(base);
  const auto exponent_bits = std::bit_cast<std::uint64_t>(exponent);
  if (base_bits != last_base || exponent_bits != last_exponent) {
    last_base = base_bits;
    last_exponent = exponent_bits;
    last_power = std::pow(base, exponent);
  }
  return last_power;
}

}  // namespace

double FrictionLimit(const scene::Friction& friction, double coefficient, double normal_N) {
  if (!(normal_N > 0.0)) return 0.0;
  if (friction.exponent == 1.0) return coefficient * normal_N;  // Coulomb: exact, no pow
  const double n0 = friction.reference_load_N;
  return coefficient * n0 * LoadPower(normal_N / n0, friction.exponent);
}

double FrictionShare(const scene::Friction& friction, double coefficient, double normal_N,
                     double pc_normal_N) {
  if (!(pc_normal_N > normal_N) || friction.exponent == 1.0)
    return FrictionLimit(friction, coefficient, normal_N);
  if (!(normal_N > 0.0)) return 0.0;
  return FrictionLimit(friction, coefficient, pc_normal_N) * (normal_N / pc_normal_N);
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
