#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <random>
#include <set>
#include <thread>
#include <utility>

#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/scene/geometry.hpp>
#include <tubeplan/trajectories/perturb.hpp>
#include <tubeplan/trajectories/synthesize.hpp>

namespace tubeplan::graph {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// A motion that has not ended after this long is cut (a safety bound; motions last seconds).
constexpr int kMaxTicksPerMotion = 30000;
// Probe moves are short and quick, as the random motions' fastest (a flick of the hand): the
// probes are most of the exploration's ticks.
constexpr double kProbeSpeed_m_per_s = 0.15;
constexpr double kProbeTurn_rad_per_s = 2.0;
// A replayed trajectory moves the hand along chords of this many ticks (20 ms: within 0.05 mm of
// the quickest minimum-jerk reach at 80 mm/s sped up 1.25 times, and about 0.03 mm of its tremor;
// at a sharp turn of the explorer's own motion a chord cuts the corner by up to about 1 mm).
constexpr int kReplayTicksPerMove = 20;
// A motion's run keeps a checkpoint every this many ticks (a core snapshot is ~70 kB, copied in
// about the time of a tick or two): a refinement or a probe starts from the one before its tick
// and replays at most this many ticks, not the whole motion up to it.
constexpr int kCheckpointTicks = 64;

using core::KeyOf;
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
// it (the motion this one's Prefix was cut from): the run goes on from there. `may_enter` says
// whether a stay (CF, refined, tick) could become the place its CF's probe starts from: those
// keep a run point.
using MayEnter = std::function<bool(const std::string&, bool, int)>;
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

// --- geometry of the scene for aiming
// -------------------------------------------------------------

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
};

Box PartsBox(const scene::Scene& scene, const std::vector<std::uint32_t>& parts) {
  Box box;
  for (std::uint32_t p : parts) {
    const scene::Part& part = scene.parts[p];
    const Eigen::AlignedBox3d bounds_P = scene::BoundsInPart(part);
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c_P = bounds_P.corner(Eigen::AlignedBox3d::CornerType(corner));
      box.lo = box.lo.cwiseMin(part.X_WP * c_P);
      box.hi = box.hi.cwiseMax(part.X_WP * c_P);
    }
  }
  return box;
}

bool InsideAnyPart(const scene::Scene& scene, const Eigen::Vector3d& p_W) {
  for (const scene::Part& part : scene.parts)
    if (scene::Contains(part, p_W)) return true;
  return false;
}

Eigen::Quaterniond TurnAxis(const Eigen::Quaterniond& q0, const Eigen::Vector3d& from,
                            const Eigen::Vector3d& to) {
  return (Eigen::Quaterniond::FromTwoVectors(from, to) * q0).normalized();
}

struct Frame {  // directions of the start pose
  Eigen::Vector3d p0, axis, up, lateral;
  Eigen::Quaterniond q0;
};

Frame StartFrame(const scene::Scene& scene) {
  Frame f;
  const Eigen::Isometry3d X0 = MotionStart(scene);
  f.p0 = X0.translation();
  f.q0 = Eigen::Quaterniond(X0.linear());
  f.axis = X0.linear().col(2);
  // Scenes have world z up (docs/scene-format.md): "down" is where the groove's floor is.
  f.up = Eigen::Vector3d::UnitZ();
  f.lateral = f.up.cross(f.axis);
  if (f.lateral.norm() < 1e-6) f.lateral = X0.linear().col(0);
  f.lateral.normalize();
  return f;
}

Eigen::Vector3d ClampToWorkspace(const scene::Scene& scene, const Eigen::Vector3d& p) {
  if (!scene.workspace) return p;
  return p.cwiseMax(scene.workspace->min_W_m).cwiseMin(scene.workspace->max_W_m);
}

bool InWorkspace(const scene::Scene& scene, const Eigen::Vector3d& p) {
  return !scene.workspace || ((p.array() >= scene.workspace->min_W_m.array()).all() &&
                              (p.array() <= scene.workspace->max_W_m.array()).all());
}

Move MoveTo(const Eigen::Vector3d& p, const Eigen::Quaterniond& q, double speed, double guard_N,
            const Eigen::Vector3d& from) {
  Move m;
  m.p_W_m = p;
  m.q_W = q;
  m.speed_m_per_s = speed;
  m.turn_rad_per_s = 1.0;  // about 60 deg/s, a calm wrist
  const Eigen::Vector3d d = p - from;
  if (guard_N > 0.0 && d.norm() > 1e-9) {
    m.guard_dir_W = -d.normalized();  // the force that pushes back against the move
    m.guard_N = guard_N;
  }
  return m;
}

// A move by `d` from wherever the hand is (where a guard stopped the move before), kept in the
// workspace, guarded against the force that pushes back along d.
Move MoveBy(const scene::Scene& scene, const Eigen::Vector3d& d, const Eigen::Quaterniond& q,
            double speed, double guard_N) {
  Move m = MoveTo(d, q, speed, guard_N, Eigen::Vector3d::Zero());
  m.relative = true;
  if (scene.workspace)
    m.within_W = Eigen::AlignedBox3d(scene.workspace->min_W_m, scene.workspace->max_W_m);
  return m;
}

std::vector<Motion> Sweeps(const scene::Scene& scene, const Box& box, const ExploreOptions& o) {
  const Frame f = StartFrame(scene);
  const double r = scene.tube.outer_radius_m;
  // Lateral offsets across the parts, a tube radius apart; the tube level and tipped down.
  const double half = 0.5 * std::abs((box.hi - box.lo).dot(f.lateral.cwiseAbs()));
  const Eigen::Vector3d centre = 0.5 * (box.lo + box.hi);
  const double centre_lateral = (centre - f.p0).dot(f.lateral);
  const int n = std::max(1, static_cast<int>(std::floor(half / r)));
  std::vector<Motion> motions;
  for (double tilt_deg : {0.0, 12.0}) {
    const Eigen::Vector3d tipped =
        Eigen::AngleAxisd(tilt_deg * kDeg, f.axis.cross(-f.up).normalized()) * f.axis;
    const Eigen::Quaterniond q = TurnAxis(f.q0, f.axis, tipped);
    for (int i = -n; i <= n; ++i) {
      Motion m;
      m.kind = "sweep";
      Eigen::Vector3d p = ClampToWorkspace(scene, f.p0 + (centre_lateral + i * r) * f.lateral);
      m.moves.push_back(MoveTo(p, q, o.speed_m_per_s, o.push_N, f.p0));
      // Down until it pushes back (or to the bottom of the parts).
      Eigen::Vector3d down = p;
      down.z() = std::min(p.z(), box.lo.z());
      down = ClampToWorkspace(scene, down);
      m.moves.push_back(MoveTo(down, q, 0.5 * o.speed_m_per_s, o.push_N, p));
      // Sideways both ways, then along the tube's axis: contact moves, at half speed, each from
      // where the last one stopped (the friction of the pressed tube stays below its guard).
      const double slide = 2.0 * r;
      for (const Eigen::Vector3d& d :
           {Eigen::Vector3d(slide * f.lateral), Eigen::Vector3d(-2.0 * slide * f.lateral),
            Eigen::Vector3d(2.5 * r * f.axis)})
        m.moves.push_back(MoveBy(scene, d, q, 0.5 * o.speed_m_per_s, 1.5 * o.push_N));
      m.moves.push_back(MoveBy(scene, 5.0 * r * f.up, f.q0, o.speed_m_per_s, 0.0));
      motions.push_back(std::move(m));
    }
  }
  return motions;
}

