#pragma once
// The virtual coupling of the hand to the held end (docs/scene-format.md, "Device"): which spring
// and damper a scene gets, and whether they are passive on its device.

#include <tubeplan/scene/scene.hpp>

namespace tubeplan::core {

struct Coupling {
  double stiffness_N_per_m = 0.0;  ///< K_c
  double damping_Ns_per_m = 0.0;   ///< B, the coupling's own (virtual) damping
};

/// Colgate & Schenkel's condition for a spring K sampled at period T with virtual damping B on a
/// device with physical damping b: passive if b > K T / 2 + |B|.
bool IsPassive(double device_damping_Ns_per_m, const Coupling& coupling, double step_s);

/// The coupling a scene runs with: its own values where it gives them, otherwise defaults with a
/// margin of two on both limits. B defaults to 0 (the device's own damping dissipates; the
/// passivity margin is then largest). K defaults to the smaller of half the device's rendering
/// limit and half the passivity bound 2 (b - |B|) / T. For the PHANToM Premium at 1 kHz that is
/// min(400, 5000) = 400 N/m. Returns K = 0 when no positive K is passive (b <= |B|).
Coupling ResolveCoupling(const scene::Device& device, double step_s);

}  // namespace tubeplan::core
