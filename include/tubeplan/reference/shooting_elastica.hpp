#pragma once
// A second reference for the planar rod in contact, independent of the core and of the segment
// rod of planar_rod.hpp by its method: the inextensible Kirchhoff rod (the elastica) integrated
// along its arc length as an initial-value problem (classical Runge-Kutta, fourth order, between
// the points where loads act) on a few segments, and shot by Newton's method to continuity
// between them and to the free end's conditions (multiple shooting). Contact forces are unknowns
// of that Newton solve, each tied to the penalty law evaluated on the shape it produces, so all
// contacts are found at once. It is slow (finite-difference Jacobian, milliseconds a solve) and
// never runs in the 1 kHz path: it judges the core from outside.
//
// Plane: the world's (x, z) plane, vectors stored as (x, z). The tangent angle theta is measured
// from +z towards +x: tangent t = (sin theta, cos theta), and g = (cos theta, -sin theta) = dt /
// dtheta is the section's in-plane direction. Moments are about the world's +y axis (the sense in
// which theta grows): a force F at r from a point carries r_z F_x - r_x F_z about it.
//
// The rod's equations, s the arc length from the held end (0) to the free end (l):
//   p' = t(theta),  EI theta' = m,  m' = -(n_x cos theta - n_z sin theta),
// n(s) the sum of the loads beyond s (constant between them) and m(s) their moment about p(s). A
// load F acting at q at arc s drops n by F and m by the moment of F about p(s) as s passes it.
// Unknowns: the clamp's moment m(0), the state (p, theta, m) at each segment's start, each
// contact's force vector, each side contact's arc. Equations: continuity at the segments' starts,
// m = 0 beyond the free end (n = 0 there holds by construction: n(0) is the sum of all loads),
// each force equal to its law at the shape, each side contact at the closest point of the
// centreline to its obstacle (a projected-gradient condition, so it may sit at either end).
// The held end follows from n(0): the operator's force is -n(0) = K_c (hand - held).

#include <optional>
#include <vector>

#include <Eigen/Core>