// Whether the tube, straight and held at X, touches nothing: a tick of the core with the hand
// there from a reset there.
bool FreePose(core::Core& core, const Eigen::Isometry3d& X) {
  core.Reset(X);
  const core::StepOutput& out = core.Step(0.0, X);
  return out.contact_count == 0 && (out.flags & core::kPenetration) == 0;
}

// A point of element e (an index into the core's elements) and its outward normal; a round
// element's where it faces the start.
scene::ElementPoint PointFacingStart(const scene::Scene& scene, const core::Core& probe, int e,
                                     const Frame& f) {
  const auto& elements = probe.elements();
  const std::size_t part_index = elements[std::size_t(e)].part_index;
  // The element's index within its part: elements come in part order.
  int first = e;
  while (first > 0 && elements[std::size_t(first - 1)].part_index == part_index) --first;
  const scene::Part& part = scene.parts[part_index];
  return scene::PointOnElement(part, e - first,
                               f.p0 - part.X_WP * scene::BoundsInPart(part).center());
}

// From the start to over p at a safe height, turned to q; returns where the hand is then.
Eigen::Vector3d GoOver(const Frame& f, const Eigen::Vector3d& p, const Eigen::Quaterniond& q,
                       const ExploreOptions& o, Motion& m) {
  Eigen::Vector3d above = p;
  above.z() = std::max(f.p0.z(), p.z());
  Eigen::Vector3d lift = f.p0;
  lift.z() = above.z();
  m.moves.push_back(MoveTo(lift, f.q0, o.speed_m_per_s, 0.0, f.p0));
  m.moves.push_back(MoveTo(above, q, o.speed_m_per_s, o.push_N, lift));
  return above;
}

// The force that ends an aim's approach: a touch that bends a soft tube by less than the
// scene's bend threshold.
constexpr double kTouchGuard_N = 0.02;

std::vector<Motion> Aims(const scene::Scene& scene, core::Core& probe,
                         const std::vector<int>& elements, const ExploreOptions& o) {
  const Frame f = StartFrame(scene);
  const double l = scene.tube.length_m, r = scene.tube.outer_radius_m;
  const double gap = scene.contact.threshold_m + 3e-3;  // start clear of epsilon
  std::vector<Motion> motions;
  for (int e : elements) {
    const scene::PartElement& element = probe.elements()[std::size_t(e)];
    const scene::ElementPoint at = PointFacingStart(scene, probe, e, f);
    const Eigen::Vector3d& c_W = at.p_W;
    const Eigen::Vector3d& n_W = at.n_W;
    // An element whose outside is inside another part (a wall's bottom on the floor) cannot be
    // touched: not aimed at.
    if (InsideAnyPart(scene, c_W + 0.5 * scene.contact.threshold_m * n_W)) continue;
    // A direction along the element, leaning down and along the start axis where it can.
    Eigen::Vector3d t = f.axis - f.up;
    t -= t.dot(n_W) * n_W;
    if (t.norm() < 1e-6) t = n_W.cross(f.lateral);
    t.normalize();
    struct Approach {
      Eigen::Vector3d axis, hand, push, slide;
      bool along_axis = false;  // the last stretch of the approach along the tube's axis
    };
    std::vector<Approach> tip_aims, side_aims;
    // The tip, its axis leaning off the normal; where no leaning pose is free on an element of
    // the goal (the floor of a hole to insert into), straight along the normal, end first,
    // coming in along its axis.
    const bool in_goal = std::any_of(
        scene.goal.contacts.begin(), scene.goal.contacts.end(),
        [&](const states::PrincipalContact& pc) { return pc.part_element == element.name; });
    for (double phi_deg : {30.0, 60.0, 80.0, 0.0}) {
      if (phi_deg == 0.0 && !in_goal) continue;
      const Eigen::Vector3d a = -n_W * std::cos(phi_deg * kDeg) + t * std::sin(phi_deg * kDeg);
      const Eigen::Vector3d tip = c_W + gap * n_W + r * std::sin(phi_deg * kDeg) * n_W;
      tip_aims.push_back({a, tip - l * a, a, t, phi_deg == 0.0});
    }
    for (const Eigen::Vector3d& a : {t, n_W.cross(t).normalized()}) {  // the side, along it
      const Eigen::Vector3d mid = c_W + (gap + r) * n_W;
      side_aims.push_back({a, mid - 0.5 * l * a, -n_W, a});
    }
    for (const std::vector<Approach>* aims : {&tip_aims, &side_aims}) {
      for (const Approach& aim : *aims) {
        const Eigen::Quaterniond q = TurnAxis(f.q0, f.axis, aim.axis);
        Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
        X.linear() = q.toRotationMatrix();
        X.translation() = aim.hand;
        if (!InWorkspace(scene, aim.hand) || !FreePose(probe, X)) continue;
        Motion m;
        m.kind = "aim " + element.name;
        // Over the target at a safe height, down onto it (straight in: down to half a tube
        // length back along the axis, then along it), press, slide, back off.
        Eigen::Vector3d entry = aim.hand;
        if (aim.along_axis) {
          Eigen::Isometry3d X_entry = X;
          X_entry.translation() = aim.hand - 0.5 * l * aim.axis;
          if (InWorkspace(scene, X_entry.translation()) && FreePose(probe, X_entry))
            entry = X_entry.translation();
        }
        const Eigen::Vector3d above = GoOver(f, entry, q, o, m);
        if (entry != aim.hand)
          m.moves.push_back(MoveTo(entry, q, 0.5 * o.speed_m_per_s, o.push_N, above));
        // The descent guarded against what pushes back along it, from the entry or from above.
        m.moves.push_back(MoveTo(aim.hand, q, 0.5 * o.speed_m_per_s, o.push_N,
                                 entry != aim.hand ? entry : above));
        // Onto the surface, stopped by the first light push (the element touched, the tube not
        // yet bent by it) and held where it stopped, then pressed, slid and backed off, each
        // from where the last move stopped.
        m.moves.push_back(MoveBy(scene, gap * aim.push, q, 0.1 * o.speed_m_per_s, kTouchGuard_N));
        m.moves.push_back(MoveBy(scene, Eigen::Vector3d::Zero(), q, o.speed_m_per_s, 0.0));
        m.moves.back().min_ticks = 100;
        m.moves.push_back(MoveBy(scene, 3e-3 * aim.push, q, 0.5 * o.speed_m_per_s, o.push_N));
        m.moves.push_back(
            MoveBy(scene, 1.5 * r * aim.slide, q, 0.5 * o.speed_m_per_s, 1.5 * o.push_N));
        m.moves.push_back(MoveBy(scene, 2.5 * r * n_W, q, o.speed_m_per_s, 0.0));
        motions.push_back(std::move(m));
        break;  // one tip motion and one side motion per element
      }
    }
  }
  return motions;
}

