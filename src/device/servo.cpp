#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <limits>
#include <pthread.h>
#include <sched.h>

#include <tubeplan/device/servo.hpp>

namespace tubeplan::device {
namespace {

std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free,
              "a signal handler may only touch lock-free atomics");

extern "C" void OnStopSignal(int signal_number) {
  g_signal.store(signal_number, std::memory_order_relaxed);
}

struct sigaction g_old_int {
}, g_old_term{};

// Response-time histogram: 1 us bins up to 20 ms; later ticks fall in the last bin (the exact
// worst is kept apart).
constexpr std::size_t kHistogramBins = 20000;

double Percentile(const std::vector<std::uint32_t>& histogram, long count, double fraction) {
  if (count <= 0) return 0.0;
  const auto rank = static_cast<long>(std::ceil(fraction * double(count)));
  long seen = 0;
  for (std::size_t i = 0; i < histogram.size(); ++i) {
    seen += histogram[i];
    if (seen >= rank) return double(i) + 1.0;  // the bin's upper edge: never an underestimate
  }
  return double(histogram.size());
}

Eigen::Isometry3d PoseOf(const trajectories::HandSample& s) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = s.q_WH.normalized().toRotationMatrix();
  X.translation() = s.p_WH_m;
  return X;
}

// Nearest multiple of 1e-9: the nearest double to that decimal, which "%.9f" prints exactly and
// from_chars reads back to the same bits.
double Nano(double v) { return std::round(v * 1e9) / 1e9; }

}  // namespace

// A high priority, leaving the top for the kernel's own threads.
int RealtimePriority() { return std::max(1, sched_get_priority_max(SCHED_FIFO) - 10); }

std::string TryRealtime() {
  sched_param param{};
  param.sched_priority = RealtimePriority();
  const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  if (e == 0) return {};
  return std::string("real-time priority (SCHED_FIFO) not permitted: ") + std::strerror(e) +
         "; the servo runs at normal priority, expect more jitter (run as root or grant "
         "CAP_SYS_NICE / an rtprio limit)";
}

const char* ToString(StopReason reason) {
  switch (reason) {
    case StopReason::kNone:
      return "running";
    case StopReason::kCompleted:
      return "completed";
    case StopReason::kStopRequested:
      return "stopped";
    case StopReason::kSignal:
      return "signal";
    case StopReason::kNonFinite:
      return "non-finite value";
    case StopReason::kMissedDeadlines:
      return "missed deadlines";
    case StopReason::kStaleData:
      return "stale device data";
    case StopReason::kDeviceError:
      return "device error";
  }
  return "unknown";
}

bool IsFault(StopReason reason) {
  return reason == StopReason::kNonFinite || reason == StopReason::kMissedDeadlines ||
         reason == StopReason::kStaleData || reason == StopReason::kDeviceError;
}

ScopedStopSignals::ScopedStopSignals() {
  g_signal.store(0);
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &g_old_int);
  sigaction(SIGTERM, &action, &g_old_term);
}

ScopedStopSignals::~ScopedStopSignals() {
  sigaction(SIGINT, &g_old_int, nullptr);
  sigaction(SIGTERM, &g_old_term, nullptr);
}

int ScopedStopSignals::received() { return g_signal.load(std::memory_order_relaxed); }
void ScopedStopSignals::Clear() { g_signal.store(0); }

trajectories::HandSample AsRecorded(double t_s, const Eigen::Isometry3d& X_W_hand) {
  trajectories::HandSample s;
  s.t_s = t_s;
  const Eigen::Vector3d& p = X_W_hand.translation();
  s.p_WH_m = Eigen::Vector3d(Nano(p.x()), Nano(p.y()), Nano(p.z()));
  const Eigen::Quaterniond q(X_W_hand.linear());
  // Kept as written (norm 1 within 1e-9); the reader normalises it, and so does PoseOf.
  s.q_WH = Eigen::Quaterniond(Nano(q.w()), Nano(q.x()), Nano(q.y()), Nano(q.z()));
  return s;
}