namespace tubeplan::reference::shooting {

/// The rod: constant data.
struct Rod {
  double length_m = 0.0;               ///< l [m]
  double bending_stiffness_Nm2 = 0.0;  ///< EI [N m^2]
  double radius_m = 0.0;               ///< r1, the surface's offset from the centreline [m]
  /// Shooting segments (multiple shooting, >= 1): the rod's equations grow errors like
  /// exp(sqrt(F/EI) s), so one shot from the clamp finds Newton's basin only near the answer
  /// beyond alpha ~ 20; J segments shrink that growth to exp(sqrt(alpha) / J).
  int segments = 8;
  /// Runge-Kutta steps on each stretch of a segment between load points (>= 2). The error is
  /// fourth order in the step: 32 steps on 8 segments give about 1e-10 of l on Mattiasson's
  /// cantilever at alpha = 10.
  int steps_per_piece = 32;
};

/// What a part presents to the tube in the plane.
enum class ObstacleKind {
  /// A plane touched by the corners of the flat end face, p(l) +- r1 g(l). The force acts at the
  /// corner, so it carries a moment r x F about the end's centre.
  kPlaneRim,
  /// A plane touched by the side: the point of the centreline nearest the plane, offset by r1
  /// towards it. Near the free end the surface is taken as the centreline's offset (a rounded end).
  kPlaneSide,
  /// An edge seen end-on (a point of the plane) touched by the side: the nearest point of the
  /// centreline, the force along the line from the edge to it.
  kEdge,
};

/// Which corners of the end face a kPlaneRim obstacle loads.
enum class RimCorners {
  kDeepest,  ///< one contact (the paper's one PC): at the corner nearer the plane
  kEach,     ///< two contacts, one per corner, each with its own penalty and friction
};

/// Friction of a contact (docs/core.md, "Friction"): static limit f_max = mu_s N0 (N / N0)^beta.
struct Friction {
  double static_coefficient = 0.0;   ///< mu_s [-]
  double kinetic_coefficient = 0.0;  ///< mu_k [-]
  double exponent = 1.0;             ///< beta [-]
  double reference_load_N = 1.0;     ///< N0 [N]
  /// The kinetic force: mu_k N when false; mu_k N0 (N / N0)^beta (the core's law) when true.
  bool kinetic_uses_exponent = false;
};

struct Obstacle {
  ObstacleKind kind = ObstacleKind::kPlaneRim;
  Eigen::Vector2d point_m = Eigen::Vector2d::Zero();  ///< a point of the plane, or the edge
  Eigen::Vector2d normal = Eigen::Vector2d::UnitY();  ///< planes: unit, out of the part (x, z)
  RimCorners corners = RimCorners::kDeepest;          ///< kPlaneRim only
  Friction friction;                                  ///< used by FollowPath
};

/// Normal force N = K (eps - d)_+ along the contact normal, d the distance from the tube's
/// surface (or the rim corner) to the obstacle.
struct ContactLaw {
  double stiffness_N_per_m = 1.0e4;  ///< K; also the stiffness of a stuck contact's spring
  double threshold_m = 1.0e-3;       ///< eps
};

struct Setup {
  Eigen::Vector2d hand_m = Eigen::Vector2d::Zero();  ///< where the coupling pulls (x, z) [m]
  double root_angle_rad = 0.0;                       ///< phi0: the grip holds the tangent there
  /// K_c [N/m]; 0 holds the held end exactly at hand_m.
  double coupling_N_per_m = 0.0;
  Eigen::Vector2d tip_force_N = Eigen::Vector2d::Zero();  ///< dead load at the end's centre
  double tip_moment_Nm = 0.0;                             ///< dead couple at the free end
  std::vector<Obstacle> obstacles;
  ContactLaw law;
};

/// One contact the solver carries: an obstacle, and for kPlaneRim with kEach the corner.
struct Slot {
  int obstacle = 0;
  int corner = 0;  ///< -1 or +1 for a fixed corner; 0 otherwise
};
/// The contacts of a setup, in the order of its obstacles (kEach rims give two, corner -1 first).
std::vector<Slot> Slots(const Setup& setup);

/// How the tangential force of a contact is found.
enum class FrictionMode {
  kNone,     ///< frictionless
  kSliding,  ///< kinetic force f_k opposite the given slip direction
  kStuck,    ///< a spring of stiffness K from an anchor on the obstacle to a point of the tube
};

/// The tangent of a contact is tau = (n_z, -n_x) for a plane of normal n; for an edge, the
/// rod's tangent made normal to the contact normal. Tangential forces are along tau.
struct SlotFriction {
  FrictionMode mode = FrictionMode::kNone;
  double slide_sign = 0.0;  ///< kSliding: the tube slips along +tau (+1) or -tau (-1)
  /// kStuck: the anchor on the obstacle (planes; an edge is its own anchor) [m].
  Eigen::Vector2d anchor_m = Eigen::Vector2d::Zero();
  /// kStuck: the tube's point held, its arc [m] and side (+1: +r1 g, -1: -r1 g); the rim's
  /// corners are arc l. The spring's stretch is tau . (that point - anchor).
  double anchor_arc_m = 0.0;
  int anchor_side = 1;
};

/// The unknowns of the Newton solve; a solution's are a good start for a nearby one.
struct Unknowns {
  double clamp_moment_Nm = 0.0;          ///< m(0), the bending moment at the held end
  std::vector<Eigen::Vector2d> force_N;  ///< per slot, the contact force on the tube
  std::vector<double> arc_m;             ///< per slot, its arc (side contacts; l for rims)
  /// (x, z, theta, m) at the start of segments 1..J-1; empty (or another size): integrated from
  /// the clamp moment and forces above.
  std::vector<Eigen::Vector4d> shape;
  /// The held end and grip angle the shape belongs to: a start for another hand pose is the
  /// shape moved rigidly with the held end.
  Eigen::Vector2d held_m = Eigen::Vector2d::Zero();
  double root_angle_rad = 0.0;
};

struct SolveOptions {
  std::vector<SlotFriction> friction;  ///< per slot; empty: all frictionless
  std::optional<Unknowns> start;       ///< the unloaded straight rod when empty
  int max_iterations = 40;
  /// Converged when every residual is below this, each scaled by the rod's own unit (moments by
  /// EI/l, forces by EI/l^2, arcs by l).
  double tolerance = 1e-10;
  /// The largest move of the centreline per Newton step [m] (0: the larger of max(r1, eps) / 2
  /// and l / 50 when there are obstacles, l / 10 otherwise), so that no step carries the tube
  /// through a part or jumps to another branch of equilibria.
  double max_move_m = 0.0;
};

struct CentrelinePoint {
  double arc_m = 0.0;
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  double angle_rad = 0.0;
  double curvature_per_m = 0.0;  ///< theta'
  double moment_Nm = 0.0;        ///< m = EI theta' (jumps where a load acts off the centreline)
};

struct ContactResult {
  Slot slot;
  double arc_m = 0.0;       ///< where on the centreline it acts (l for the rim)
  double distance_m = 0.0;  ///< d
  bool active = false;      ///< d < eps
  Eigen::Vector2d point_m = Eigen::Vector2d::Zero();  ///< where the force acts (the surface)
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();   ///< from the obstacle into the tube
  Eigen::Vector2d tangent = Eigen::Vector2d::Zero();  ///< tau
  double normal_N = 0.0;                              ///< N
  double tangential_N = 0.0;                          ///< T, along tau
  Eigen::Vector2d force_N = Eigen::Vector2d::Zero();  ///< N normal + T tangent, on the tube
  double stretch_m = 0.0;        ///< kStuck: the spring's stretch (T = -K stretch)
  double static_limit_N = 0.0;   ///< f_max at N
  double kinetic_force_N = 0.0;  ///< f_k at N
  double friction_ratio = 0.0;   ///< |T| / f_max (0 when T = 0; infinite if f_max = 0 < |T|)
};

struct Solution {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;  ///< the largest scaled residual
  Unknowns unknowns;
  Eigen::Vector2d held_m = Eigen::Vector2d::Zero();  ///< the held end's centre
  /// What the operator applies at the held end = minus the sum of the loads on the tube [N].
  Eigen::Vector2d operator_force_N = Eigen::Vector2d::Zero();
  /// The couple the grip applies, about the held end's centre [N m] (= -m(0)).
  double operator_moment_Nm = 0.0;
  Eigen::Vector2d tip_m = Eigen::Vector2d::Zero();  ///< centre of the end face
  double tip_angle_rad = 0.0;
  double max_turn_rad = 0.0;      ///< max |theta(s) - phi0|: zero for a straight rod
  double bending_energy_J = 0.0;  ///< integral of m^2 / (2 EI)
  /// Bending + penalty + stuck springs + coupling - work of the dead loads [J]: a potential
  /// while friction is stuck or absent (it picks between equilibria of one hold).
  double potential_energy_J = 0.0;
  std::vector<ContactResult> contacts;      ///< per slot
  std::vector<CentrelinePoint> centreline;  ///< the integration's nodes, arc increasing
};

/// Solves the equilibrium. Throws std::invalid_argument on a bad rod or options.
Solution Solve(const Rod& rod, const Setup& setup, const SolveOptions& options = {});

/// The centreline at arc s, interpolated between the solution's nodes (cubic Hermite in
/// position and angle, fourth order like the integration).
CentrelinePoint At(const std::vector<CentrelinePoint>& centreline, double arc_m);

// --- quasi-static path --------------------------------------------------------------------------

/// One hand pose of a path.
struct Hold {
  Eigen::Vector2d hand_m = Eigen::Vector2d::Zero();
  double root_angle_rad = 0.0;
};

enum class ContactPhase { kOpen, kStuck, kSliding };

struct PathOptions {
  /// The state before the first hold: unknowns to start Newton from, and each slot's friction
  /// (empty: the straight rod, every contact open).
  std::optional<Unknowns> start;
  std::vector<SlotFriction> start_friction;
  /// Non-zero: buckling of a straight, pressed rod. Along such holds the sign of det(J) is
  /// watched (J, the Newton Jacobian, is singular where the straight branch crosses a
  /// bifurcation); once it changes, Newton is also started from the straight solution moved
  /// along J's null direction (the buckling mode), either way, turning a section by this angle
  /// and by factors of 4 less, until a bent equilibrium of lower potential energy replaces the
  /// straight one. Zero: the path follows what continuation from the last hold gives.
  double buckling_seed_rad = 0.0;
  /// A hold that does not converge from the last one is split in halves, at most this deep.
  int max_bisections = 8;
  SolveOptions solve;  ///< tolerance, iterations, steps (friction and start are the path's)
};

struct HoldResult {
  Hold hold;
  Solution solution;
  std::vector<ContactPhase> phase;     ///< per slot
  std::vector<SlotFriction> friction;  ///< per slot, carried to the next hold
  int substeps = 1;                    ///< 2^k when the hold was bisected
  int passes = 0;                      ///< solves for stick / slip / touch decisions
  bool settled = true;                 ///< the stick-slip decisions reached a fixed point
  bool seeded = false;                 ///< a buckling seed gave this hold's equilibrium
};

struct PathResult {
  bool ok = true;  ///< every hold converged and settled
  std::vector<HoldResult> holds;
};

/// Follows the hand through `holds` quasi-statically (setup.hand_m and root_angle_rad are
/// replaced by each hold's), continuing every solution from the last, with per contact: on first
/// touch (d crossing eps, interpolated between holds) an anchor where the surface touched;
/// stuck while |T| <= f_max; past it, sliding with f_k and the anchor returned so that the spring
/// carries exactly f_k; open again when d >= eps. A stuck contact's held point moves with the
/// contact point along the tube (rolling is not slip), its stretch kept.
PathResult FollowPath(const Rod& rod, const Setup& setup, const std::vector<Hold>& holds,
                      const PathOptions& options = {});

/// f_max = mu_s N0 (N / N0)^beta, 0 for N <= 0.
double StaticLimit(const Friction& friction, double normal_N);
/// The kinetic force at N (Friction::kinetic_uses_exponent).
double KineticForce(const Friction& friction, double normal_N);

}  // namespace tubeplan::reference::shooting
