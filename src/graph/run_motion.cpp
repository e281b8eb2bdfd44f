#include "graph/run_motion.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>
#include <utility>

namespace tubeplan::graph::explorer {
namespace {

// A motion that has not ended after this long is cut (a safety bound; motions last seconds).
constexpr int kMaxTicksPerMotion = 30000;
// A motion's run keeps a checkpoint every this many ticks (a core snapshot is ~70 kB, copied in
// about the time of a tick or two): a refinement or a probe starts from the one before its tick
// and replays at most this many ticks, not the whole motion up to it.
constexpr int kCheckpointTicks = 64;

using core::KeyOf;

Sample SampleOf(const core::StepOutput& out) {
  Sample s;
  s.X_W_hand = out.X_W_hand;
  s.X_WH = out.X_WH;
  s.energy_J = out.energy_J;
  s.force_N = out.force_W_N.norm();
  for (const core::ContactState& c : out.Contacts()) {
    s.friction_N += c.friction_W_N.norm();
    s.friction_limit_N += c.friction_limit_N;
  }
  return s;
}

// Sub-steps tick `tick` of the motion and returns the CFs the sub-ticks went through, in order,
// starting with `from` (the state before the tick), with the sub-tick each was entered at.
std::vector<std::pair<RawRun, Sample>> Refine(core::Core& refine_core, const Motion& motion,
                                              int tick, const RawRun& from, int substeps,
                                              const Checkpoint* checkpoint, long& ticks) {
  std::vector<std::pair<RawRun, Sample>> chain = {{from, Sample{}}};
  ReplaySubsteps(
      refine_core, motion, tick, substeps,
      [&](int j, const core::StepOutput& out) {
        ++ticks;
        states::ContactFormation c = refine_core.Formation();
        if (c == chain.back().first.cf) return true;
        RawRun run;
        run.text = states::ToString(c);
        run.cf = std::move(c);
        run.start = run.end = j;
        chain.push_back({std::move(run), SampleOf(out)});
        return true;
      },
      checkpoint);
  ticks += tick - 1 - (checkpoint != nullptr ? checkpoint->tick : 0);
  return chain;
}

// Runs one motion and records its debounced CFs and transitions: a CF counts once the core has
// kept it for `dwell` (as the plan judge counts states), so a state the core flickers through
// for a tick or two is not a node. A transition between counted states that changes more than
// one PC is bridged by a brief state in between when one is a single change from both, else
// refined by sub-stepping the tick where it happened, else flagged simultaneous.
// `resume`, if given, is a point of a run of a motion whose moves are the same as this one's up to
// it (the motion this one's Prefix was cut from): the run goes on from there; stays that
// `may_enter` accepts keep a run point.
// Kept whole: its steps share the debouncing state (stable, raw, brief) and the run points.
MotionResult RunMotion(core::Core& core, core::Core& refine_core, const Motion& motion, int index,
                       const ExploreOptions& options, const RunPointPtr& resume,
                       const MayEnter& may_enter, const Deadline& deadline) {
  MotionResult result;
  const double step_s = core.scene().model.time_step_s;
  const int dwell = std::max(1, static_cast<int>(std::lround(options.dwell_s / step_s)));
  const Eigen::Isometry3d X_start = MotionStart(core.scene());
  const double force_limit_N = ExploreForceLimit(core.scene(), options);
  const bool probe = motion.kind.starts_with("probe");
  MotionRunner runner(motion, X_start, step_s);
  // Ticks up to here replay another motion to a witness: nothing new there, nothing recorded.
  const int prefix = motion.prefix_ticks;
  RawRun stable, raw;         // the counted state and the one the core is in
  std::vector<RawRun> brief;  // states since `stable` that did not last `dwell`
  CfKey key{};
  int k = 1;
  if (options.resume_runs && resume != nullptr && resume->at.tick <= prefix &&
      core.Restore(resume->at.core)) {
    runner.Resume(resume->at.runner);
    key = resume->key;
    stable = resume->stable;
    raw = resume->raw;
    brief = resume->brief;
    k = resume->at.tick + 1;
  } else {
    core.Reset(X_start);
  }
  const int base = k - 1;          // samples[i] is tick base + i's
  std::vector<Sample> samples(1);  // [0]: tick base's (unused when base is 0)
  if (base > 0) samples[0] = resume->sample;
  auto sample = [&](int tick) -> const Sample& { return samples[std::size_t(tick - base)]; };
  // Run points every kCheckpointTicks ticks (the one resumed from first), for refinements and for
  // the probes of the CFs this motion finds.
  std::vector<RunPointPtr> points;
  if (base > 0) points.push_back(resume);
  auto point_before = [&](int tick) -> RunPointPtr {
    for (auto it = points.rbegin(); it != points.rend(); ++it)
      if ((*it)->at.tick <= tick) return *it;
    return nullptr;
  };
  // The CFs a stay has been recorded for with a run point (refined or not).
  std::set<std::pair<std::string, bool>> pointed;
  auto add_stay = [&](Stay stay) {
    RunPointPtr point;
    if (stay.witness.substeps == 0 && may_enter(stay.cf, stay.refined, stay.witness.tick) &&
        pointed.insert({stay.cf, stay.refined}).second)
      point = point_before(stay.witness.tick);
    result.stays.push_back(std::move(stay));
    result.stay_points.push_back(std::move(point));
  };
  auto record_stay = [&](RawRun run) {
    if (run.end <= prefix) return;
    run.start = std::max(run.start, prefix + 1);
    const int mid = run.start + (run.end - run.start) / 2;
    add_stay({run.text, static_cast<int>(run.cf.contacts.size()), TickRef{index, mid, 0, 0},
              run.end - run.start + 1, false, sample(mid)});
  };
  auto add_change = [&](const RawRun& from, const RawRun& to, bool simultaneous, TickRef at) {
    result.changes.push_back({from.text, to.text, simultaneous, at});
  };
  auto commit = [&](const RawRun& to) {
    if (to.start <= prefix) return;
    if (PcChanges(stable.cf, to.cf) <= 1) {
      add_change(stable, to, false, {index, to.start});
      return;
    }
    for (auto it = brief.rbegin(); it != brief.rend(); ++it) {
      if (PcChanges(stable.cf, it->cf) <= 1 && PcChanges(it->cf, to.cf) <= 1) {
        add_stay({it->text, static_cast<int>(it->cf.contacts.size()),
                  TickRef{index, it->start, 0, 0}, it->end - it->start + 1, true, it->first});
        add_change(stable, *it, false, {index, it->start});
        add_change(*it, to, false, {index, to.start});
        return;
      }
    }
    if (brief.empty() && options.substeps > 1) {
      ++result.refinements;
      const RunPointPtr point = point_before(to.start - 1);
      const auto chain = Refine(refine_core, motion, to.start, stable, options.substeps,
                                point ? &point->at : nullptr, result.ticks);
      bool single = chain.back().first.cf == to.cf;
      for (std::size_t c = 1; c < chain.size(); ++c)
        single = single && PcChanges(chain[c - 1].first.cf, chain[c].first.cf) <= 1;
      if (single) {
        for (std::size_t c = 1; c < chain.size(); ++c) {
          const TickRef at{index, to.start, options.substeps, chain[c].first.start};
          if (c + 1 < chain.size()) {
            Sample s = chain[c].second;
            s.move = sample(to.start - 1).move;
            s.move_tick = sample(to.start - 1).move_tick;
            add_stay({chain[c].first.text, static_cast<int>(chain[c].first.cf.contacts.size()), at,
                      chain[c + 1].first.start - chain[c].first.start, true, s});
          }
          add_change(chain[c - 1].first, chain[c].first, false, at);
        }
        return;
      }
    }
    add_change(stable, to, true, {index, to.start});
  };

  for (; k <= kMaxTicksPerMotion && !runner.Done(); ++k) {
    // The clock is read every kCheckpointTicks ticks: a motion stops within that many ticks.
    if (k % kCheckpointTicks == 0 && deadline.Passed()) {
      result.timed_out = true;
      return result;
    }
    const core::StepOutput& out = core.Step(k * step_s, runner.Next(core.last()));
    if ((out.flags & core::kProxySeparated) || (!probe && out.force_W_N.norm() > force_limit_N)) {
      // The operator force passed the explorer's limit (a probe's step stops there and goes
      // back), or the coupling is stretched beyond the device's force and the tube no longer
      // follows the hand: the motion ends (the tick is not recorded).
      result.held_back = true;
      ++k;
      break;
    }
    samples.push_back(SampleOf(out));
    samples.back().move = runner.move();
    samples.back().move_tick = runner.move_tick();
    const CfKey now = KeyOf(out);
    if (k == 1 || now != key) {
      key = now;
      RawRun next;
      next.cf = core.Formation();
      next.text = states::ToString(next.cf);
      next.start = next.end = k;
      next.first = samples.back();
      if (k == 1) {
        stable = raw = next;
        continue;
      }
      if (raw.end - raw.start + 1 >= dwell || raw.start == 1) {
        record_stay(raw);  // (the first run is the start state, however brief)
      } else if (raw.text != stable.text) {
        brief.push_back(raw);
      }
      raw = std::move(next);
      if (raw.text == stable.text) brief.clear();  // back where it was: the flicker is noise
    } else {
      raw.end = k;
    }
    if (raw.text != stable.text && raw.end - raw.start + 1 == dwell) {
      commit(raw);
      stable = raw;
      brief.clear();
    }
    if (options.resume_runs && k % kCheckpointTicks == 0) {
      auto point = std::make_shared<RunPoint>();
      point->at.tick = k;
      core.Save(point->at.core);
      point->at.runner = runner.position();
      point->key = key;
      point->stable = stable;
      point->raw = raw;
      point->brief = brief;
      point->sample = samples.back();
      points.push_back(std::move(point));
    }
  }
  result.ticks += k - 1 - base;
  if (raw.end - raw.start + 1 >= dwell || result.stays.empty()) record_stay(raw);
  return result;
}

}  // namespace

std::vector<MotionResult> RunAll(const scene::Scene& scene, const std::vector<Motion>& motions,
                                 int first, int count, const std::vector<RunPointPtr>& resumes,
                                 const MayEnter& may_enter, const ExploreOptions& o,
                                 std::vector<std::unique_ptr<core::Core>>& cores,
                                 const Deadline& deadline,
                                 const std::function<void(int, int)>& waiting) {
  std::vector<MotionResult> results(static_cast<std::size_t>(count));
  const int jobs = std::clamp(o.jobs, 1, std::max(1, count));
  while (static_cast<int>(cores.size()) < 2 * jobs)
    cores.push_back(std::make_unique<core::Core>(scene));
  std::atomic<int> next{0}, done{0};
  std::mutex mutex;
  std::condition_variable ended;
  int running = 0;
  auto work = [&](int worker) {
    for (int i = next++; i < count; i = next++) {
      MotionResult& r = results[std::size_t(i)];
      if (deadline.Passed()) {
        r.timed_out = true;
        continue;
      }
      r = RunMotion(*cores[std::size_t(2 * worker)], *cores[std::size_t(2 * worker + 1)],
                    motions[std::size_t(first + i)], first + i, o,
                    std::size_t(i) < resumes.size() ? resumes[std::size_t(i)] : nullptr, may_enter,
                    deadline);
      ++done;
    }
  };
  std::vector<std::thread> threads;
  if (!waiting) {
    for (int w = 1; w < jobs; ++w) threads.emplace_back(work, w);
    work(0);
  } else {
    running = jobs;
    for (int w = 0; w < jobs; ++w)
      threads.emplace_back([&, w] {
        work(w);
        const std::lock_guard lock(mutex);
        --running;
        ended.notify_one();
      });
    const auto interval = std::chrono::duration<double>(o.status_interval_s);
    std::unique_lock lock(mutex);
    while (running > 0) {
      ended.wait_for(lock, interval, [&] { return running == 0; });
      if (running > 0) waiting(done.load(), std::min(next.load(), count));
    }
  }
  for (std::thread& t : threads) t.join();
  return results;
}

}  // namespace tubeplan::graph::explorer
