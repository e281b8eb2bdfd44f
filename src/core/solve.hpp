#pragma once
// The solve stage: Newton's method on the tick's incremental potential, from the last tick's
// shape, with a line search, a cap on how far any point moves in one iteration, and a way out of
// saddles (docs/core.md, "Solving a tick").

#include "core/data.hpp"
#include "core/model.hpp"

namespace tubeplan::core {

/// Moves data.state.x_W to the equilibrium nearest it (or as far towards one as the iteration
/// cap allows), with data.scratch.samples the contact points there; reports in data.solve.
void SolveEquilibrium(const Model& model, Data& data);

}  // namespace tubeplan::core