// A goal's PCs as the aim at them together sees them: each element's point and outward normal,
// whether the tube's side is to lie on it (else its end is to meet it), the tube's axis and the
// hand's turn to it, and a point the tube's middle (sides only) or its end is placed nearest.
struct GoalPose {
  struct Target {
    Eigen::Vector3d c, n;
    bool side = false;
  };
  std::vector<Target> targets;
  Eigen::Vector3d axis, base;
  Eigen::MatrixXd normals;  // 3 x targets
  Eigen::Quaterniond q;

  // The free end's centre where the side's axis is r + gap off its faces and the end face gap off
  // its own, nearest `base` (least squares where they cannot all hold: between facing faces).
  Eigen::Vector3d Tip(double r, double gap) const {
    Eigen::VectorXd rhs(Eigen::Index(targets.size()));
    for (std::size_t i = 0; i < targets.size(); ++i)
      rhs[Eigen::Index(i)] =
          targets[i].n.dot(targets[i].c - base) + (targets[i].side ? r : 0.0) + gap;
    return base +
           normals * (normals.transpose() * normals).completeOrthogonalDecomposition().solve(rhs);
  }
};

// The goal's targets and the pose's axis: into the first end contact's element, else along the
// first two sides' faces (the start's axis between facing faces), turned into every side's
// face; the base point is the targets' mean. False where there is no such axis.
bool MakeGoalPose(const scene::Scene& scene, const core::Core& probe, const Frame& f, GoalPose& g) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const states::PrincipalContact& pc : scene.goal.contacts) {
    const auto& elements = probe.elements();
    const auto it = std::find_if(elements.begin(), elements.end(),
                                 [&](const auto& e) { return e.name == pc.part_element; });
    if (it == elements.end()) return false;
    const scene::ElementPoint at =
        PointFacingStart(scene, probe, static_cast<int>(it - elements.begin()), f);
    g.targets.push_back({at.p_W, at.n_W, pc.tube == states::TubeElement::kSide});
    mean += at.p_W / double(scene.goal.contacts.size());
  }
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  for (const GoalPose::Target& t : g.targets)
    if (!t.side && a.isZero()) a = -t.n;
  if (a.isZero()) {
    for (std::size_t j = 1; j < g.targets.size() && a.norm() < 1e-3; ++j)
      a = g.targets[0].n.cross(g.targets[j].n);
    if (a.norm() < 1e-3) a = f.axis;
    if (a.dot(f.axis) < 0.0) a = -a;
  }
  for (const GoalPose::Target& t : g.targets)
    if (t.side) a -= a.dot(t.n) * t.n;
  if (a.norm() < 1e-3) return false;
  g.axis = a.normalized();
  const bool sides_only =
      std::all_of(g.targets.begin(), g.targets.end(), [](const auto& t) { return t.side; });
  g.base = mean + (sides_only ? 0.5 * scene.tube.length_m : 0.0) * g.axis;
  g.normals.resize(3, Eigen::Index(g.targets.size()));
  for (std::size_t i = 0; i < g.targets.size(); ++i)
    g.normals.col(Eigen::Index(i)) = g.targets[i].n;
  g.q = TurnAxis(f.q0, f.axis, g.axis);
  return true;
}

// The hand's pose that puts the straight tube's free end at `tip` along the goal's axis.
Eigen::Isometry3d HandFor(const scene::Scene& scene, const GoalPose& g,
                          const Eigen::Vector3d& tip) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = g.q.toRotationMatrix();
  X.translation() = tip - scene.tube.length_m * g.axis;
  return X;
}

// A move by d that stops where the force against it passes guard_N, then a hold of 100 ms (so
// the state there counts).
void GuardedMoveAndHold(const scene::Scene& scene, const Eigen::Vector3d& d,
                        const Eigen::Quaterniond& q, double speed, double guard_N, Motion& m) {
  m.moves.push_back(MoveBy(scene, d, q, speed, guard_N));
  m.moves.push_back(MoveBy(scene, Eigen::Vector3d::Zero(), q, speed, 0.0));
  m.moves.back().min_ticks = 100;
}

