#pragma once
// The inextensible elastica of a cantilever under a dead tip load (large deflection;
// docs/models.md, "The elastica under a tip load"). Everything here is dimensionless: arc length s
// in [0, 1] is measured in units of l, positions in units of l, and the load by
// alpha = |F| l^2 / (E I).
//
// The cantilever is clamped at s = 0 along +z (the tube frame O-xyz of linear_beam.hpp); theta(s)
// is the angle of the tangent from +z towards +x. The tip load is
//     F = |F| (cos psi x + sin psi z),  psi in [-pi/2, pi/2]
// (x is chosen so that F_x >= 0; psi = 0 is a pure lateral load, psi = -pi/2 pure compression,
// psi = +pi/2 pure tension), and the equilibrium is
//     theta'' = -alpha cos(theta + psi),  theta(0) = 0,  theta'(1) = 0.
// The solution returned is the first-mode branch that grows continuously from the straight
// cantilever as alpha grows from 0 (for pure compression below Euler's load pi^2/4 that is the
// straight rod itself).

#include <limits>
#include <span>

#include <Eigen/Core>

namespace tubeplan::model {

/// Tip figures of a solved elastica, dimensionless.
struct ElasticaTip {
  double deflection = 0.0;      ///< x(1): lateral tip displacement / l
  double shortening = 0.0;      ///< 1 - z(1): tip shortening / l
  double tip_angle_rad = 0.0;   ///< theta(1) [rad]
  double root_curvature = 0.0;  ///< theta'(0): root moment = (E I / l) * root_curvature
  double energy = 0.0;          ///< 1/2 int_0^1 theta'^2 ds: bending energy U = (E I / l) * energy
};

/// Everything needed to evaluate the solved shape anywhere; plain data, no heap.
struct ElasticaSolution {
  double alpha = 0.0;    ///< load parameter, >= 0
  double psi_rad = 0.0;  ///< load direction, in [-pi/2, pi/2]
  ElasticaTip tip;
  // Solver internals a shape evaluation needs (meaning documented in elastica.cpp).
  double modulus_k = 0.0;   ///< elliptic modulus k = sin(A/2) of the pendulum amplitude A
  double modulus_kc = 1.0;  ///< complementary modulus k' = cos(A/2), kept separately for k -> 1
  double u0 = 0.0;          ///< amplitude-parameter at the root
  int iterations = 0;       ///< root-finding iterations used
  bool series = false;      ///< true when the small-alpha series produced the answer
  /// The load direction's sines (elastica.cpp's Loading: sin(phi0/2), sin(gap/2), cos psi,
  /// sin psi), valid while loading_psi_rad equals psi_rad (NaN: none): a warm start from this
  /// solution and its shape evaluations take them instead of four sin calls each.
  double loading_psi_rad = std::numeric_limits<double>::quiet_NaN();
  double loading_s0 = 0.0, loading_c0 = 0.0, loading_cos_psi = 0.0, loading_sin_psi = 0.0;
  /// std::sin and std::cos of tip.tip_angle_rad, valid while tip_trig_angle_rad equals it (NaN:
  /// none; SolveElastica leaves them so): a caller that forms them anyway keeps them here, and
  /// ElasticaSamples takes them instead of another sine and cosine.
  double tip_trig_angle_rad = std::numeric_limits<double>::quiet_NaN();
  double tip_sin = 0.0, tip_cos = 1.0;
};

/// The largest load parameter SolveElastica accepts.
inline constexpr double kMaxElasticaAlpha = 1e4;

/// Solves the elastica for alpha in [0, kMaxElasticaAlpha = 1e4] and psi in [-pi/2, pi/2]. Never
/// returns NaN or Inf; throws std::invalid_argument for arguments outside those ranges or not
/// finite. psi = +-std::numbers::pi / 2 (the double nearest pi/2) is exactly axial: tension is
/// straight, and compression is straight up to and including alpha = std::numbers::pi^2 / 4 (the
/// double nearest Euler's load), buckled towards +x above it.
ElasticaSolution SolveElastica(double alpha, double psi_rad);
/// The same, started from `near` (a solution for a nearby load, e.g. the last tick's; may be
/// null): the same answer to rounding (~1e-15 relative) in fewer iterations where the load is
/// close, and the search from scratch where Newton from there does not converge within a few
/// steps. The answer then depends on `near` in its last bits only.
ElasticaSolution SolveElastica(double alpha, double psi_rad, const ElasticaSolution* near);

/// Centreline of the solved shape at the arc positions s (each in [0, 1]): out[i] = (x, z) / l and
/// theta_out[i] = theta(s[i]). Sizes of s, xz_out and theta_out must match. No heap allocation.
void ElasticaCentreline(const ElasticaSolution& solution, std::span<const double> s,
                        std::span<Eigen::Vector2d> xz_out, std::span<double> theta_out);

/// The centreline at n = xz_out.size() >= 2 evenly spaced arc positions s_j = j / (n - 1):
/// xz_out[j] = (x, z) / l and tangent_out[j] = (sin theta, cos theta) there. The same shape as
/// ElasticaCentreline (to ~1e-14 of l) at a fraction of its cost: the Jacobi functions go from
/// sample to sample by their addition theorems. Throws std::invalid_argument if the sizes differ
/// or n < 2. No heap allocation.
void ElasticaSamples(const ElasticaSolution& solution, std::span<Eigen::Vector2d> xz_out,
                     std::span<Eigen::Vector2d> tangent_out);
/// The same over [s_first, s_last] (0 <= s_first <= s_last <= 1): s_j = s_first + (s_last -
/// s_first) j / (n - 1), the last exactly s_last.
/// The walk starts afresh at a first sample past the root and a last short of the tip. Throws
/// std::invalid_argument for a range out of [0, 1] or out of order, as for the sizes.
void ElasticaSamples(const ElasticaSolution& solution, double s_first, double s_last,
                     std::span<Eigen::Vector2d> xz_out, std::span<Eigen::Vector2d> tangent_out);

}  // namespace tubeplan::model
