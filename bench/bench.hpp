#pragma once
// The bench harness (`tubeplan bench`, docs/core.md): scenarios of the beam models and of the
// core's tick, each timed over samples with std::chrono::steady_clock after a warm-up. Calls far
// shorter than the clock's overhead (~20 ns) are timed in batches and reported per call. Each
// core scenario steps kReplicas cores in lockstep (the same scene and hand poses, so the same
// state to the bit, checked by their outputs) and times each: a tick's own cost is the least of
// its replicas' times, the machine's interruptions (20-80 us, a few hundred a second on a shared
// machine) no part of it. Nothing here passes or fails a build: tests never time anything.

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <tubeplan/model/tube.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::bench {

/// Cores stepped in lockstep by each core scenario.
inline constexpr int kReplicas = 3;

/// One timed call (or batch of calls) and the figures it is held to.
struct Scenario {
  std::string name;
  std::string what;
  int calls_per_sample = 1;
  double target_s = 0.0;  ///< the figure set for the median; 0 when none
  /// Runs calls_per_sample calls with inputs chosen by the sample index; returns a value that
  /// depends on every result so the compiler cannot drop the work.
  std::function<double(int sample)> run;
  double target_p999_s = 0.0;  ///< the figure set for p99.9; 0 when none
  /// For core scenarios: what the core was doing while timed (asked after the run).
  std::function<nlohmann::json()> state = nullptr;
  /// For core scenarios: the same call on replica r (1 .. replicas - 1), a core that has seen
  /// everything `run` has; it returns the same value as `run` did for this sample.
  std::function<double(int sample, int replica)> replica = nullptr;
  int replicas = 1;
};

/// A scenario's times [s] over its samples.
struct Figures {
  double median_s = 0.0, p99_s = 0.0, p999_s = 0.0, max_s = 0.0;
  /// Over each sample's least time across the replicas (equal to the above without replicas).
  double own_median_s = 0.0, own_p99_s = 0.0, own_p999_s = 0.0, own_max_s = 0.0;
  int replica_mismatches = 0;  ///< samples where a replica's result differed (must stay 0)
};

/// Times `scenario` over `samples` samples after a warm-up; `sink` takes every result.
Figures Measure(const Scenario& scenario, int samples, double& sink);
/// The beam models' scenarios for `tube` (linear beam, elastica).
std::vector<Scenario> MakeScenarios(const model::TubeSpec& tube);
/// The hand's poses of the contact scenarios, for a groove along world y with its floor's top at
/// z = 0 (the shipped scenes' layout), sized by the tube and by the gap between the tube and the
/// wall named `left` (the groove taken as symmetric), so that each scenario reaches the same
/// contact formation on a soft short tube and a stiff long one.
struct CorePoses {
  Eigen::Isometry3d end, two_pcs, three_pcs, side_on_floor;
};
CorePoses PosesFor(const scene::Scene& scene);

/// How long a core scenario's hand takes from the scene's start to its pose [s].
inline constexpr double kApproach_s = 0.5;

/// The hand's pose t_s after a core scenario starts: from `start` to `at` along a smooth step
/// (3u^2 - 2u^3, positions linearly, orientations by slerp) in kApproach_s, then held at `at`.
Eigen::Isometry3d Approach(const Eigen::Isometry3d& start, const Eigen::Isometry3d& at, double t_s);

/// The dither of the scenarios held still: 20 um up and down, a period of 126 ticks, so that
/// every tick does real work without changing the state.
Eigen::Isometry3d Dither(const Eigen::Isometry3d& X, long tick);

/// The core's tick in `scene`: free, an end stuck and sliding, two and three PCs, a side on a
/// floor, the end and the side on the floor made a 10,092-triangle mesh (when the scene has a
/// box named "floor"); each with its targets.
std::vector<Scenario> MakeCoreScenarios(const scene::Scene& scene);

}  // namespace tubeplan::bench
