#pragma once
// The tick's incremental potential and its derivatives: the rod's bending (and its stiff axial
// spring), the coupling to the hand, the penalty of every contact point and the friction springs
// (docs/core.md, "One equilibrium per tick").

#include <span>

#include <Eigen/Core>

#include "core/data.hpp"
#include "core/model.hpp"
#include "core/rod.hpp"

namespace tubeplan::core {

/// The unknowns: the nodes 0 .. N, node 0 being the held end.
int UnknownCount(const Model& model);
void NodesOf(const Model& model, const Eigen::VectorXd& q, std::span<Eigen::Vector3d> x_W);
void UnknownsOf(const Model& model, std::span<const Eigen::Vector3d> x_W, Eigen::VectorXd& q);

/// What Assemble computes besides the potential.
enum class Derivatives { kNone, kGradient, kHessian };

/// The potential at the nodes x_W with the contact points in data.scratch.samples (found at
/// x_W); and, as asked, its gradient (and Hessian) in data.scratch.
double Assemble(const Model& model, Data& data, std::span<const Eigen::Vector3d> x_W,
                Derivatives derivatives);

/// The coupling's part of the potential at the held end's position: its energy, its gradient
/// (the force the operator feels) and Hessian.
struct CouplingTerm {
  double energy_J = 0.0;
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();
  Eigen::Matrix3d stiffness_N_per_m = Eigen::Matrix3d::Zero();
  bool saturated = false;  ///< the spring is stretched beyond the device's force
};
CouplingTerm Coupling(const Model& model, const Data& data, const Eigen::Vector3d& p_held_W);

/// The parts of the potential the output reports: the rod's bending energy [J].
double BendingEnergyOf(const Model& model, const Data& data, std::span<const Eigen::Vector3d> x_W);

/// The material point of a friction point at the nodes x_W (Material, with `tangents`).
MaterialPoint FrictionMaterial(const Model& model, const FrictionPoint& f,
                               std::span<const Eigen::Vector3d> x_W, NodeTangents& tangents,
                               bool jacobian = false);

}  // namespace tubeplan::core