// The straight tube clear of every goal element by the same gap, brought in along the sum of
// their inward normals so that it meets them together (a tube lying in a corner, or on a floor
// with its end against a wall), held at the first light touch, pressed and backed off. None
// where that sum does not close on every element (facing faces) or no pose is clear.
std::optional<Motion> ApproachTogether(const scene::Scene& scene, core::Core& probe, const Frame& f,
                                       const GoalPose& g, const ExploreOptions& o) {
  Eigen::Vector3d push = -g.normals.rowwise().sum();
  if (push.norm() < 1e-6) return std::nullopt;
  push.normalize();
  // Each element's distance falls at this rate along push, or the approach cannot meet it.
  double slowest = 1.0;
  for (const GoalPose::Target& t : g.targets) slowest = std::min(slowest, -push.dot(t.n));
  if (slowest < 0.1) return std::nullopt;
  // A narrower gap where the wider does not fit (a tube seated in a groove's corner has 2 mm to
  // spare on the other side).
  for (const double gap : {scene.contact.threshold_m + 3e-3, scene.contact.threshold_m + 1e-3}) {
    const double travel = gap / slowest;  // until the last element is within reach
    const Eigen::Isometry3d X = HandFor(scene, g, g.Tip(scene.tube.outer_radius_m, gap));
    if (!InWorkspace(scene, X.translation()) || !FreePose(probe, X)) continue;
    Motion m;
    m.kind = "aim goal";
    const Eigen::Vector3d above = GoOver(f, X.translation() - travel * push, g.q, o, m);
    m.moves.push_back(MoveTo(X.translation(), g.q, 0.5 * o.speed_m_per_s, o.push_N, above));
    GuardedMoveAndHold(scene, travel * push, g.q, 0.1 * o.speed_m_per_s, kTouchGuard_N, m);
    m.moves.push_back(MoveBy(scene, 3e-3 * push, g.q, 0.5 * o.speed_m_per_s, o.push_N));
    m.moves.push_back(
        MoveBy(scene, -2.5 * scene.tube.outer_radius_m * push, g.q, o.speed_m_per_s, 0.0));
    return m;
  }
  return std::nullopt;
}

// For facing faces (a slot under a bar): the tube set down on the goal face that faces up most,
// drawn back along its axis by the fewest whole radii (up to its length) that take it clear,
// slid in (guarded at the probing force), held and drawn back. None where no such pose is
// clear, or no goal face takes the tube's side.
std::optional<Motion> SlideIn(const scene::Scene& scene, core::Core& probe, const Frame& f,
                              const GoalPose& g, const ExploreOptions& o) {
  const auto set_down_on =
      std::max_element(g.targets.begin(), g.targets.end(), [&](const auto& x, const auto& y) {
        return x.side < y.side || (x.side == y.side && x.n.dot(f.up) < y.n.dot(f.up));
      });
  if (!set_down_on->side) return std::nullopt;
  const Eigen::Vector3d& n_up = set_down_on->n;
  const double l = scene.tube.length_m, r = scene.tube.outer_radius_m;
  const double eps = scene.contact.threshold_m, gap = eps + 3e-3;
  const Eigen::Vector3d tip = g.Tip(r, 0.5 * eps);
  for (double back = r; back <= l; back += r) {
    const Eigen::Isometry3d X = HandFor(scene, g, tip - back * g.axis + gap * n_up);
    if (!InWorkspace(scene, X.translation()) || !FreePose(probe, X)) continue;
    Motion m;
    m.kind = "aim goal";
    const Eigen::Vector3d above = GoOver(f, X.translation(), g.q, o, m);
    m.moves.push_back(MoveTo(X.translation(), g.q, 0.5 * o.speed_m_per_s, o.push_N, above));
    GuardedMoveAndHold(scene, -gap * n_up, g.q, 0.1 * o.speed_m_per_s, kTouchGuard_N, m);
    GuardedMoveAndHold(scene, back * g.axis, g.q, 0.25 * o.speed_m_per_s, o.push_N, m);
    m.moves.push_back(MoveBy(scene, -back * g.axis, g.q, 0.5 * o.speed_m_per_s, 0.0));
    m.moves.push_back(MoveBy(scene, 2.5 * r * n_up, g.q, o.speed_m_per_s, 0.0));
    return m;
  }
  return std::nullopt;
}

// The aim at a goal of two or more PCs as a whole: brought in along the goal faces' normals, else
// slid in along the tube's axis.
std::vector<Motion> GoalAims(const scene::Scene& scene, core::Core& probe,
                             const ExploreOptions& o) {
  if (scene.goal.contacts.size() < 2) return {};
  const Frame f = StartFrame(scene);
  GoalPose g;
  if (!MakeGoalPose(scene, probe, f, g)) return {};
  std::optional<Motion> m = ApproachTogether(scene, probe, f, g, o);
  if (!m) m = SlideIn(scene, probe, f, g, o);
  if (!m) return {};
  return {std::move(*m)};
}

// Runs motions [first, first + count) of `motions` on `jobs` threads, one core pair each; motion
// first + i goes on from resumes[i] where there is one. With `waiting`, the calling thread runs no
// motion: it calls waiting(motions done, motions started) about every `interval_s` until all
// have ended. A motion the deadline stopped, or that it kept from starting, is timed_out.
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

// The neighbour probes of a node (docs/contact-states.md: one small motion of the held end takes
// a CF to its neighbour): from the hand pose of its witness, the hand moves by `step` along and
// against each of the start frame's three directions, tips the tube down and up and turns it
// left and right by `turn` about the hand; after each it holds still for longer than the dwell
// (so the state there counts), goes back and holds again. Unguarded: the step bounds the force
// (the coupling spring's stiffness times the step).
std::vector<Move> Probes(const scene::Scene& scene, const Eigen::Isometry3d& X_W_hand,
                         const ExploreOptions& o) {
  const Frame f = StartFrame(scene);
  const int hold = 5 + static_cast<int>(std::lround(o.dwell_s / scene.model.time_step_s));
  const Eigen::Vector3d p = X_W_hand.translation();
  const Eigen::Quaterniond q(X_W_hand.linear());
  const Eigen::Vector3d tip_axis = f.axis.cross(-f.up).normalized();
  std::vector<std::pair<Eigen::Vector3d, Eigen::Quaterniond>> targets;
  for (const Eigen::Vector3d& d : {f.lateral, f.axis, f.up})
    for (double sign : {1.0, -1.0})
      targets.push_back({ClampToWorkspace(scene, p + sign * o.probe_step_m * d), q});
  for (const Eigen::Vector3d& axis : {tip_axis, f.up})
    for (double sign : {1.0, -1.0})
      targets.push_back(
          {p, (Eigen::Quaterniond(Eigen::AngleAxisd(sign * o.probe_turn_rad, axis)) * q)
                  .normalized()});
  std::vector<Move> moves;
  auto go = [&](const Eigen::Vector3d& to_p, const Eigen::Quaterniond& to_q, double limit_N) {
    Move move = MoveTo(to_p, to_q, kProbeSpeed_m_per_s, 0.0, to_p);
    move.turn_rad_per_s = kProbeTurn_rad_per_s;
    move.force_limit_N = limit_N;
    moves.push_back(move);
    move.min_ticks = hold;  // the same pose again: held still
    moves.push_back(move);
  };
  // Out, stopped where the operator force passes the explorer's limit, and back.
  const double limit_N = ExploreForceLimit(scene, o);
  for (const auto& [to_p, to_q] : targets) {
    go(to_p, to_q, limit_N);
    go(p, q, 0.0);
  }
  return moves;
}

