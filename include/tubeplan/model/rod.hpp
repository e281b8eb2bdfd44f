#pragma once
// A discrete inextensible rod (Kirchhoff, isotropic, torsionally rigid) clamped at s = 0 along
// +z and loaded by dead point forces on its surface: the large-deflection model for the loadings
// the elastica (elastica.hpp: one tip load) does not cover — several loads on one cantilever, a
// line contact carried by two load points, an axial push with a lateral one. It keeps its length
// whatever the load, which the linear model does not (docs/core.md).
//
// Equilibrium. With n(s) = sum_{s_j > s} F_j the force the part beyond s exerts on the part
// before it (known: the loads are dead) and m(s) the moment, m' = -t x n between loads, and m
// drops by r_j x F_j (the load's moment about the centre, r_j its offset to the surface) at s_j.
// The curvature is kappa = m_perp / (E I), the tangent turns as t' = kappa x t. Beyond the last
// load the moment is exactly zero, so the integration runs from there back to the clamp, and
// the unknown is the orientation of the section at the last load: Newton on it makes the section
// at s = 0 the clamp's (a shooting method, its Jacobian the exact derivative of the discrete map,
// carried through the integration step by step). Shooting from the free end is the classical
// choice for the cantilever: the map from the end's angle to the root's is monotone along the
// first mode (the pendulum analogy), where shooting from the clamp with the root moment as
// unknown winds through several modes already at F l^2 / (E I) ~ 15.
//
// Discretisation. Steps of at most `max_step_m` between breakpoints (the loads and the arc
// positions asked for). Each step is an arc: its rotation h kappa(s + h/2) from the moment
// predicted at its middle, its chord exact for that arc, and the moment updated exactly by the
// chord (m_new = m - dx x n), so the discrete chain is in exact equilibrium with the loads at
// every node; the curvature's midpoint rule makes the shape second-order accurate in the step
// (tests/model/rod_test.cpp measures the order against the exact elastica).
//
// Everything here is in the clamp's frame, SI. No heap allocation.

#include <array>
#include <span>

#include <Eigen/Core>

namespace tubeplan::model {

/// A dead force on the rod's surface: applied at the centreline point of arc position s_m plus
/// the offset r_m (surface point minus centre, clamp frame), which carries the moment r x F. The
/// offset turns with its cross-section when the shape is evaluated.
struct RodLoad {
  double s_m = 0.0;
  Eigen::Vector3d f_N = Eigen::Vector3d::Zero();
  Eigen::Vector3d r_m = Eigen::Vector3d::Zero();
};

/// A solved rod: its root moment, and what the shape gives.
struct RodSolution {
  Eigen::Vector3d root_moment_Nm = Eigen::Vector3d::Zero();  ///< m(0), clamp frame
  /// The section frame at the last load (z: tangent), clamp frame: the unknown solved for, and
  /// the next solve's starting guess.
  Eigen::Matrix3d end_R = Eigen::Matrix3d::Identity();
  /// The inverse Jacobian of the shooting map (clamp residual per turn of the end) at the
  /// solution when Newton ran, else the last one as the chord steps corrected it (Broyden): the
  /// next solve's iterations use it while it still contracts (a chord method: one plain
  /// integration an iteration instead of one carrying the derivatives). Zero when there is none.
  Eigen::Matrix3d jacobian_inv = Eigen::Matrix3d::Zero();
  bool converged = false;
  int iterations = 0;          ///< Newton iterations used
  double energy_J = 0.0;       ///< bending energy, 1/2 int |m_perp|^2 / (E I) ds
  double max_moment_Nm = 0.0;  ///< largest |m_perp| along the rod
  double end_m = 0.0;          ///< arc position of the last load
  Eigen::Vector3d end_p_m = Eigen::Vector3d::Zero();  ///< centre at end_m
};

/// Where the shape is asked for: arc positions (ascending, within [0, end_m]) and the centre
/// and section frame found there.
struct RodSamples {
  std::span<const double> s_m;
  std::span<Eigen::Vector3d> p_m;
  std::span<Eigen::Matrix3d> R;  ///< may be empty
};

/// A moment on a solved rod's end section, linearised (Rod::Compliance), clamp frame.
struct RodEndMoment {
  Eigen::Matrix3d turn_per_Nm = Eigen::Matrix3d::Zero();  ///< the end section's turn [rad/(N m)]
  /// Each load's surface point's displacement [m/(N m)], by the loads' index in the caller's
  /// span (at most Rod::kMaxLoads of them).
  std::array<Eigen::Matrix3d, 16> w_per_Nm{};
};

class Rod {
 public:
  /// Bending stiffness E I [N m^2] (> 0) and the longest step [m] (> 0).
  Rod(double bending_stiffness_Nm2, double max_step_m);

