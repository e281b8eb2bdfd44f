#pragma once
// Motions of the operator's hand used to explore a scene with the core: a list of guarded moves,
// each a straight line in position and a slerp in orientation at a set speed, that ends early
// when the force the operator feels along a direction exceeds a set value (the way a person
// probes: "go down until it pushes back"). A motion starts at the scene's start pose. Running a
// motion is deterministic, so a tick of a motion is a reproducible witness of the state the core
// was in: MotionRunner replays it exactly.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/core/core.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::graph {

/// One guarded move: from wherever the hand is to (p_W_m, q_W), at `speed_m_per_s` along the
/// line (and at most `turn_rad_per_s` in rotation), stopping early once the operator force
/// projected on `guard_dir_W` exceeds `guard_N` (guard_N <= 0: unguarded).
struct Move {
  Eigen::Vector3d p_W_m = Eigen::Vector3d::Zero();
  /// p_W_m is an offset from where the hand is when the move starts, not a place: a move that
  /// goes on from wherever a guard stopped the one before. Its target is kept in `within_W`
  /// (an empty box: anywhere).
  bool relative = false;
  Eigen::AlignedBox3d within_W;
  Eigen::Quaterniond q_W = Eigen::Quaterniond::Identity();
  double speed_m_per_s = 0.1;
  double turn_rad_per_s = 1.0;
  Eigen::Vector3d guard_dir_W = Eigen::Vector3d::Zero();
  double guard_N = 0.0;
  /// > 0: the move also stops once the operator force's magnitude exceeds this [N].
  double force_limit_N = 0.0;
  /// > 0: the move lasts at least this many ticks (a move to where the hand is holds it still).
  int min_ticks = 0;
  /// > 0: the move ends after this many ticks, on the path it would have followed whole (how a
  /// motion is cut at a witness tick to go on from there, see Prefix).
  int max_ticks = 0;
};

struct Motion {
  std::string kind;  ///< "sweep", "aim", "random", "probe": how the explorer made it
  std::vector<Move> moves;
  /// Ticks at the start that replay another motion up to a witness (Prefix): what they produce
  /// is known already, so the explorer records only what comes after.
  int prefix_ticks = 0;
};

/// Where a motion is refined: between ticks tick-1 and tick the hand's step is split into
/// `substeps` equal parts, each run as a core tick, from the state the core was in at tick-1.
/// substeps == 0: the motion as it is.
struct TickRef {
  int motion = 0;  ///< index into the explorer's motion list
  int tick = 0;    ///< ticks of the motion run (1 = after the first Step)
  int substeps = 0;
  int substep = 0;  ///< with substeps > 0: how many of the sub-ticks were run (1 .. substeps)
};

/// Feeds a Motion to a core tick by tick. The hand starts at the core's reset pose.
class MotionRunner {
 public:
  MotionRunner(const Motion& motion, const Eigen::Isometry3d& X_W_start, double time_step_s);

  /// Where a runner is between ticks: Resume puts a runner of a motion whose moves are the
  /// same up to there (the motion itself, or one made with Prefix) at the same place.
  struct Position {
    std::size_t move = 0;
    int move_tick = 0, move_ticks = 0;
    Eigen::Vector3d p_W_m = Eigen::Vector3d::Zero(), p_from_W_m = Eigen::Vector3d::Zero();
    Eigen::Quaterniond q_W = Eigen::Quaterniond::Identity();
    Eigen::Quaterniond q_from_W = Eigen::Quaterniond::Identity();
  };
  Position position() const;
  void Resume(const Position& at);
  /// The hand pose the last Next returned (the start pose before the first).
  Eigen::Isometry3d Pose() const;

  bool Done() const { return move_ >= moves_.size(); }
  /// Where the hand is along the motion after the last Next: the move and its tick.
  int move() const { return static_cast<int>(move_); }
  int move_tick() const { return move_tick_; }
  /// The hand pose for the next tick, given the core's last output (its force drives the guards).
  Eigen::Isometry3d Next(const core::StepOutput& last);

 private:
  std::vector<Move> moves_;
  std::size_t move_ = 0;
  double step_s_;
  Eigen::Vector3d p_W_m_;
  Eigen::Quaterniond q_W_;
  Eigen::Vector3d p_from_W_m_;
  Eigen::Quaterniond q_from_W_;
  int move_tick_ = 0;
  int move_ticks_ = 0;
};

/// A point of a motion's run to go on from without replaying the motion up to it: the core's
/// state and the runner's position after tick `tick`.
struct Checkpoint {
  int tick = 0;
  core::Core::Snapshot core;
  MotionRunner::Position runner;
};

/// The moves of `motion` up to tick `move_tick` of move `move` (a MotionRunner's move() and
/// move_tick() after some tick k): run, they put the hand where `motion` had it at tick k, bit for
/// bit, and moves appended to them go on from there.
std::vector<Move> Prefix(const Motion& motion, int move, int move_tick);

/// A motion that follows `trajectory` on the core's step `time_step_s`: from the scene's start to
/// its first pose at `speed_m_per_s`, then a move every `ticks_per_move` ticks to where the
/// trajectory is then, so that the hand is on it at the end of every move and on the chord
/// between (a replay of a plan's trajectory the explorer can cut and resume as its own motions).
Motion MotionAlong(const trajectories::Trajectory& trajectory, double time_step_s,
                   int ticks_per_move, double speed_m_per_s, std::string kind);

/// The held-end pose a motion's start puts the hand at (the scene's start pose).
Eigen::Isometry3d MotionStart(const scene::Scene& scene);

/// The CF's text the core gives after one tick at rest at MotionStart: the state a plan would
/// start in.
std::string RestingFormation(const scene::Scene& scene);

/// Runs `motion` through `core` (reset to the scene's start) up to and including `ref`, and
/// returns the last step's output. The core is left in that state.
const core::StepOutput& ReplayTo(core::Core& core, const Motion& motion, const TickRef& ref);

/// The hand's path along `motion` up to tick `tick`, as a run through `core` moves it (its
/// guards stop moves where the core's forces say): sample k is the pose the explorer fed the
/// core at tick k, at t = k T; sample 0 is the start pose.
std::vector<trajectories::HandSample> HandPath(core::Core& core, const Motion& motion, int tick);

/// Runs ticks 1 .. tick-1 of `motion`, then splits the hand's step of `tick` into `substeps`
/// sub-ticks and runs them, calling on_substep(j, output) after sub-tick j; stops when it
/// returns false. ReplayTo uses it, so a refined witness replays bit for bit. With `from` (a
/// checkpoint of a run of `motion` before `tick`), the ticks up to the checkpoint's are not run
/// but restored: the same bits, sooner.
void ReplaySubsteps(core::Core& core, const Motion& motion, int tick, int substeps,
                    const std::function<bool(int, const core::StepOutput&)>& on_substep,
                    const Checkpoint* from = nullptr);

}  // namespace tubeplan::graph