class Merger {
 public:
  // `witness_limit_N`: a stay with a larger operator force is a witness only where the node has
  // no stay within it.
  Merger(ContactGraph& graph, double witness_limit_N)
      : graph_(graph), witness_limit_N_(witness_limit_N) {}

  // Returns whether the result added a node or an arc.
  bool Add(const MotionResult& r) {
    const std::size_t nodes = graph_.nodes.size(), arcs = graph_.arcs.size();
    for (std::size_t j = 0; j < r.stays.size(); ++j) {
      const Stay& s = r.stays[j];
      const int i = NodeOf(s.cf);
      Node& n = graph_.nodes[std::size_t(i)];
      if (!s.refined) n.ticks += s.length;
      // The stay of least force, with its poses: another witness to aim at (a brief bridge's
      // too: every aim is replayed and judged, and one that does not hold the state is not kept).
      if (s.sample.force_N < n.min_force_N) {
        n.min_force_N = s.sample.force_N;
        n.X_W_hand_least = s.sample.X_W_hand;
        n.X_WH_least = s.sample.X_WH;
      }
      // The witness: a stay within the force limit before any beyond it, then a settled stay
      // before a refined one, then the longest.
      Best& best = best_[std::size_t(i)];
      const bool within = s.sample.force_N <= witness_limit_N_;
      const bool better =
          best.length < 0 || (within && !best.within) ||
          (within == best.within &&
           ((best.refined && !s.refined) || (best.refined == s.refined && s.length > best.length)));
      // Probes start from the settled stay that is quickest to replay (any stay if none is).
      const int ticks = s.witness.substeps > 0 ? s.witness.tick - 1 : s.witness.tick;
      Entry& entry = entry_[std::size_t(i)];
      if (entry.ticks < 0 || (entry.refined && !s.refined) ||
          (entry.refined == s.refined && ticks < entry.ticks)) {
        entry = {ticks,
                 s.refined,
                 s.witness.motion,
                 s.sample.move,
                 s.sample.move_tick,
                 s.sample.X_W_hand,
                 s.witness.substeps == 0 ? r.stay_points[j] : nullptr};
      }
      if (better) {
        best = {s.length, s.refined, within};
        n.pcs = s.pcs;
        n.witness = s.witness;
        n.X_W_hand = s.sample.X_W_hand;
        n.X_WH = s.sample.X_WH;
        n.energy_J = s.sample.energy_J;
        n.friction_N = s.sample.friction_N;
        n.friction_limit_N = s.sample.friction_limit_N;
        n.force_N = s.sample.force_N;
      }
    }
    for (const Change& c : r.changes) {
      const int from = NodeOf(c.from), to = NodeOf(c.to);
      const auto [it, inserted] = arc_of_.try_emplace({from, to}, int(graph_.arcs.size()));
      if (inserted) {
        Arc a;
        a.from = from, a.to = to, a.simultaneous = c.simultaneous, a.witness = c.at;
        graph_.arcs.push_back(a);
      }
      Arc& a = graph_.arcs[std::size_t(it->second)];
      ++a.count;
      // Simultaneous only if it was never produced as a single change.
      a.simultaneous = a.simultaneous && c.simultaneous;
    }
    graph_.ticks += r.ticks;
    graph_.refinements += r.refinements;
    graph_.held_back += r.held_back ? 1 : 0;
    graph_.saturation.push_back({static_cast<int>(graph_.saturation.size()) + 1,
                                 static_cast<int>(graph_.nodes.size()),
                                 static_cast<int>(graph_.arcs.size())});
    return graph_.nodes.size() > nodes || graph_.arcs.size() > arcs;
  }

  // A run point of node i's probe motion at or before its prefix's end (null: replay it whole).
  // Handed over once: the merger keeps no snapshots of probed nodes.
  RunPointPtr TakeProbePoint(int i) { return std::move(entry_[std::size_t(i)].point); }
  // Whether a stay of `cf` (refined or not, at `ticks` of its motion) would become the place its
  // probe starts from, as Add chooses it, if no stay merged after now beat it; nodes [0, probed)
  // have had their probe.
  bool MayEnter(const std::string& cf, bool refined, int ticks, std::size_t probed) const {
    const auto it = node_of_.find(cf);
    if (it == node_of_.end()) return true;
    if (std::size_t(it->second) < probed) return false;
    const Entry& entry = entry_[std::size_t(it->second)];
    return entry.ticks < 0 || (entry.refined && !refined) ||
           (entry.refined == refined && ticks < entry.ticks);
  }

  // Node i's probe motion: the prefix of the motion of its quickest stay to replay, then the
  // neighbour probes from the hand pose there.
  Motion ProbeMotion(int i, const scene::Scene& scene, const ExploreOptions& o) const {
    const Entry& e = entry_[std::size_t(i)];
    Motion m;
    m.kind = "probe " + graph_.nodes[std::size_t(i)].cf;
    m.moves = Prefix(graph_.motions[std::size_t(e.motion)], e.move, e.move_tick);
    m.prefix_ticks = e.ticks;
    const std::vector<Move> probes = Probes(scene, e.X_W_hand, o);
    m.moves.insert(m.moves.end(), probes.begin(), probes.end());
    return m;
  }

 private:
  struct Best {
    long length = -1;
    bool refined = true;
    bool within = false;  // its operator force within the witness limit
  };
  struct Entry {     // where probes start from (a stay of the node)
    int ticks = -1;  // ticks of its motion up to there
    bool refined = true;
    int motion = 0, move = 0, move_tick = 0;
    Eigen::Isometry3d X_W_hand = Eigen::Isometry3d::Identity();
    RunPointPtr point;
  };
  int NodeOf(const std::string& cf) {
    const auto [it, inserted] = node_of_.try_emplace(cf, int(graph_.nodes.size()));
    if (inserted) {
      Node n;
      n.cf = cf;
      graph_.nodes.push_back(std::move(n));
      best_.push_back({});
      entry_.push_back({});
    }
    return it->second;
  }
  ContactGraph& graph_;
  double witness_limit_N_;
  std::map<std::string, int> node_of_;
  std::map<std::pair<int, int>, int> arc_of_;
  std::vector<Best> best_;
  std::vector<Entry> entry_;
};

std::set<std::string> ReachedElements(const ContactGraph& graph) {
  std::set<std::string> reached;
  for (const Node& n : graph.nodes) {
    const states::ParseResult parsed = states::ParseContactFormation(n.cf);
    if (!parsed.cf) continue;
    for (const states::PrincipalContact& pc : parsed.cf->contacts) reached.insert(pc.part_element);
  }
  return reached;
}

