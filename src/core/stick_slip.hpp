#pragma once
// The friction stage (docs/core.md, "Friction"): after a solve, which contact points stick and
// which slide; at the tick's end, the anchors the next tick's friction springs start from.

#include "core/data.hpp"
#include "core/model.hpp"

namespace tubeplan::core {

/// The offset from the tube's centreline of the material point that a contact point's friction
/// holds: where its section meets the part, the tube's surface carried across the contact band's
/// gap along the normal, so that a tube turning about the point it touches (over an edge it is
/// stuck on) stretches no spring, as with a hard contact. The rim's and the end face's points
/// keep the tube's surface: their offsets stay in the end's section as it turns.
Eigen::Vector3d FrictionOffset(const Model& model, const Sample& smp);

/// The moment about p_W of a contact point's forces: its normal force at the point, its friction
/// where its friction holds it.
Eigen::Vector3d ContactMoment(const Model& model, const Sample& smp, const Eigen::Vector3d& p_W);

/// Pairs the solved contact points with the carried friction points and checks each against its
/// limit at the solved normal forces: a stuck point whose spring carries more than the static
/// limit starts sliding, a sliding point takes the kinetic limit of its new load, a point whose
/// contact opened lets go. True when anything changed: the equilibrium must be solved again.
bool ReturnFrictionToLimits(const Model& model, Data& data);

/// After the last solve: the friction force and work of every contact point, and the friction
/// points the next tick carries (stuck points keep their anchor, sliding points drag theirs to
/// the kinetic limit, new contacts start stuck where they are).
void CarryFriction(const Model& model, Data& data);

}  // namespace tubeplan::core
