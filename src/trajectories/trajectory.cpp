#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tubeplan/trajectories/trajectory.hpp>

namespace tubeplan::trajectories {
namespace {

HandSample Interpolate(const HandSample& a, const HandSample& b, double t_s) {
  if (t_s == a.t_s) return a;
  if (t_s == b.t_s) return b;
  const double s = (t_s - a.t_s) / (b.t_s - a.t_s);
  HandSample out;
  out.t_s = t_s;
  out.p_WH_m = a.p_WH_m + s * (b.p_WH_m - a.p_WH_m);
  // q and -q are the same rotation: interpolate towards whichever of b, -b is nearer to a, so
  // the hand never swings the long way round between two samples.
  Eigen::Quaterniond q_b = b.q_WH;
  if (a.q_WH.dot(q_b) < 0.0) q_b.coeffs() = -q_b.coeffs();
  out.q_WH = a.q_WH.slerp(s, q_b).normalized();
  return out;
}

}  // namespace

HandSample PoseAt(const Trajectory& trajectory, double t_s, std::size_t& cursor) {
  const std::vector<HandSample>& v = trajectory.samples;
  if (v.empty()) throw std::invalid_argument("PoseAt: empty trajectory");
  if (t_s <= v.front().t_s) {
    cursor = 0;
    HandSample held = v.front();
    held.t_s = t_s;
    return held;
  }
  if (t_s >= v.back().t_s) {
    cursor = v.size() - 1;
    HandSample held = v.back();
    held.t_s = t_s;
    return held;
  }
  if (cursor >= v.size() || v[cursor].t_s > t_s) cursor = 0;  // moved backwards: start over
  while (cursor + 1 < v.size() && v[cursor + 1].t_s <= t_s) ++cursor;
  return Interpolate(v[cursor], v[cursor + 1], t_s);
}

namespace {

// The first sample's time, after Resample's checks of the trajectory and the step, in its order.
double FirstTime(const Trajectory& trajectory, double step_s) {
  if (!(step_s > 0.0) || !std::isfinite(step_s))
    throw std::invalid_argument("Resample: the step must be a finite time greater than zero");
  if (trajectory.samples.size() < 2)
    throw std::invalid_argument("Resample: a trajectory needs at least two samples");
  return trajectory.samples.front().t_s;
}

}  // namespace

TickSource::TickSource(double t_first_s, double t_last_s, double step_s)
    : step_s_(step_s), t0_(t_first_s), t_last_s_(t_last_s) {
  if (!(step_s > 0.0) || !std::isfinite(step_s))
    throw std::invalid_argument("Resample: the step must be a finite time greater than zero");
  const double duration = t_last_s - t0_;
  // 1e-9 of a step: a recorder's time stamps are rounded; a last sample meant to be on the grid
  // must not be lost to that rounding.
  count_ = static_cast<std::size_t>(std::floor(duration / step_s + 1e-9)) + 1;
}

TickStream::TickStream(const Trajectory& trajectory, double step_s)
    : TickSource(FirstTime(trajectory, step_s), trajectory.samples.back().t_s, step_s),
      trajectory_(trajectory) {}

HandSample TickStream::Tick(std::size_t k) {
  // t0 + k T rather than an accumulated sum: no drift over long recordings.
  HandSample sample = PoseAt(trajectory_, SampleTimeOf(k), cursor_);
  sample.t_s = TimeOf(k);
  return sample;
}

SampleTicks::SampleTicks(SampleSource& samples, double t_first_s, double t_last_s, double step_s)
    : TickSource(t_first_s, t_last_s, step_s), samples_(samples) {
  if (!(t_last_s > t_first_s))
    throw std::invalid_argument("Resample: a trajectory needs at least two samples");
}

void SampleTicks::Advance() {
  a_ = b_;
  if (!samples_.Next(b_)) throw std::runtime_error("SampleTicks: the samples ended early");
}

HandSample SampleTicks::Tick(std::size_t k) {
  // PoseAt's cases on the two samples around t instead of the whole vector: the same samples
  // reach the same arithmetic, so the ticks are the same bits.
  if (!started_) {
    if (!samples_.Next(a_) || !samples_.Next(b_))
      throw std::runtime_error("SampleTicks: fewer than two samples");
    if (a_.t_s != TimeOf(0)) throw std::runtime_error("SampleTicks: the first sample moved");
    started_ = true;
  }
  const double t = SampleTimeOf(k);
  HandSample sample;
  if (ended_) {
    sample = b_;
  } else if (t >= t_last_s()) {
    // The end, held at the last sample (PoseAt's second case): read to it.
    HandSample next;
    while (samples_.Next(next)) a_ = b_, b_ = next;
    if (b_.t_s != t_last_s()) throw std::runtime_error("SampleTicks: the last sample moved");
    ended_ = true;
    sample = b_;
  } else {
    // PoseAt's first case (t at the first sample) is Interpolate's exact return of a_.
    while (b_.t_s <= t) Advance();
    sample = Interpolate(a_, b_, t);
  }
  sample.t_s = TimeOf(k);
  return sample;
}

std::vector<HandSample> Resample(const Trajectory& trajectory, double step_s) {
  TickStream ticks(trajectory, step_s);
  std::vector<HandSample> out;
  out.reserve(ticks.count());
  for (std::size_t k = 0; k < ticks.count(); ++k) out.push_back(ticks.Tick(k));
  return out;
}

}  // namespace tubeplan::trajectories
