#pragma once
// Running the explorer's motions through the core: what one motion records (its debounced
// stays in each CF and the changes between them, refined where several PCs change at once), and
// a group of motions run on threads. Internal to the explorer (src/graph/explore.cpp).

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <tubeplan/core/core.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/motion.hpp>
#include <tubeplan/scene/scene.hpp>
#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::graph::explorer {

using CfKey = core::FormationKey;
using Clock = std::chrono::steady_clock;

// The time limit: none, or the moment after which no motion starts and those under way stop.
struct Deadline {
  std::optional<Clock::time_point> at;
  bool Passed() const { return at && Clock::now() >= *at; }
};

struct Sample {  // what a node keeps of its witness tick
  Eigen::Isometry3d X_W_hand = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_WH = Eigen::Isometry3d::Identity();
  double energy_J = 0.0, friction_N = 0.0, friction_limit_N = 0.0, force_N = 0.0;
  // Where the motion's hand was at that tick (MotionRunner::move, move_tick): a probe motion
  // starts with the motion's Prefix up to there. Sub-tick witnesses keep the tick before's.
  int move = 0, move_tick = 0;
};

struct Stay {  // a stretch of ticks in one CF
  std::string cf;
  int pcs = 0;
  TickRef witness;
  long length = 0;
  bool refined = false;  // seen while refining a step: a weaker witness
  Sample sample;
};

struct Change {
  std::string from, to;
  bool simultaneous = false;
  TickRef at;
};

// A stretch of ticks [start, end] of a motion in one CF, as the core classified them, and the
// sample of its first tick.
struct RawRun {
  std::string text;
  states::ContactFormation cf;
  int start = 0, end = 0;
  Sample first;
};

// A run of a motion after some tick, whole: the core and the runner (Checkpoint) and RunMotion's
// own state there (which CF counts, which are brief, the tick's sample). A run that goes on from
// it records what a run from the motion's start would, bit for bit.
struct RunPoint {
  Checkpoint at;
  CfKey key{};
  RawRun stable, raw;
  std::vector<RawRun> brief;
  Sample sample;
};
using RunPointPtr = std::shared_ptr<const RunPoint>;

struct MotionResult {
  std::vector<Stay> stays;
  std::vector<Change> changes;
  long ticks = 0;
  int refinements = 0;
  bool held_back = false;  // cut at the explorer's force limit or the device's
  bool timed_out = false;  // stopped by the time limit before its end: not a result
  // Per stay: the run's point at or before its witness, from which its CF's probe can start,
  // kept for the first stay of each CF (refined or not) that could become that probe's start
  // (Merger::MayEnter); null for the others.
  std::vector<RunPointPtr> stay_points;
};

// Whether a stay (CF, refined, tick) could become the place its CF's probe starts from: those
// keep a run point (Merger::MayEnter).
using MayEnter = std::function<bool(const std::string&, bool, int)>;

// Runs motions [first, first + count) of `motions` on `jobs` threads, one core pair each; motion
// first + i goes on from resumes[i] where there is one. With `waiting`, the calling thread runs no
// motion: it calls waiting(motions done, motions started) about every `interval_s` until all
// have ended. A motion the deadline stopped, or that it kept from starting, is timed_out.
std::vector<MotionResult> RunAll(const scene::Scene& scene, const std::vector<Motion>& motions,
                                 int first, int count, const std::vector<RunPointPtr>& resumes,
                                 const MayEnter& may_enter, const ExploreOptions& o,
                                 std::vector<std::unique_ptr<core::Core>>& cores,
                                 const Deadline& deadline,
                                 const std::function<void(int, int)>& waiting);

}  // namespace tubeplan::graph::explorer