  /// Solves for the loads (any order; s_m > 0). `end_R_guess` is the end section's frame to
  /// start from: the last solution's, for a rod loaded a little differently, so that a sequence
  /// of solves follows one branch of equilibria as the loads change (a rod pushed past a
  /// buckling load has several). If Newton does not converge from it, the solve starts from the
  /// unloaded rod and grows the load in steps (continuation): the branch that grows
  /// continuously from the straight rod. Never NaN: without convergence `converged` is false
  /// and the figures are those of the last iterate. At most kMaxLoads loads (asserted).
  RodSolution Solve(std::span<const RodLoad> loads, const Eigen::Matrix3d& end_R_guess) const;
  /// The same from a previous solution: its end frame and its Jacobian as the starting point.
  RodSolution Solve(std::span<const RodLoad> loads, const RodSolution& previous) const;
  /// The same, and the solution's shape at the samples (at most kMaxShapeSamples), as Shape
  /// would give it, to the bit: every integration of the solve steps through the samples' arc
  /// positions, so the one that converged has drawn the shape on its way, and the integration
  /// Shape would add is spared. (The breakpoints change the discrete rod a little, within its
  /// discretisation error: a solve with samples is not bit-equal to one without.) The samples
  /// must lie in [0, inf), ascending and finite (std::invalid_argument otherwise); they are the
  /// solution's shape only when it `converged` (else some iterate's, possibly of a
  /// continuation step).
  RodSolution Solve(std::span<const RodLoad> loads, const RodSolution& previous,
                    const RodSamples& shape) const;

  /// Solves with each load's force across the clamp's axis (its x and y) unknown as well: the
  /// forces that put the centre at each load's arc position at `pinned_xy_m` (x, y of the clamp
  /// frame, one per load in the loads' order), the axial parts (z) as given. A rod whose load
  /// points are held sideways by stiff contacts: pushed along its axis past the free end's
  /// Euler load, the dead-load solve swings the end away by centimetres under a force that
  /// rounding decides (the buckled branch), where held sideways it stays straight up to the
  /// pinned column's own buckling load, eight times as large. One Newton iteration solves for the
  /// end's turn and the lateral forces together (their Jacobian from one integration, exact for
  /// the discrete rod), from `start` (the last solution), each step halved (up to three times)
  /// until it brings the residuals down; at most kMaxPinnedIterations, and given up at a second
  /// step that does not halve them (it is not converging from this start). Converged (the
  /// clamp within 1e-10 rad, each point within 1e-10 of the end's arc position, on the solve's
  /// own steps) and within half a radian of the start, the loads' x, y are the solution's and
  /// the shape is drawn at `shape`'s samples (positions only; a rod within its discretisation
  /// error of the solve's); otherwise `converged` is false and neither is written.
  RodSolution SolvePinned(std::span<RodLoad> loads, const RodSolution& start,
                          std::span<const Eigen::Vector2d> pinned_xy_m,
                          const RodSamples& shape) const;

  /// The shape of a solved rod at the samples' arc positions (within [0, end_m]).
  void Shape(std::span<const RodLoad> loads, const RodSolution& solution,
             const RodSamples& samples) const;

