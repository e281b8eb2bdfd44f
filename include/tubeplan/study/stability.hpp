#pragma once
// The stability sweep: stiff and extreme cases driven through core::Core::Step with
// canonical motions, each checked for finite outputs, bounded forces, passivity, no tunnelling
// and bit-identical repetition. docs/accuracy.md has the checks and their tolerances.

#include <string>
#include <vector>

#include <tubeplan/scene/scene.hpp>

namespace tubeplan::study {

enum class Motion {
  kPushIntoWall,    ///< the tip pushed into a wall across the axis
  kSlideAlongWall,  ///< pushed, then moved sideways along it
  kRollOverEdge,    ///< the side pressed on an edge while the hand draws back: it rolls off the tip
  kSqueeze,         ///< inside a groove barely wider than the tube, swung against both walls
  kFastPass,        ///< the hand runs at the case's speed through a 1 mm wall across the axis
};

const char* ToString(Motion motion);

/// One case: a scene (the tube and its parts) and a motion of the hand.
struct StabilityCase {
  std::string name;  ///< "<motion> <parameter>=<value>"
  Motion motion = Motion::kPushIntoWall;
  scene::Scene scene;
  double speed_m_per_s = 0.05;
  /// The hand's offset out of the motion's plane (world y) at every waypoint [m].
  double off_plane_m = 0.0;
  std::string parameter;  ///< the parameter varied from the base case ("base" for none)
  /// Empty when the case lies inside the model's validity; otherwise why not (the case then
  /// passes or fails on the safety checks only: finite, force bounds, same bits).
  std::string outside_validity;
};

struct StabilityResult {
  std::string name;
  std::string motion;
  std::string parameter;
  bool pass = true;
  std::string detail;           ///< what failed, first failing tick, or the figures of a pass
  std::string warning;          ///< outside validity, or a physical check failing there
  int first_failing_tick = -1;  ///< -1 when it passed
  /// Ticks whose solve stopped short of its tolerance (core::kNotConverged: a snap through, or
  /// a jump of the hand), and the first (-1 if none): shown, not judged.
  int unconverged_ticks = 0;
  int first_unconverged_tick = -1;
  /// Outside the model's validity (a warning, not a failure, for the physical checks).
  bool outside = false;
  int ticks = 0;
  double peak_force_N = 0.0;
};

/// The base scene (the rubber tube of scenes/groove.yaml) and the sweep over
/// every motion: E, K, eps, r2/r1, l/r1, hand speed, mu, beta and alpha, one at a time. `quick`
/// takes the extremes only and shorter motions.
std::vector<StabilityCase> StabilityCases(bool quick);

/// Runs one case twice (the second run only for the bits) and checks every tick.
StabilityResult RunStabilityCase(const StabilityCase& c);

}  // namespace tubeplan::study
