#pragma once
// Builds the contact-state graph of a scene by exploring it with the core (docs/graph.md):
//  1. sweeps: the tube, level and tipped down, lowered into the parts at a row of lateral
//     offsets until it pushes back, slid sideways both ways, pushed along its axis, lifted;
//  2. aims: for each element of a reachable part that no PC has touched yet, motions that bring
//     the tube's tip and then its side against that element (elements whose outside is covered
//     by another part are not aimed at);
//  3. random guarded motions from a seed, until `effort` motions in a row add no node or arc.
// A step that changes more than one PC is re-run from the tick before with the hand's step split
// into sub-ticks; what the sub-ticks produce is recorded, and a change that stays multiple is
// flagged simultaneous. Motions run in parallel on `jobs` threads, each with its own core, and
// are merged in motion order, so the graph depends on the seed only, not on `jobs`.

#include <cstdint>
#include <functional>

#include <tubeplan/graph/contact_graph.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::graph {

struct ExploreOptions {
  std::uint64_t seed = 1;
  /// Saturation: stop after this many random motions in a row added no node and no arc.
  int effort = 40;
  /// A bound whatever happens: the groove's graph has a long tail of rare transitions (corners
  /// of parts, three-PC wedges) that random motions keep finding one at a time.
  int max_motions = 300;
  int jobs = 1;
  double push_N = 2.0;          ///< guard force of the probing moves
  double speed_m_per_s = 0.08;  ///< hand speed of sweeps and aims (a calm human motion)
  int substeps = 16;            ///< sub-ticks per tick when refining a multi-PC change
  /// A CF counts once the core has kept it this long (the plan judge's dwell); briefer states
  /// are flicker, not nodes, unless they bridge a two-PC change.
  double dwell_s = 0.020;
};

/// Number of PC changes between two CFs: a PC added, removed or re-marked counts one; a PC that
/// keeps one of its elements and changes the other (Ee -> Fe on the same face, a rim sliding
/// from a face onto its edge) counts one.
int PcChanges(const states::ContactFormation& a, const states::ContactFormation& b);

/// Explores `scene` and returns the unpruned graph. `progress` (may be empty) is called after
/// each merged motion.
ContactGraph Explore(const scene::Scene& scene, const ExploreOptions& options,
                     const std::function<void(const SaturationPoint&)>& progress = {});

/// `count` random motions from `seed` as the explorer makes them (for independent checks).
std::vector<Motion> RandomMotions(const scene::Scene& scene, std::uint64_t seed, int first,
                                  int count, const ExploreOptions& options);

}  // namespace tubeplan::graph