  /// Tangent compliance at a solution: w[i * count + j] = d p_i / d F_j [m/N] for the surface
  /// points p_i = centre(s_i) + R(s_i) R*(s_i)^T r_i of the loads (R* the solved frame), the end
  /// frame following the loads so that the rod stays clamped: p_i and the clamp residual e move
  /// with the end frame's rotation q and with F_j, and d p / d F = dp/dF - dp/dq (de/dq)^-1
  /// de/dF, all from one integration carrying the 3 + 3 count directions (exact derivatives of
  /// the discrete map).
  /// False if the shooting Jacobian is singular (at a bifurcation).
  /// If `end_turn` is not empty (size >= loads.size()), end_turn[j] is also written: the turn of
  /// the end section (clamp frame, rad per N of load j's force, a column per force axis) that
  /// keeps the root clamped: with it a caller predicts the next solve's end from a change of
  /// the forces (BeamChain::SolveRodChain).
  /// If `end_moment` is given, it is written too: what a moment on the end section (the section
  /// at the last load, clamp frame) does with the root kept clamped, from three more directions
  /// of the same integration. Its end turn per moment and each load's surface point's
  /// displacement per moment; the latter is the transpose of `end_turn` (Maxwell-Betti, to the
  /// discrete rod's asymmetry: its chain is in equilibrium at its nodes, not derived from an
  /// energy).
  bool Compliance(std::span<const RodLoad> loads, const RodSolution& solution,
                  std::span<Eigen::Matrix3d> w, std::span<Eigen::Matrix3d> end_turn = {},
                  RodEndMoment* end_moment = nullptr) const;

  double bending_stiffness_Nm2() const { return EI_; }
  double max_step_m() const { return max_step_m_; }

  static constexpr int kMaxLoads = 16;
  static constexpr int kMaxShapeSamples = 129;
  /// Newton iterations one Solve may spend, continuation included (each one integration
  /// carrying its Jacobian, ~2.5 plain ones, and more if the step is damped).
  static constexpr int kMaxIterations = 320;
  static constexpr int kMaxPinnedIterations = 12;

 private:
  struct Result {
    Eigen::Vector3d residual = Eigen::Vector3d::Zero();  ///< rotation vector of the root frame
    Eigen::Vector3d root_moment = Eigen::Vector3d::Zero();
    double energy_J = 0.0, max_moment_Nm = 0.0;
    Eigen::Vector3d end_p = Eigen::Vector3d::Zero();
  };
  // The derivatives of an integration along directions of its inputs, carried with it (rod.cpp).
  template <int kMaxDirections>
  struct Tangent;
  // Integrates from the last load (frame Q) back to the clamp with the loads scaled by `scale`;
  // writes the centre (relative to the root's) and frame at the sample positions (ascending), and
  // the derivatives when `tangent` is given. Loads must be sorted by s (order).
  template <int kMaxDirections>
  Result Integrate(std::span<const RodLoad> loads, std::span<const int> order, double scale,
                   const Eigen::Matrix3d& Q, const RodSamples& samples,
                   Tangent<kMaxDirections>* tangent) const;
  Result Integrate(std::span<const RodLoad> loads, std::span<const int> order, double scale,
                   const Eigen::Matrix3d& Q, const RodSamples& samples) const;
  // The samples a solve draws the shape at (`shape`, possibly empty) and where its trial
  // integrations draw theirs until one is accepted (`trial`: the same arc positions).
  struct ShapeBuffers {
    RodSamples shape, trial;
    void Accept() const;  // the trial's samples become the shape's
  };
  bool Newton(std::span<const RodLoad> loads, std::span<const int> order, double scale,
              int max_iterations, Eigen::Matrix3d& Q, Eigen::Matrix3d& jacobian_inv,
              int& iterations, Result& result, const ShapeBuffers& buffers) const;
  RodSolution SolveFrom(std::span<const RodLoad> loads, const Eigen::Matrix3d& end_R_guess,
                        const Eigen::Matrix3d& jacobian_inv, const RodSamples& shape) const;

  double EI_ = 0.0;
  double max_step_m_ = 0.0;
};
static_assert(std::tuple_size_v<decltype(RodEndMoment::w_per_Nm)> == Rod::kMaxLoads);

}  // namespace tubeplan::model
