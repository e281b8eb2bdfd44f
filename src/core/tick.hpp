#pragma once
// The stages of a tick that set it up and close it (docs/core.md, "A tick"): reading the hand,
// the output the drivers read, what is carried to the next tick.

#include <Eigen/Geometry>

#include "core/data.hpp"
#include "core/model.hpp"

namespace tubeplan::core {

/// Reads the hand's pose, turns the held end with it (a rigid grip), and places the tube where
/// the solve starts from. False, nothing changed, when the pose is not finite.
bool StartTick(const Model& model, double t_s, const Eigen::Isometry3d& X_W_hand, Data& data);

/// A tick that could not be solved: the tube stays as the tick found it, the force is zero.
void HoldStill(const Model& model, Data& data);

/// The wrench on the operator, energies, strain and flags of the solved tick.
void WriteOutput(const Model& model, Data& data);

/// What the next tick needs of this one: the hand and held end, where contact points entered.
void EndTick(const Model& model, Data& data);

}  // namespace tubeplan::core