ServoLoop::ServoLoop(core::Core& core, HapticDevice& device, Clock& clock,
                     const SafetyLimits& limits, ServoConfig config, SpscRing<TickRecord>* ring,
                     Seqlock<ServoStatus>* status)
    : core_(core),
      device_(device),
      clock_(clock),
      limiter_(limits, core.scene().model.time_step_s),
      config_(config),
      ring_(ring),
      status_(status),
      histogram_(kHistogramBins, 0) {}

ServoStats ServoLoop::Run() {
  ServoStats stats;
  if (config_.realtime) stats.realtime_note = TryRealtime();
  const double T = core_.scene().model.time_step_s;
  const auto T_ns = static_cast<std::int64_t>(std::llround(T * 1e9));
  std::fill(histogram_.begin(), histogram_.end(), 0u);

  const std::int64_t start_ns = clock_.NowNs();
  // Tick k is due at schedule_ns + k T; a stall moves the schedule on by the time it lost.
  std::int64_t schedule_ns = start_ns;
  std::int64_t previous_wake_ns = 0, last_end_ns = start_ns;
  std::uint64_t last_sequence = 0;
  int stale_ticks = 0;
  DeviceSample sample;
  TickRecord record;
  ServoStatus status;
  StopReason reason = StopReason::kNone;
  const double nan = std::numeric_limits<double>::quiet_NaN();

  // The run times of the last stalls, oldest first overwritten (the rate of stalls).
  std::array<std::int64_t, 64> stall_ns{};
  const int stall_window = std::clamp(config_.max_stalls_per_s + 1, 1, int(stall_ns.size()));

  for (long k = 0; config_.max_ticks == 0 || k < config_.max_ticks; ++k) {
    std::int64_t deadline_ns = schedule_ns + k * T_ns;
    clock_.SleepUntilNs(deadline_ns);
    if (on_tick) on_tick(k);
    const std::int64_t wake_ns = clock_.NowNs();
    const std::int64_t latency_ns = wake_ns - deadline_ns;
    stats.max_latency_us = std::max(stats.max_latency_us, double(latency_ns) * 1e-3);
    if (k > 0)
      stats.max_jitter_us =
          std::max(stats.max_jitter_us, std::abs(double(wake_ns - previous_wake_ns - T_ns)) * 1e-3);
    previous_wake_ns = wake_ns;
    // A stall: this tick woke more than a period late. The schedule moves on by the whole
    // periods it lost (the loop does not race to catch up; the core still steps every tick, so
    // a replay of the recording steps it the same), its force is zero and ramps back in after;
    // one stall too long or too many in a second end the run.
    const bool missed = latency_ns > T_ns;
    stats.late_wakeups += missed;
    if (missed) {
      const long lost = long(latency_ns / T_ns);
      schedule_ns += lost * T_ns;
      deadline_ns = schedule_ns + k * T_ns;
      stall_ns[std::size_t(stats.stalls % stall_window)] = wake_ns;
      ++stats.stalls;
      stats.ticks_lost += lost;
      stats.longest_stall_ms = std::max(stats.longest_stall_ms, double(latency_ns) * 1e-6);
      if (stats.first_stall_s < 0.0) stats.first_stall_s = double(wake_ns - start_ns) * 1e-9;
      const std::int64_t oldest = stall_ns[std::size_t(stats.stalls % stall_window)];
      if (double(latency_ns) * 1e-9 > config_.max_stall_s ||
          (config_.max_stalls_per_s > 0 && stats.stalls >= stall_window &&
           wake_ns - oldest < 1'000'000'000))
        reason = StopReason::kMissedDeadlines;
    }

    if (ScopedStopSignals::received() != 0) reason = StopReason::kSignal;
    if (reason == StopReason::kNone && stop_requested_.load(std::memory_order_acquire))
      reason = StopReason::kStopRequested;
    if (reason == StopReason::kNone && !device_.Read(sample)) reason = StopReason::kDeviceError;
    if (reason == StopReason::kNone) {
      stale_ticks = sample.sequence == last_sequence ? stale_ticks + 1 : 0;
      last_sequence = sample.sequence;
      if (stale_ticks >= config_.max_stale_ticks) reason = StopReason::kStaleData;
    }
    const bool finite = sample.X_W_hand.matrix().allFinite() && sample.v_W_m_per_s.allFinite() &&
                        sample.w_W_rad_per_s.allFinite();
    record.tick = k;
    record.stepped = false;
    record.stalled = missed;
    record.stall_ms = missed ? float(double(latency_ns) * 1e-6) : 0.0f;
    record.buttons = sample.buttons;
    LimitedWrench wrench;
    if (reason == StopReason::kNone && !finite) {
      // Through the limiter like every wrench: a NaN request latches it at zero.
      wrench = limiter_.Command(Eigen::Vector3d::Constant(nan), Eigen::Vector3d::Zero());
      reason = StopReason::kNonFinite;
    } else if (reason == StopReason::kNone) {
      record.hand = AsRecorded(double(k) * T, sample.X_W_hand);
      const Eigen::Isometry3d X_W_hand = PoseOf(record.hand);
      if (k == 0) core_.Reset(X_W_hand);  // as a replay starts: held end at the first pose
      const core::StepOutput& out = core_.Step(record.hand.t_s, X_W_hand);
      record.out = out;
      record.stepped = true;
      // Stalls are this loop's to judge (above), not the limiter's streak.
      wrench = limiter_.Command(out.force_W_N, out.torque_W_Nm);
      if (wrench.fault == Fault::kNonFinite) reason = StopReason::kNonFinite;
      if (missed && wrench.fault == Fault::kNone) wrench = limiter_.Drop();
    } else {
      limiter_.Stop();
      wrench = limiter_.Command(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    }
    device_.Send(wrench);
    const std::int64_t end_ns = clock_.NowNs();
    last_end_ns = end_ns;
    const std::int64_t response_ns = end_ns - deadline_ns;
    stats.overruns += response_ns > T_ns;
    ++stats.ticks;
    const double response_us = double(response_ns) * 1e-3;
    stats.max_us = std::max(stats.max_us, response_us);
    histogram_[std::min<std::size_t>(
        kHistogramBins - 1,
        static_cast<std::size_t>(std::max<std::int64_t>(0, response_ns) / 1000))]++;

    record.force_sent_N = wrench.force_N;
    record.torque_sent_Nm = wrench.torque_Nm;
    record.response_ns = static_cast<std::int32_t>(
        std::min<std::int64_t>(response_ns, std::numeric_limits<std::int32_t>::max()));
    if (ring_) ring_->TryPush(record);
    if (status_) {
      status.ticks = stats.ticks;
      status.overruns = stats.overruns;
      status.t_s = double(k) * T;
      status.force_N = wrench.force_N.norm();
      status.request_N = record.stepped ? record.out.force_W_N.norm() : 0.0;
      status.worst_us = stats.max_us;
      status.rate_hz =
          end_ns > start_ns ? double(stats.ticks) / (double(end_ns - start_ns) * 1e-9) : 0.0;
      if (record.stepped) status.key = core::KeyOf(record.out);
      status.stop = reason;
      status_->Store(status);
    }
    if (reason != StopReason::kNone) break;
  }
  if (reason == StopReason::kNone) reason = StopReason::kCompleted;
  // The end of a session is a stop like any other: zero through the limiter, then disabled.
  limiter_.Stop();
  device_.Send(limiter_.Command(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()));
  device_.Disable();

  stats.stop = reason;
  stats.median_us = Percentile(histogram_, stats.ticks, 0.5);
  stats.p999_us = std::min(Percentile(histogram_, stats.ticks, 0.999), stats.max_us);
  stats.median_us = std::min(stats.median_us, stats.max_us);
  stats.rate_hz =
      last_end_ns > start_ns ? double(stats.ticks) / (double(last_end_ns - start_ns) * 1e-9) : 0.0;
  stats.dropped = ring_ ? ring_->dropped() : 0;
  if (status_) {
    status.stop = reason;
    status_->Store(status);
  }
  return stats;
}

}  // namespace tubeplan::device
