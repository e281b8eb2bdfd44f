#pragma once
// The small scenes the core's closed-form tests start from: a tube and its contact law, no parts,
// the tube's end held stiffly (a grip stronger than any load the tests make).
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::testing {

// The steel tube of scenes/groove-steel.yaml: stiff, small deflections (alpha < 0.07 at 5 N).
inline scene::Scene SteelScene() {
  scene::Scene s;
  s.name = "steel";
  s.tube = {3e-3, 2.5e-3, 0.3, 200e9, 0.3};
  s.contact = {1e4, 1e-3, 1e-4};
  s.device.coupling_stiffness_N_per_m = 400.0;
  s.device.coupling_damping_Ns_per_m = 0.0;
  // The closed forms hold the tube's end rigidly: a grip stronger than any load here.
  s.device.max_torque_Nm = 100.0;
  s.device.max_force_N = 50.0;
  return s;
}

// The rubber tube of scenes/groove.yaml: soft, large deflections (alpha = 2.75 at 1 N).
inline scene::Scene RubberScene() {
  scene::Scene s = SteelScene();
  s.name = "rubber";
  s.tube = {8e-3, 5e-3, 0.15, 3e6, 0.5};
  return s;
}

}  // namespace tubeplan::testing
