#pragma once
// The contact stage: every point of the tube's surface closer to a part than epsilon, with its
// distance, normal and derivatives, at the rod's current nodes (docs/core.md, "Contact points").

#include <span>

#include <Eigen/Core>

#include "core/data.hpp"
#include "core/model.hpp"

namespace tubeplan::core {

/// Which parts the tube can touch this tick: those whose box comes within reach of the rod's
/// nodes, grown by how far the tick may move them.
void FindPartsNear(const Model& model, std::span<const Eigen::Vector3d> x_W, double reach_m,
                   Data& data);

/// Where a contact point sits on the tube is chosen when the point is first found in a tick and
/// kept for the tick (the rim's on a frictionless part: at every iterate). At a trial point of the
/// line search the new choices are pending until the point is taken (CommitContactChoices), so that
/// a rejected trial leaves nothing behind.
enum class Choices { kKeep, kPending };

/// Fills data.scratch.samples with the contact points at the nodes x_W.
void FindContacts(const Model& model, std::span<const Eigen::Vector3d> x_W, Data& data,
                  Choices choices = Choices::kKeep);
void CommitContactChoices(Data& data);

}  // namespace tubeplan::core
