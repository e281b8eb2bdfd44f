#pragma once
// Robustness of a plan: its trajectory perturbed the way a second operator, or the same one on
// another day, would move differently — a constant offset of the hand, physiological tremor, a
// faster or slower motion — and judged again (tubeplan evaluate --monte-carlo).

#include <cstdint>

#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::trajectories {

struct Perturbation {
  double offset_m = 1e-3;   ///< constant hand offset, uniform in a ball of this radius
  double tremor_m = 1e-4;   ///< 8-12 Hz tremor amplitude per axis (physiological: ~0.1 mm)
  double speed_min = 0.8;   ///< speed factor drawn uniformly in [speed_min, speed_max]:
  double speed_max = 1.25;  ///< the motion runs that many times as fast
};

/// Replicate `replicate` of `trajectory` under `p`, from generator seed `seed` (the same seed and
/// replicate give the same trajectory on any machine and thread).
Trajectory Perturb(const Trajectory& trajectory, const Perturbation& p, std::uint64_t seed,
                   int replicate);

/// Wilson score interval (95 %, z = 1.96) of a proportion of `successes` in `trials` (> 0).
struct Interval {
  double low = 0.0, high = 1.0;
};
Interval WilsonInterval(int successes, int trials);

}  // namespace tubeplan::trajectories
