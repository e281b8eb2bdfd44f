#pragma once
// The tube as MuJoCo sees it (MuJoCo 2.2.2's C API): a chain of capsules on ball joints held by
// a mocap body, pressed on a plane, settled, then timed per simulated millisecond.

#include <cmath>
#include <functional>

#include <Eigen/Geometry>

namespace tubeplan::bench::mujoco {

/// One contact case, in world coordinates [SI].
struct ChainCase {
  double length_m = 0.0;               ///< l
  double outer_radius_m = 0.0;         ///< r1: the capsules' radius
  double inner_radius_m = 0.0;         ///< r2: the bore (mass and inertia only)
  double bending_stiffness_Nm2 = 0.0;  ///< EI
  /// The tube's density: it sets the chain's mass, which tubeplan's quasi-static core has none
  /// of (rubber, 1200 kg/m^3; the scene does not give one).
  double density_kg_per_m3 = 1200.0;
  double floor_z_m = 0.0;                  ///< the floor's top, a plane of normal +z
  double contact_stiffness_N_per_m = 0.0;  ///< K: MuJoCo's contact is softened to match it
  double threshold_m = 0.0;                ///< epsilon: the contact's margin
  double friction = 0.0;                   ///< MuJoCo's one Coulomb coefficient
  std::function<Eigen::Isometry3d(double t_s)> hand;  ///< the grip's pose at time t
  double settle_s = 2.0;                              ///< simulated before the force is read
};

/// What one chain did.
struct ChainRun {
  int elements = 0;
  int steps_per_ms = 0;            ///< mj_step calls per simulated ms (the stable time step's)
  double force_z_N = 0.0;          ///< settled vertical force on the operator at the grip
  double contact_force_z_N = 0.0;  ///< the floor's vertical force on the chain (the same, settled)
  double contact_stiffness_N_per_m = 0.0;  ///< measured: normal force / (margin - distance)
  int contacts = 0;                        ///< MuJoCo's contacts with the floor, settled
  double tip_drift_m = 0.0;                ///< the end's horizontal motion while timed (stuck: ~0)
  double still_us = 0.0;     ///< median wall time per simulated ms, the hand held still
  double dithered_us = 0.0;  ///< the same with the hand dithered (bench::Dither)
};

/// Builds the chain of `elements` capsules for `c`, finds the longest stable time step that
/// divides 1 ms (the settled force then agrees with the next shorter one's to 0.2 %), calibrates
/// the contact's softness to K, settles and times `samples` simulated ms each way.
ChainRun RunChain(const ChainCase& c, int elements, int samples);

}  // namespace tubeplan::bench::mujoco
