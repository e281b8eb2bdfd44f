#pragma once
// A reference solver for the accuracy study, independent of the core's method: a planar,
// inextensible Kirchhoff rod (the elastica) discretised into N straight segments whose angles are
// the unknowns, with the held end on the coupling spring, dead tip loads and penalty contacts
// against planes and edges, solved to convergence by Newton's method. It is slow (dense Newton,
// finite-difference Jacobian) and never runs in the 1 kHz path: it judges the core from outside.
//
// Plane: the (x, z) plane of the world; z is the undeformed tube's axis, x the lateral direction.
// Angles theta are measured from +z towards +x.
//
// Discretisation (second order in h = l / N): segment k (1..N) has the angle theta_k, which
// stands for the tangent at its midpoint; node k = node k-1 + h (sin theta_k, cos theta_k), node
// 0 is the held end p. The bending energy is
//   U = EI/h (theta_1 - phi0)^2 + sum_{k=1}^{N-1} EI/(2h) (theta_{k+1} - theta_k)^2,
// the first term being the half segment between the clamp (angle phi0) and the first midpoint.
// Tip figures extrapolate the last half segment with the last curvature.
//
// Contacts use the core's constitutive law (docs/core.md, "The contact law"): one force
// K (eps - d)_+ per obstacle along the normal of the nearest pair, d the distance from the tube's
// surface (the centreline offset by r1) to the obstacle, an end face's shared among its rim's
// points (ContactLaw); sliding friction mu_k N opposite a given sliding direction.
// What differs from the core is everything else: the exact (converged) large-deflection rod
// under any number of loads, the exact geometry of the deformed tube, all contacts at once.

#include <optional>
#include <vector>

#include <Eigen/Core>

namespace tubeplan::reference {

/// The rod: constant data.
struct PlanarRod {
  double length_m = 0.0;               ///< l [m]
  double bending_stiffness_Nm2 = 0.0;  ///< EI [N m^2]
  double radius_m = 0.0;               ///< r1, the surface's offset from the centreline [m]
  int segments = 64;                   ///< N, >= 2
};

/// What a part presents to the tube in the plane.
enum class ObstacleKind {
  kPlaneEnd,   ///< a plane (a box's face) touched by the end face's corners (the rim)
  kPlaneSide,  ///< a plane touched by the tube's side (deepest node)
  kEdge,       ///< an edge (a point in the plane) touched by the tube's side
};

struct Obstacle {
  ObstacleKind kind = ObstacleKind::kEdge;
  Eigen::Vector2d point_m = Eigen::Vector2d::Zero();  ///< a point of the plane, or the edge (x, z)
  Eigen::Vector2d normal = Eigen::Vector2d::UnitX();  ///< plane only: unit, out of the part
  double kinetic_friction = 0.0;                      ///< mu_k [-]
  /// Sliding direction of the tube at the contact along the tangent (n_z, -n_x) (planes) or the
  /// rod's tangent (edges): +1, -1, or 0 for no friction. Friction opposes it.
  double slide_sign = 0.0;
};

struct ContactLaw {
  double stiffness_N_per_m = 1.0e4;  ///< K
  double threshold_m = 1.0e-3;       ///< eps
  /// The end face on a plane with eps > 0: 0 puts the force at the nearer corner; n > 0 shares
  /// it among n points round the rim (in-plane offsets r1 cos(2 pi j / n)) by the weights of a
  /// smooth minimum of their distances of width rim_softness * eps: the core's rim law, under
  /// which a flat end carries a moment until it tips onto a corner.
  int rim_points = 0;
  double rim_softness = 0.0;
};

struct Loading {
  Eigen::Vector2d hand_m = Eigen::Vector2d::Zero();  ///< where the coupling spring pulls (x, z)
  double root_angle_rad = 0.0;                       ///< phi0: the grip holds the root tangent
  /// K_c [N/m]; 0 holds the held end exactly at hand_m.
  double coupling_N_per_m = 0.0;
  Eigen::Vector2d tip_force_N = Eigen::Vector2d::Zero();  ///< dead load at the tip centre
  std::vector<Obstacle> obstacles;
  ContactLaw law;
};

/// The unknowns: held-end position and the N segment angles.
struct RodState {
  Eigen::Vector2d held_m = Eigen::Vector2d::Zero();
  Eigen::VectorXd theta_rad;
};

struct RodSolution {
  RodState state;
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;  ///< infinity norm of the last residual (N and N m mixed)
  Eigen::Vector2d tip_m = Eigen::Vector2d::Zero();  ///< centre of the end face
  double tip_angle_rad = 0.0;                       ///< tangent angle at s = l
  double energy_J = 0.0;                            ///< bending energy
  /// Sum of the contact forces on the rod = the force the operator feels (x, z) [N].
  Eigen::Vector2d contact_force_N = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector2d> obstacle_force_N;  ///< per obstacle, on the rod
  std::vector<double> obstacle_distance_m;        ///< per obstacle, d
};

/// The straight rod at the hand, along phi0.
RodState StraightState(const PlanarRod& rod, const Loading& loading);

/// Solves the equilibrium by damped Newton from `start` (the straight rod when empty): the
/// residual is the gradient of the bending and coupling energy minus the generalised forces of
/// the loads. Converged when the Newton step is below 1e-12 rad (and 1e-12 l) and the residual
/// below 1e-9 of the load scale.
RodSolution SolveRod(const PlanarRod& rod, const Loading& loading,
                     const std::optional<RodState>& start = std::nullopt);

/// The N + 1 nodes of the centreline (x, z) [m].
std::vector<Eigen::Vector2d> RodNodes(const PlanarRod& rod, const RodState& state);

/// Richardson's extrapolation of a second-order quantity from N and 2N segments.
inline double Richardson2(double coarse, double fine) { return (4.0 * fine - coarse) / 3.0; }

}  // namespace tubeplan::reference
