#pragma once
// The discrete rod's energies and the material points on its surface, with their derivatives
// (docs/core.md, "The rod"). Nodes x_0 .. x_N; x_0 is the held end and x_1 = x_0 + l/N t_H, so
// the grip holds the first element's direction.

#include <array>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "core/model.hpp"

namespace tubeplan::core {

/// An energy term's gradient and Hessian over a stencil of up to three consecutive nodes.
/// Only the first 3 `nodes` rows and columns are read, and each term writes them all.
struct StencilTerm {
  int first = 0;             ///< the stencil's first node
  int nodes = 0;             ///< 1, 2 or 3
  bool with_hessian = true;  ///< whether the term is asked for its Hessian too
  Eigen::Matrix<double, 9, 1> gradient = Eigen::Matrix<double, 9, 1>::Zero();
  Eigen::Matrix<double, 9, 9> hessian = Eigen::Matrix<double, 9, 9>::Zero();
};

/// Bending at node i: (EI / h) (1 - cos phi_i), phi_i the angle between the elements on either
/// side; at the grip (i = 0) between the held end's axis t_H and the first element, with twice
/// the weight (the grip's half element carries half the length and twice the curvature). Its
/// energy is returned and, when `term` is given, filled.
double BendingEnergy(const RodModel& rod, const Eigen::Vector3d& t_H,
                     std::span<const Eigen::Vector3d> x_W, int i, StencilTerm* term);

/// Stretching of element i (from node i to i + 1): (EA / 2h) (|e_i| - h)^2. Its Hessian keeps the
/// geometric term, negative for a shortened element: the softening that lets a column buckle.
double StretchEnergy(const RodModel& rod, std::span<const Eigen::Vector3d> x_W, int i,
                     StencilTerm* term);

/// The paper's small-deflection beam (model.beam: linear) at node i: EI / (2 h^3) |b|^2 with b
/// the lateral part, in the held frame, of x_{i+1} - 2 x_i + x_{i-1} (at the grip, i = 0, of
/// x_1 - x_0, with twice the weight). Its elements keep their length along the held axis
/// (`AxialHoldEnergy` of element i), not their length: the paper's beam has no axial response
/// and stretches as it deflects.
double LinearBendingEnergy(const RodModel& rod, const Eigen::Matrix3d& R_WH,
                           std::span<const Eigen::Vector3d> x_W, int i, StencilTerm* term);
double AxialHoldEnergy(const RodModel& rod, const Eigen::Matrix3d& R_WH,
                       std::span<const Eigen::Vector3d> x_W, int i, StencilTerm* term);

/// Where a point of the tube's surface sits on the rod: the centre it is offset from (a node, or
/// a point of an element) and the tangent that carries its offset.
enum class Carrier : unsigned char {
  kInnerNode,  ///< node i, 1 <= i <= N-1, tangent bisecting its two elements
  kEndNode,    ///< node N, tangent of the last element
  kElement,    ///< the point theta of element i (nodes i, i+1), its tangent
  kCurve,      ///< the point theta of the smooth centreline's piece about inner node i
               ///< (CurveWeights); an offset turns with node i's tangent
};

/// The tube's smooth centreline about inner node i: the quadratic B-spline of nodes i - 1, i and
/// i + 1, from the middle of element i - 1 (theta 0) to the middle of element i (theta 1),
/// c(theta) = sum_k w_k x_{i-1+k}. Neighbouring pieces meet with the same point and tangent, so
/// the surface around it has no edges at the nodes.
std::array<double, 3> CurveWeights(double theta);
/// d w_k / d theta: the tangent c'(theta) = sum_k w'_k x_{i-1+k}.
std::array<double, 3> CurveSlopes(double theta);

/// A material point: the centre plus an offset perpendicular to the tangent, carried with the
/// section as the tangent turns (no twist).
struct MaterialPoint {
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();
  /// The carrier's tangent that turns the offset; zero for a point without one (CarrierTangent
  /// gives it).
  Eigen::Vector3d tangent_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset_W = Eigen::Vector3d::Zero();  ///< perpendicular to the tangent
  int first = 0;                                       ///< first node of the stencil
  int nodes = 0;
  Eigen::Matrix<double, 3, 9> jacobian = Eigen::Matrix<double, 3, 9>::Zero();
};

/// The tangent at a carrier (unit).
Eigen::Vector3d CarrierTangent(Carrier carrier, std::span<const Eigen::Vector3d> x_W, int i);
/// d tangent / d nodes of the carrier's stencil (the nodes from i - 1 at a node, from i on an
/// element).
Eigen::Matrix<double, 3, 9> TangentJacobian(Carrier carrier, std::span<const Eigen::Vector3d> x_W,
                                            int i);
Eigen::Vector3d CarrierCentre(Carrier carrier, std::span<const Eigen::Vector3d> x_W, int i,
                              double theta);

/// The inner nodes' tangents (kInnerNode, kCurve) and their derivatives, each kept with the three
/// nodes it was found at and given again while those nodes have the same bits: a tick asks for
/// node i's many times at the same nodes (its section's contact, its friction point's spring in
/// every assembly and friction pass, the anchor). Sized once; it allocates nothing after.
/// Kept per node: saves 5 % of side_on_floor's median tick on groove.yaml and 6 % on
/// groove-steel.yaml (`tubeplan bench`), where every inner node carries a friction point.
class NodeTangents {
 public:
  void Resize(int nodes);
  /// CarrierTangent(Carrier::kInnerNode, x_W, i) and TangentJacobian(Carrier::kInnerNode, x_W, i).
  const Eigen::Vector3d& Tangent(std::span<const Eigen::Vector3d> x_W, int i);
  const Eigen::Matrix<double, 3, 9>& Jacobian(std::span<const Eigen::Vector3d> x_W, int i);

 private:
  struct Entry {
    /// x_{i-1}, x_i, x_{i+1} they were found at
    std::array<Eigen::Vector3d, 3> nodes_W{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                           Eigen::Vector3d::Zero()};
    Eigen::Vector3d tangent_W = Eigen::Vector3d::Zero();
    Eigen::Matrix<double, 3, 9> jacobian = Eigen::Matrix<double, 3, 9>::Zero();
    bool has_tangent = false, has_jacobian = false;
  };
  Entry& At(std::span<const Eigen::Vector3d> x_W, int i);
  std::vector<Entry> entries_;
};

/// The material point whose offset was `offset0_W` (any length), turned into the plane normal to
/// the carrier's current tangent, with d point / d nodes when `jacobian` is set; an inner node's
/// tangent from `tangents` when given (the same bits).
MaterialPoint Material(Carrier carrier, std::span<const Eigen::Vector3d> x_W, int i, double theta,
                       const Eigen::Vector3d& offset0_W, bool jacobian = true,
                       NodeTangents* tangents = nullptr);

}  // namespace tubeplan::core