std::vector<Motion> RandomMotionsIn(const scene::Scene& scene, const Box& box, std::uint64_t seed,
                                    int first, int count, const ExploreOptions& o) {
  const Frame f = StartFrame(scene);
  const double l = scene.tube.length_m;
  // The hand roams across the parts (sideways), from their bottom to a quarter tube length above
  // their top, and along the tube's start axis from the start to a fifth of a tube length
  // further in: the region of the insertion task. Further along, the tube only meets the far
  // ends of the parts, which are another task's states.
  const auto range = [&](const Eigen::Vector3d& d) {
    double a = std::numeric_limits<double>::infinity(), b = -a;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c(corner & 1 ? box.hi.x() : box.lo.x(),
                              corner & 2 ? box.hi.y() : box.lo.y(),
                              corner & 4 ? box.hi.z() : box.lo.z());
      a = std::min(a, (c - f.p0).dot(d)), b = std::max(b, (c - f.p0).dot(d));
    }
    return std::pair{a, b};
  };
  const auto [lateral_lo, lateral_hi] = range(f.lateral);
  const auto [up_lo, up_hi] = range(f.up);
  const double along_lo = 0.0, along_hi = 0.2 * l;
  const double up_top = up_hi + 0.25 * l;
  const Eigen::Vector3d tip_axis = f.axis.cross(-f.up).normalized();
  std::vector<Motion> motions;
  for (int i = first; i < first + count; ++i) {
    // One generator per motion, seeded by (seed, index): motion i is the same whichever
    // motions were made before it.
    std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                           static_cast<std::uint32_t>(i)};
    std::mt19937_64 rng(sequence);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    auto uniform = [&](double a, double b) { return a + (b - a) * unit(rng); };
    Motion m;
    m.kind = "random";
    Eigen::Vector3d from = f.p0;
    Eigen::Quaterniond q = f.q0;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d p = ClampToWorkspace(
          scene, f.p0 + uniform(lateral_lo, lateral_hi) * f.lateral +
                     uniform(along_lo, along_hi) * f.axis + uniform(up_lo, up_top) * f.up);
      if (unit(rng) < 0.7) {
        const Eigen::Vector3d tipped =
            Eigen::AngleAxisd(uniform(-8.0, 8.0) * kDeg, f.up) *
            (Eigen::AngleAxisd(uniform(-5.0, 30.0) * kDeg, tip_axis) * f.axis);
        q = TurnAxis(f.q0, f.axis, tipped);
      }
      const double guard = unit(rng) < 0.6 ? uniform(1.0, 4.0) : 0.0;
      m.moves.push_back(MoveTo(p, q, uniform(0.05, 0.15), guard, from));
      from = p;
    }
    m.moves.push_back(MoveTo(from + 0.05 * f.up, q, o.speed_m_per_s, 0.0, from));
    motions.push_back(std::move(m));
  }
  return motions;
}

}  // namespace

int PcChanges(const states::ContactFormation& a, const states::ContactFormation& b) {
  std::vector<const states::PrincipalContact*> removed, added;
  int changes = 0;
  for (const states::PrincipalContact& pa : a.contacts) {
    const auto same = std::find_if(b.contacts.begin(), b.contacts.end(), [&](const auto& pb) {
      return pb.tube == pa.tube && pb.part_element == pa.part_element;
    });
    if (same == b.contacts.end()) {
      removed.push_back(&pa);
    } else if (same->marker != pa.marker) {
      ++changes;
    }
  }
  for (const states::PrincipalContact& pb : b.contacts) {
    const bool kept = std::any_of(a.contacts.begin(), a.contacts.end(), [&](const auto& pa) {
      return pb.tube == pa.tube && pb.part_element == pa.part_element;
    });
    if (!kept) added.push_back(&pb);
  }
  // Pair each removed PC with an added one that shares an element: one change between them.
  std::vector<bool> used(added.size(), false);
  for (const states::PrincipalContact* r : removed) {
    ++changes;
    for (std::size_t i = 0; i < added.size(); ++i) {
      if (!used[i] && (added[i]->tube == r->tube || added[i]->part_element == r->part_element)) {
        used[i] = true;
        break;
      }
    }
  }
  changes += static_cast<int>(std::count(used.begin(), used.end(), false));
  return changes;
}

std::vector<Motion> RandomMotions(const scene::Scene& scene, std::uint64_t seed, int first,
                                  int count, const ExploreOptions& options) {
  const core::Core probe(scene);
  return RandomMotionsIn(scene, PartsBox(scene, probe.reachable_parts()), seed, first, count,
                         options);
}

namespace {

// Marks the start and goal nodes and each node's distance to the goal.
void MarkStartAndGoal(const scene::Scene& scene, ContactGraph& graph) {
  graph.goal = graph.FindNode(states::ToString(scene.goal));
  if (graph.start >= 0) graph.nodes[std::size_t(graph.start)].start = true;
  if (graph.goal >= 0) {
    Node& goal = graph.nodes[std::size_t(graph.goal)];
    goal.goal = true;
    const double half_length = 0.5 * scene.tube.length_m;
    for (Node& n : graph.nodes) {
      n.distance_m =
          (n.X_WH.translation() - goal.X_WH.translation()).norm() +
          half_length * Eigen::AngleAxisd(goal.X_WH.linear().transpose() * n.X_WH.linear()).angle();
    }
  }
}

// MarkStartAndGoal, and the part elements reached.
void MarkStartGoalAndReach(const scene::Scene& scene, const core::Core& probe,
                           ContactGraph& graph) {
  MarkStartAndGoal(scene, graph);
  const std::set<std::string> reached = ReachedElements(graph);
  graph.reached_elements.assign(reached.begin(), reached.end());
  for (const scene::PartElement& e : probe.elements())
    if (!reached.contains(e.name)) graph.unreached_elements.push_back(e.name);
}

}  // namespace

