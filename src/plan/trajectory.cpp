#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tubeplan/plan/trajectory.hpp>

namespace tubeplan::plan {
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

TickStream::TickStream(const Trajectory& trajectory, double step_s)
    : trajectory_(trajectory), step_s_(step_s) {
  if (!(step_s > 0.0) || !std::isfinite(step_s))
    throw std::invalid_argument("Resample: the step must be a finite time greater than zero");
  if (trajectory.samples.size() < 2)
    throw std::invalid_argument("Resample: a trajectory needs at least two samples");
  t0_ = trajectory.samples.front().t_s;
  const double duration = trajectory.samples.back().t_s - t0_;
  // 1e-9 of a step: a recorder's time stamps are rounded; a last sample meant to be on the grid
  // must not be lost to that rounding.
  count_ = static_cast<std::size_t>(std::floor(duration / step_s + 1e-9)) + 1;
}

HandSample TickStream::Tick(std::size_t k) {
  // t0 + k T rather than an accumulated sum: no drift over long recordings.
  const double t = std::min(TimeOf(k), trajectory_.samples.back().t_s);
  HandSample sample = PoseAt(trajectory_, t, cursor_);
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

}  // namespace tubeplan::plan
