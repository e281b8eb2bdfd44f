#pragma once
// The classify stage: the contact formation read off the solved shape and its contact points
// (contact-states.md): principal contacts, their deformation markers, their forces.

#include "core/data.hpp"
#include "core/model.hpp"

namespace tubeplan::core {

/// Fills data.out's contacts and contact_count from data.scratch.samples at data.state.x_W.
void Classify(const Model& model, Data& data);

/// The free end's distance from the line of the held end's axis [m].
double TipDeflection(const Model& model, const Data& data);

}  // namespace tubeplan::core