std::vector<std::vector<Eigen::Isometry3d>> CandidateWaypoints(const scene::Scene& scene,
                                                               const ContactGraph& graph,
                                                               const ExploreOptions& options) {
  // The candidate paths of the graph as it stands, pruned as `plans` prunes it; of the explored
  // graph only (a state seen only in an evaluate report has no witness to aim at).
  ContactGraph marked;
  std::vector<int> index(graph.nodes.size(), -1);
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    if (graph.nodes[i].from_replay) continue;
    index[i] = static_cast<int>(marked.nodes.size());
    marked.nodes.push_back(graph.nodes[i]);
  }
  for (const Arc& a : graph.arcs) {
    if (a.from_replay || index[std::size_t(a.from)] < 0 || index[std::size_t(a.to)] < 0) continue;
    marked.arcs.push_back(a);
    marked.arcs.back().from = index[std::size_t(a.from)];
    marked.arcs.back().to = index[std::size_t(a.to)];
  }
  marked.start = graph.start >= 0 ? index[std::size_t(graph.start)] : -1;
  MarkStartAndGoal(scene, marked);
  if (marked.start < 0 || marked.goal < 0 || marked.goal == marked.start) return {};
  const PruneWeights weights =
      options.weights.value_or(PruneWeights{scene.heuristics.friction, scene.heuristics.energy,
                                            scene.heuristics.distance, scene.heuristics.tolerance});
  Prune(marked, weights);
  std::vector<std::vector<Eigen::Isometry3d>> waypoint_lists;
  for (const Path& path : KShortestPaths(marked, ArcCosts(marked, weights), options.replay_paths))
    for (auto& aimed : DistinctAims(scene, marked, path))
      if (std::none_of(waypoint_lists.begin(), waypoint_lists.end(),
                       [&](const auto& a) { return SamePoses(a, aimed.second); }))
        waypoint_lists.push_back(std::move(aimed.second));
  return waypoint_lists;
}

std::vector<trajectories::HandSample> GoalMotionPath(const scene::Scene& scene,
                                                     const ContactGraph& graph) {
  const int goal = graph.FindNode(states::ToString(scene.goal));
  if (goal < 0 || goal == graph.start) return {};
  const Node& node = graph.nodes[std::size_t(goal)];
  // A goal only passed through (no stay of it lasted the dwell) has no stay a plan could end in.
  if (node.ticks == 0 || node.from_replay || node.witness.motion < 0 ||
      std::size_t(node.witness.motion) >= graph.motions.size())
    return {};
  core::Core core(scene);
  return HandPath(core, graph.motions[std::size_t(node.witness.motion)], node.witness.tick);
}

std::vector<trajectories::Trajectory> CandidateTrajectories(const scene::Scene& scene,
                                                            const ContactGraph& graph,
                                                            const ExploreOptions& options) {
  trajectories::SynthesisOptions synthesis;
  synthesis.peak_speed_m_per_s = options.speed_m_per_s;
  std::vector<trajectories::Trajectory> nominals;
  for (const std::vector<Eigen::Isometry3d>& aim : CandidateWaypoints(scene, graph, options))
    nominals.push_back(trajectories::SynthesizeTrajectory(aim, synthesis));
  if (nominals.empty()) return nominals;
  // The explorer's own motion to the goal, retimed as `plans` retimes it: on the scene's step.
  const std::vector<trajectories::HandSample> path = GoalMotionPath(scene, graph);
  synthesis.rate_Hz = 1.0 / scene.model.time_step_s;
  if (path.size() >= 2) nominals.push_back(trajectories::RetimeHandPath(path, synthesis));
  return nominals;
}

std::vector<Motion> PerturbedReplays(const scene::Scene& scene,
                                     std::span<const trajectories::Trajectory> nominals,
                                     const ExploreOptions& options, std::uint64_t seed,
                                     int first_replicate, int copies) {
  trajectories::Perturbation perturbation;
  perturbation.offset_m = options.replay_offset_m;
  std::vector<Motion> motions;
  int replicate = first_replicate;
  for (const trajectories::Trajectory& nominal : nominals)
    for (int c = 0; c < copies; ++c)
      motions.push_back(MotionAlong(trajectories::Perturb(nominal, perturbation, seed, replicate++),
                                    scene.model.time_step_s, kReplayTicksPerMove,
                                    options.speed_m_per_s, "replay"));
  return motions;
}

namespace {

// Whether two trajectories have equal samples.
bool SameSamples(std::span<const trajectories::HandSample> a,
                 std::span<const trajectories::HandSample> b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& x, const auto& y) {
    return x.t_s == y.t_s && x.p_WH_m == y.p_WH_m && x.q_WH.coeffs() == y.q_WH.coeffs();
  });
}

// A closing round's motions: `closing_motions` random motions of the seed from `next_random`, then
// `replay_copies` perturbed replays from `next_replicate` of each candidate trajectory of the
// graph as it stands and of `planned`, each distinct one once. Advances both counters.
std::vector<Motion> ClosingRound(const scene::Scene& scene, const Box& box,
                                 const ContactGraph& graph,
                                 std::span<const trajectories::Trajectory> planned,
                                 const ExploreOptions& o, int& next_random, int& next_replicate) {
  std::vector<trajectories::Trajectory> nominals;
  if (o.replay_copies > 0) nominals = CandidateTrajectories(scene, graph, o);
  for (const trajectories::Trajectory& p : planned)
    if (std::none_of(nominals.begin(), nominals.end(),
                     [&](const auto& n) { return SameSamples(n.samples, p.samples); }))
      nominals.push_back(p);
  std::vector<Motion> round =
      RandomMotionsIn(scene, box, o.seed, next_random, o.closing_motions, o);
  next_random += o.closing_motions;
  std::vector<Motion> replays =
      PerturbedReplays(scene, nominals, o, o.seed, next_replicate, o.replay_copies);
  next_replicate += static_cast<int>(replays.size());
  round.insert(round.end(), std::make_move_iterator(replays.begin()),
               std::make_move_iterator(replays.end()));
  return round;
}

}  // namespace

double ExploreForceLimit(const scene::Scene& scene, const ExploreOptions& options) {
  return options.witness_force_N > 0.0 ? options.witness_force_N : 0.5 * scene.device.max_force_N;
}

