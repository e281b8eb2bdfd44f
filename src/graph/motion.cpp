#include <algorithm>
#include <cmath>
#include <utility>

#include <tubeplan/graph/motion.hpp>

namespace tubeplan::graph {

MotionRunner::MotionRunner(const Motion& motion, const Eigen::Isometry3d& X_W_start,
                           double time_step_s)
    : moves_(motion.moves),
      step_s_(time_step_s),
      p_W_m_(X_W_start.translation()),
      q_W_(Eigen::Quaterniond(X_W_start.linear())),
      p_from_W_m_(p_W_m_),
      q_from_W_(q_W_) {}

MotionRunner::Position MotionRunner::position() const {
  return {move_, move_tick_, move_ticks_, p_W_m_, p_from_W_m_, q_W_, q_from_W_};
}

void MotionRunner::Resume(const Position& at) {
  move_ = at.move;
  move_tick_ = at.move_tick;
  move_ticks_ = at.move_ticks;
  p_W_m_ = at.p_W_m;
  p_from_W_m_ = at.p_from_W_m;
  q_W_ = at.q_W;
  q_from_W_ = at.q_from_W;
}

Eigen::Isometry3d MotionRunner::Pose() const {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = q_W_.normalized().toRotationMatrix();
  X.translation() = p_W_m_;
  return X;
}

namespace {

// Where a move that starts at p_from_W ends.
Eigen::Vector3d TargetOf(const Move& move, const Eigen::Vector3d& p_from_W) {
  if (!move.relative) return move.p_W_m;
  const Eigen::Vector3d p = p_from_W + move.p_W_m;
  if (move.within_W.isEmpty()) return p;
  return p.cwiseMax(move.within_W.min()).cwiseMin(move.within_W.max());
}

}  // namespace

Eigen::Isometry3d MotionRunner::Next(const core::StepOutput& last) {
  while (move_ < moves_.size()) {
    const Move& move = moves_[move_];
    if (move_ticks_ == 0) {
      // Start the move from where the hand is; its duration comes from the slower of the
      // translation and the rotation, whole ticks, at least one.
      p_from_W_m_ = p_W_m_;
      q_from_W_ = q_W_;
      const double distance_m = (TargetOf(move, p_from_W_m_) - p_from_W_m_).norm();
      const double angle_rad = q_from_W_.angularDistance(move.q_W);
      const double duration_s = std::max(distance_m / std::max(move.speed_m_per_s, 1e-6),
                                         angle_rad / std::max(move.turn_rad_per_s, 1e-6));
      move_ticks_ =
          std::max({1, move.min_ticks, static_cast<int>(std::ceil(duration_s / step_s_ - 1e-9))});
      move_tick_ = 0;
    }
    const bool guarded = move.guard_N > 0.0 && move_tick_ > 0;
    const bool limited = move.force_limit_N > 0.0 && move_tick_ > 0;
    if (move_tick_ == move_ticks_ || (move.max_ticks > 0 && move_tick_ >= move.max_ticks) ||
        (guarded && last.force_W_N.dot(move.guard_dir_W) > move.guard_N) ||
        (limited && last.force_W_N.norm() > move.force_limit_N)) {
      ++move_;
      move_ticks_ = 0;
      continue;
    }
    ++move_tick_;
    const double u = static_cast<double>(move_tick_) / move_ticks_;
    p_W_m_ = p_from_W_m_ + u * (TargetOf(move, p_from_W_m_) - p_from_W_m_);
    q_W_ = q_from_W_.slerp(u, move.q_W);
    break;
  }
  return Pose();
}

std::vector<Move> Prefix(const Motion& motion, int move, int move_tick) {
  const std::size_t whole =
      std::min(static_cast<std::size_t>(std::max(move, 0)), motion.moves.size());
  std::vector<Move> moves(motion.moves.begin(), motion.moves.begin() + static_cast<long>(whole));
  if (whole < motion.moves.size() && move_tick > 0) {
    Move cut = motion.moves[whole];
    cut.max_ticks = cut.max_ticks > 0 ? std::min(cut.max_ticks, move_tick) : move_tick;
    moves.push_back(cut);
  }
  return moves;
}

Motion MotionAlong(const trajectories::Trajectory& trajectory, double time_step_s,
                   int ticks_per_move, double speed_m_per_s, std::string kind) {
  const std::vector<trajectories::HandSample> ticks =
      trajectories::Resample(trajectory, time_step_s);
  Motion motion;
  motion.kind = std::move(kind);
  Move first;
  first.p_W_m = ticks.front().p_WH_m;
  first.q_W = ticks.front().q_WH;
  first.speed_m_per_s = speed_m_per_s;
  motion.moves.push_back(first);
  const std::size_t every = std::size_t(std::max(1, ticks_per_move));
  for (std::size_t from = 0; from + 1 < ticks.size();) {
    const std::size_t to = std::min(from + every, ticks.size() - 1);
    Move move;
    move.p_W_m = ticks[to].p_WH_m;
    move.q_W = ticks[to].q_WH;
    // The ticks set the pace: no speed limit slows the hand below the trajectory's.
    move.speed_m_per_s = 1e3;
    move.turn_rad_per_s = 1e3;
    move.min_ticks = static_cast<int>(to - from);
    motion.moves.push_back(move);
    from = to;
  }
  return motion;
}

Eigen::Isometry3d MotionStart(const scene::Scene& scene) { return scene.X_WH_start; }

std::string RestingFormation(const scene::Scene& scene) {
  core::Core core(scene);
  core.Reset(MotionStart(scene));
  core.Step(scene.model.time_step_s, MotionStart(scene));
  return core.FormationText();
}

void ReplaySubsteps(core::Core& core, const Motion& motion, int tick, int substeps,
                    const std::function<bool(int, const core::StepOutput&)>& on_substep,
                    const Checkpoint* from) {
  const scene::Scene& scene = core.scene();
  const double step_s = scene.model.time_step_s;
  const Eigen::Isometry3d X_start = MotionStart(scene);
  MotionRunner runner(motion, X_start, step_s);
  Eigen::Isometry3d X_prev = X_start;
  int k = 1;
  if (from != nullptr && from->tick < tick && core.Restore(from->core)) {
    runner.Resume(from->runner);
    X_prev = runner.Pose();
    k = from->tick + 1;
  } else {
    core.Reset(X_start);
  }
  for (; k < tick; ++k) {
    X_prev = runner.Next(core.last());
    core.Step(k * step_s, X_prev);
  }
  const Eigen::Isometry3d X_next = runner.Next(core.last());
  const Eigen::Quaterniond q_prev(X_prev.linear()), q_next(X_next.linear());
  for (int j = 1; j <= substeps; ++j) {
    // The sub-ticks are core ticks of the scene's step: the hand covers the tick's motion more
    // slowly, which is what refining a motion means here.
    const double u = static_cast<double>(j) / substeps;
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = q_prev.slerp(u, q_next).normalized().toRotationMatrix();
    X.translation() = X_prev.translation() + u * (X_next.translation() - X_prev.translation());
    const core::StepOutput& out = core.Step((tick - 1 + j) * step_s, X);
    if (!on_substep(j, out)) break;
  }
}

const core::StepOutput& ReplayTo(core::Core& core, const Motion& motion, const TickRef& ref) {
  if (ref.substeps > 0) {
    ReplaySubsteps(core, motion, ref.tick, ref.substeps,
                   [&](int j, const core::StepOutput&) { return j < ref.substep; });
    return core.last();
  }
  const scene::Scene& scene = core.scene();
  const double step_s = scene.model.time_step_s;
  const Eigen::Isometry3d X_start = MotionStart(scene);
  core.Reset(X_start);
  MotionRunner runner(motion, X_start, step_s);
  for (int k = 1; k <= ref.tick; ++k) core.Step(k * step_s, runner.Next(core.last()));
  return core.last();
}

std::vector<trajectories::HandSample> HandPath(core::Core& core, const Motion& motion, int tick) {
  const double step_s = core.scene().model.time_step_s;
  const Eigen::Isometry3d X_start = MotionStart(core.scene());
  std::vector<trajectories::HandSample> path;
  path.reserve(std::size_t(std::max(tick, 0)) + 1);
  auto add = [&](double t_s, const Eigen::Isometry3d& X_W_hand) {
    path.push_back({t_s, X_W_hand.translation(), Eigen::Quaterniond(X_W_hand.linear())});
  };
  add(0.0, X_start);
  core.Reset(X_start);
  MotionRunner runner(motion, X_start, step_s);
  for (int k = 1; k <= tick && !runner.Done(); ++k) {
    const Eigen::Isometry3d X_W_hand = runner.Next(core.last());
    core.Step(k * step_s, X_W_hand);
    add(k * step_s, X_W_hand);
  }
  return path;
}

}  // namespace tubeplan::graph
