#include <algorithm>
#include <cmath>

#include <tubeplan/core/coupling.hpp>

namespace tubeplan::core {

bool IsPassive(double device_damping_Ns_per_m, const Coupling& coupling, double step_s) {
  return device_damping_Ns_per_m >
         coupling.stiffness_N_per_m * step_s / 2.0 + std::abs(coupling.damping_Ns_per_m);
}

Coupling ResolveCoupling(const scene::Device& device, double step_s) {
  Coupling c;
  c.damping_Ns_per_m = device.coupling_damping_Ns_per_m.value_or(0.0);
  if (device.coupling_stiffness_N_per_m) {
    c.stiffness_N_per_m = *device.coupling_stiffness_N_per_m;
    return c;
  }
  const double margin = device.damping_Ns_per_m - std::abs(c.damping_Ns_per_m);
  if (!(margin > 0.0)) return c;  // K = 0: nothing positive is passive
  const double passivity_bound = 2.0 * margin / step_s;
  c.stiffness_N_per_m = 0.5 * std::min(device.max_stiffness_N_per_m, passivity_bound);
  return c;
}

}  // namespace tubeplan::core