ContactGraph Explore(const scene::Scene& scene, const ExploreOptions& o,
                     const std::function<void(const SaturationPoint&)>& progress) {
  const auto clock_start = Clock::now();
  Deadline deadline;
  if (o.time_limit_s > 0.0)
    deadline.at = clock_start + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(o.time_limit_s));
  ContactGraph graph;
  Merger merger(graph, ExploreForceLimit(scene, o));
  std::vector<std::unique_ptr<core::Core>> cores;
  cores.push_back(std::make_unique<core::Core>(scene));
  core::Core& probe = *cores.front();
  const Box box = PartsBox(scene, probe.reachable_parts());
  std::size_t probed = 0;  // nodes [0, probed) have had their probe motion
  // Read by the threads of a group, while the merger stands still.
  const MayEnter may_enter = [&](const std::string& cf, bool refined, int ticks) {
    return merger.MayEnter(cf, refined, ticks, probed);
  };
  std::optional<ExploreEnd> stopped;  // the budget or the time limit, whichever came first
  const auto stop = [&](ExploreEnd why) {
    if (!stopped) stopped = why;
  };
  const auto room = [&] {
    return std::max(0, o.max_motions - static_cast<int>(graph.motions.size()));
  };
  std::string phase;
  const auto status = [&](int done, int started) {
    if (!o.status) return;
    o.status({phase, done, started, static_cast<int>(graph.nodes.size()),
              static_cast<int>(graph.arcs.size()),
              std::chrono::duration<double>(Clock::now() - clock_start).count()});
  };
  // Runs a group of motions whole, or as much of it as the budget leaves, and merges the results
  // in motion order up to the first the time limit stopped (that one and those after it are
  // dropped, and so is the rest of the exploration). Returns how many were merged.
  const auto run = [&](std::vector<Motion> group, const std::vector<RunPointPtr>& resumes) {
    if (stopped == ExploreEnd::kTimeLimit) return 0;
    if (static_cast<int>(group.size()) > room()) {
      group.resize(std::size_t(room()));
      stop(ExploreEnd::kBudget);
    }
    const int first = static_cast<int>(graph.motions.size());
    const int count = static_cast<int>(group.size());
    if (count == 0) return 0;
    for (Motion& m : group) graph.motions.push_back(std::move(m));
    const std::function<void(int, int)> waiting =
        o.status ? std::function<void(int, int)>(
                       [&](int done, int started) { status(first + done, first + started); })
                 : nullptr;
    const std::vector<MotionResult> results =
        RunAll(scene, graph.motions, first, count, resumes, may_enter, o, cores, deadline, waiting);
    int merged = 0;
    for (const MotionResult& r : results) {
      if (r.timed_out) break;
      merger.Add(r);
      ++merged;
      if (progress) progress(graph.saturation.back());
    }
    if (merged < count) {
      graph.motions.resize(std::size_t(first + merged));
      stop(ExploreEnd::kTimeLimit);
    }
    status(first + merged, first + merged);
    return merged;
  };

  // Sweeps and aims run whole unless a limit cuts them, merged in order.
  phase = "sweeps";
  run(Sweeps(scene, box, o), {});
  graph.start = graph.nodes.empty() ? -1 : 0;  // the first stay of the first motion: the start
  if (!stopped) {
    // Aim at the goal's contacts together first, then at the goal's elements, then at those no PC
    // has touched yet.
    const std::set<std::string> reached = ReachedElements(graph);
    std::set<std::string> in_goal;
    for (const states::PrincipalContact& pc : scene.goal.contacts) in_goal.insert(pc.part_element);
    std::vector<int> unseen;
    for (std::size_t e = 0; e < probe.elements().size(); ++e)
      if (in_goal.contains(probe.elements()[e].name)) unseen.push_back(static_cast<int>(e));
    for (std::size_t e = 0; e < probe.elements().size(); ++e)
      if (!reached.contains(probe.elements()[e].name) &&
          !in_goal.contains(probe.elements()[e].name))
        unseen.push_back(static_cast<int>(e));
    phase = "aims";
    std::vector<Motion> aims = GoalAims(scene, probe, o);
    for (Motion& m : Aims(scene, probe, unseen, o)) aims.push_back(std::move(m));
    run(std::move(aims), {});
  }
  // Random motions from the seed, all merged (they reach pressed, tipped and wedged states the
  // sweeps and aims do not).
  if (!stopped && o.random_motions > 0) {
    phase = "random motions";
    run(RandomMotionsIn(scene, box, o.seed, 0, o.random_motions, o), {});
  }
  // Neighbour probing in rounds, each probing the nodes found since the last, until a round finds
  // no new node. Every node has then been probed, and probing one again from the same stay
  // replays the same motion (the core is deterministic), which finds nothing new.
  const auto probe_new_nodes = [&] {
    phase = "probes";
    while (!stopped && probed < graph.nodes.size()) {
      const int wanted = static_cast<int>(graph.nodes.size() - probed);
      const int count = std::min(wanted, room());
      if (count < wanted) stop(ExploreEnd::kBudget);
      if (count <= 0) break;
      // Each goes on from the run point kept at its start stay, if there is one: the same bits
      // as replaying its prefix.
      std::vector<Motion> group;
      std::vector<RunPointPtr> resumes;
      for (int i = 0; i < count; ++i) {
        group.push_back(merger.ProbeMotion(static_cast<int>(probed) + i, scene, o));
        resumes.push_back(merger.TakeProbePoint(static_cast<int>(probed) + i));
      }
      probed += std::size_t(count);
      const int merged = run(std::move(group), resumes);
      probed -= std::size_t(count - merged);
    }
  };
  probe_new_nodes();
  // Closing rounds: more random motions of the same seed and perturbed replays of the candidate
  // plans, those of the graph as the round starts and those `plans` makes (of the graph as it is
  // here, before the first round: the one `plans` explores), each round merged and its new nodes
  // probed, until a round adds no node and no arc (saturated), or a limit ends it.
  const std::vector<trajectories::Trajectory> planned =
      o.replay_copies > 0 && !stopped ? CandidateTrajectories(scene, graph, o)
                                      : std::vector<trajectories::Trajectory>{};
  int next_random = o.random_motions, next_replicate = 0;
  while (!stopped && (o.closing_motions > 0 || o.replay_copies > 0)) {
    const std::size_t nodes_before = graph.nodes.size(), arcs_before = graph.arcs.size();
    phase = "closing rounds";
    std::vector<Motion> round =
        ClosingRound(scene, box, graph, planned, o, next_random, next_replicate);
    // Nothing to run (no random motions, and no plan before the goal is reached): no round.
    if (round.empty()) break;
    run(std::move(round), {});
    ++graph.closing_rounds;
    probe_new_nodes();
    if (graph.nodes.size() == nodes_before && graph.arcs.size() == arcs_before) break;
  }
  graph.probed = static_cast<int>(probed);
  graph.end = stopped.value_or(ExploreEnd::kSaturated);
  graph.saturated = !stopped && probed == graph.nodes.size();

  MarkStartGoalAndReach(scene, probe, graph);
  graph.seconds = std::chrono::duration<double>(Clock::now() - clock_start).count();
  return graph;
}

}  // namespace tubeplan::graph
