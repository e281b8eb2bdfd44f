// Invariants of the core on many states, its allocation-free tick, its determinism and its
// degenerate inputs.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <random>
#include <thread>

#include <catch2/catch.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/core/coupling.hpp>
#include <tubeplan/core/friction.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/model/tube.hpp>

#include "../alloc_count.hpp"
#include "../study/quick_case.hpp"

using namespace tubeplan;

// Every allocation of this test program is counted, per thread (tests/alloc_count.cpp).
using tubeplan::testing::g_allocations;

namespace {

std::string SourcePath(const std::string& relative) {
  return std::string(TUBEPLAN_SOURCE_DIR) + "/" + relative;
}

scene::Scene LoadScene(const std::string& relative) {
  io::SceneLoadResult loaded = io::LoadSceneFile(SourcePath(relative));
  REQUIRE(loaded.scene.has_value());
  return *loaded.scene;
}

std::vector<plan::HandSample> DemoTicks() {
  io::TrajectoryLoadResult loaded = io::LoadTrajectoryFile(SourcePath("plans/groove-insert.csv"));
  REQUIRE(loaded.trajectory.has_value());
  return plan::Resample(*loaded.trajectory, 1e-3);
}

Eigen::Isometry3d Pose(const plan::HandSample& s) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = s.q_WH.toRotationMatrix();
  X.translation() = s.p_WH_m;
  return X;
}

// FNV-1a over the bytes of every double the tick returns and of the CF's compact form.
struct Hash {
  std::uint64_t h = 1469598103934665603ull;
  void Add(const void* data, std::size_t n) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  }
  void Add(double v) { Add(&v, sizeof v); }
  void Add(const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) Add(v[i]);
  }
};

// The hash of ticks [first, ticks.size()) run on `c` as it is.
std::uint64_t HashTicks(core::Core& c, const std::vector<plan::HandSample>& ticks,
                        std::size_t first) {
  Hash hash;
  for (std::size_t k = first; k < ticks.size(); ++k) {
    const plan::HandSample& sample = ticks[k];
    const core::StepOutput& out = c.Step(sample.t_s, Pose(sample));
    hash.Add(out.force_W_N);
    hash.Add(out.torque_W_Nm);
    hash.Add(out.X_WH.translation());
    hash.Add(out.energy_J);
    hash.Add(out.max_strain);
    hash.Add(&out.flags, sizeof out.flags);
    for (const core::ContactState& pc : out.Contacts()) {
      const int code[3] = {int(pc.tube), int(pc.marker), pc.part_element};
      hash.Add(code, sizeof code);
      hash.Add(pc.force_W_N);
    }
  }
  return hash.h;
}

std::uint64_t RunDemo(const scene::Scene& s, const std::vector<plan::HandSample>& ticks) {
  core::Core c(s);
  c.Reset(Pose(ticks.front()));
  return HashTicks(c, ticks, 0);
}

}  // namespace

TEST_CASE("A tick allocates nothing, with or without the shape", "[core][alloc]") {
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const std::vector<plan::HandSample> ticks = DemoTicks();
  core::Core c(s);
  c.Reset(Pose(ticks.front()));
  std::array<Eigen::Vector3d, 21> centreline;
  // The demo passes through free motion, an end contact stuck and sliding, the side landing and
  // the tube lying in the groove, with the elastica and its linear fallback.
  const std::int64_t before = g_allocations;
  for (const plan::HandSample& sample : ticks) {
    c.Step(sample.t_s, Pose(sample));
    c.Centreline(centreline);
  }
  CHECK(g_allocations - before == 0);
  // The counter does count: the cold path (the CF as text) allocates.
  const std::int64_t cold = g_allocations;
  CHECK(!c.FormationText().empty());
  CHECK(g_allocations > cold);
}

TEST_CASE("A tick allocates nothing where the rod's shape is held sideways", "[core][alloc]") {
  // The stability sweep's push 0.1 mm off the axis: from the free end's Euler load (tick 82) to
  // the held column's own (tick 415) the rod shapes the tube, and where its dead-load shape
  // lands off the contacts it is held sideways (model::Rod::SolvePinned). Without the hold,
  // 3 of these 410 ticks are off their contacts (from tick 82): none being so, with 300 on the
  // rod, is the path run.
  const study::StabilityCase push = testing::QuickCase("push into a wall off-plane=0.1mm");
  const scene::Scene& s = push.scene;
  core::Core c(s);
  const double dt = s.model.time_step_s;
  const Eigen::Vector3d target(0.0, push.off_plane_m, 2.0 * s.contact.threshold_m + 1e-3 + 0.03);
  // The sweep's hand, to the bit (the bifurcation is decided by rounding): n steps of target/n.
  const int n = int(std::ceil(target.norm() / (push.speed_m_per_s * dt)));
  const std::int64_t before = g_allocations;
  int rod_ticks = 0, off_ticks = 0;
  double t = 0.0;
  for (int tick = 1; tick <= 410; ++tick) {
    Eigen::Isometry3d X_WH = Eigen::Isometry3d::Identity();
    X_WH.translation() = target * (double(std::min(tick, n)) / n);
    const core::StepOutput& out = c.Step(t += dt, X_WH);
    rod_ticks += (out.flags & core::kRodShape) != 0 ? 1 : 0;
    off_ticks += (out.flags & core::kShapeOffContacts) != 0 ? 1 : 0;
  }
  CHECK(g_allocations - before == 0);
  CHECK(rod_ticks > 300);
  CHECK(off_ticks == 0);
}

TEST_CASE("The same inputs give the same bits, in any thread", "[core][determinism]") {
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const std::vector<plan::HandSample> ticks = DemoTicks();
  const std::uint64_t first = RunDemo(s, ticks);
  CHECK(RunDemo(s, ticks) == first);
  std::uint64_t a = 0, b = 0;
  std::thread ta([&] { a = RunDemo(s, ticks); });
  std::thread tb([&] { b = RunDemo(s, ticks); });
  ta.join();
  tb.join();
  CHECK(a == first);
  CHECK(b == first);
}

TEST_CASE("A snapshot puts a core back where it was, bit for bit, in another core too",
          "[core][determinism]") {
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const std::vector<plan::HandSample> ticks = DemoTicks();
  // Snapshots at ticks in each kind of state the demo has: free, the elastica, the rod (the side
  // on the floor, carried by the rod's solution and tangent), and in contact with friction.
  core::Core a(s);
  a.Reset(Pose(ticks.front()));
  std::vector<std::size_t> at;
  bool free_seen = false, elastica_seen = false, rod_seen = false;
  for (std::size_t k = 0; k < ticks.size(); ++k) {
    const core::StepOutput& out = a.Step(ticks[k].t_s, Pose(ticks[k]));
    const bool rod = (out.flags & core::kRodShape) != 0;
    if (out.contact_count == 0 && !free_seen && k > 10) {
      free_seen = true;
      at.push_back(k + 1);
    } else if (out.contact_count > 0 && !rod && !elastica_seen) {
      elastica_seen = true;
      at.push_back(k + 1);
    } else if (rod && !rod_seen) {
      rod_seen = true;
      at.push_back(k + 20);  // well into the rod's stretch: its warm start is carried
    }
  }
  REQUIRE(at.size() == 3);
  for (const std::size_t first : at) {
    CAPTURE(first);
    core::Core c(s);
    c.Reset(Pose(ticks.front()));
    for (std::size_t k = 0; k < first; ++k) c.Step(ticks[k].t_s, Pose(ticks[k]));
    core::Core::Snapshot snapshot;
    CHECK(snapshot.empty());
    c.Save(snapshot);
    const core::Core::Snapshot copy = snapshot;  // a copy restores as well
    const std::uint64_t expected = HashTicks(c, ticks, first);
    // The same core, after it has run on to the end.
    REQUIRE(c.Restore(snapshot));
    CHECK(HashTicks(c, ticks, first) == expected);
    // Another core whose own state is elsewhere (it ran the whole demo, then was reset away).
    core::Core other(s);
    other.Reset(Pose(ticks.front()));
    HashTicks(other, ticks, 0);
    REQUIRE(other.Restore(copy));
    CHECK(HashTicks(other, ticks, first) == expected);
  }
  // Refused: an empty snapshot, and one from a core of another shape (another capsule count).
  core::Core c(s);
  core::Core::Snapshot empty;
  CHECK_FALSE(c.Restore(empty));
  scene::Scene coarser = s;
  coarser.model.capsules = core::kMinCapsules;
  REQUIRE(core::ChainCapsuleCount(coarser) != c.capsule_count());
  core::Core coarse(coarser);
  core::Core::Snapshot of_coarse;
  coarse.Save(of_coarse);
  CHECK_FALSE(c.Restore(of_coarse));
}

TEST_CASE("The shipped insertion replays to its golden hash", "[core][determinism]") {
  // The golden value pins the physics: any change of a force, a pose, an energy, a flag or a
  // contact formation anywhere in the 5501 ticks of plans/groove-insert.csv changes it. Values are
  // hashed at 7 significant digits so that the release and the sanitizer builds (different
  // optimisation levels, same IEEE arithmetic) agree even if one ever rounds a last bit
  // differently; the CFs, markers and flags are hashed exactly.
  // A deliberate change of the physics changes this value: run this test, take the value it
  // prints, and say in the commit message why the physics changed.
  constexpr std::uint64_t kGolden = 0x46337ebb2d1a8bb8ull;
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const std::vector<plan::HandSample> ticks = DemoTicks();
  core::Core c(s);
  c.Reset(Pose(ticks.front()));
  Hash hash;
  const auto add = [&](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6e", v == 0.0 ? 0.0 : v);  // -0 and 0 alike
    hash.Add(text, std::strlen(text));
  };
  const auto add3 = [&](const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) add(v[i]);
  };
  for (const plan::HandSample& sample : ticks) {
    const core::StepOutput& out = c.Step(sample.t_s, Pose(sample));
    add3(out.force_W_N);
    add3(out.torque_W_Nm);
    add3(out.X_WH.translation());
    add(out.energy_J);
    add(out.max_strain);
    hash.Add(&out.flags, sizeof out.flags);
    for (const core::ContactState& pc : out.Contacts()) {
      const int code[3] = {int(pc.tube), int(pc.marker), pc.part_element};
      hash.Add(code, sizeof code);
    }
  }
  char printed[32];
  std::snprintf(printed, sizeof printed, "0x%016llxull", static_cast<unsigned long long>(hash.h));
  INFO("golden hash of this run: " << printed);
  CHECK(hash.h == kGolden);
}

TEST_CASE("Leaving idle parts out changes no bit of any tick", "[core][determinism]") {
  // The core leaves out a part with no load whose pieces are provably beyond epsilon, bounds
  // each pass's motion along the part's possible normals, and solves the tick again with every
  // part where one might have closed (docs/core.md, "Idle parts"). That must be the tick it
  // would have been: a core with it off is the independent method, compared output by output,
  // exactly, at every tick. The motions: the shipped insertion on both scenes; the tube lying
  // in the groove swept sideways at 0.5 m/s into each wall; the tip pressed on the floor and the
  // hand dragged sideways at 20 mm/s, so that the stuck tip slips and the bent tube snaps
  // across within a tick towards a wall that was left out (without the check after each pass
  // this run differs from tick 1502 on); random walks of the hand in and over the groove, with
  // both multi-contact rules and both beam models.
  const auto hand = [](double x, double y, double z, double down_deg, double yaw_deg) {
    constexpr double kDeg = 3.14159265358979323846 / 180.0;
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = (Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd((-90.0 - down_deg) * kDeg, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    X.translation() = Eigen::Vector3d(x, y, z);
    return X;
  };
  std::vector<Eigen::Isometry3d> demo;
  for (const plan::HandSample& sample : DemoTicks()) demo.push_back(Pose(sample));
  std::vector<Eigen::Isometry3d> swipe(300, hand(0.0, -0.090, 0.0082, 0.0, 0.0));
  for (int k = 0, dir = 1; k < 3000; ++k) {
    Eigen::Isometry3d X = swipe.back();
    X.translation().x() += dir * 0.5e-3;
    if (std::abs(X.translation().x()) > 0.006) dir = -dir;
    swipe.push_back(X);
  }
  std::vector<Eigen::Isometry3d> drag(300, hand(0.0, -0.090, 0.0455, 15.0, 0.0));
  for (int k = 0, dir = 1; k < 6000; ++k) {
    Eigen::Isometry3d X = drag.back();
    X.translation().x() += dir * 20e-6;
    if (std::abs(X.translation().x()) > 0.02) dir = -dir;
    drag.push_back(X);
  }
  const auto walk = [&](unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> g(0.0, 1.0);
    std::vector<Eigen::Isometry3d> poses;
    Eigen::Vector3d p(0.0, -0.090, 0.012), v = Eigen::Vector3d::Zero();
    double down = 5.0, yaw = 0.0, down_rate = 0.0, yaw_rate = 0.0;
    for (int k = 0; k < 6000; ++k) {
      v = 0.995 * v + 2e-3 * Eigen::Vector3d(g(rng), g(rng), g(rng));
      down_rate = 0.99 * down_rate + 0.05 * g(rng);
      yaw_rate = 0.99 * yaw_rate + 0.05 * g(rng);
      p = (p + 1e-3 * v)
              .cwiseMax(Eigen::Vector3d(-0.008, -0.12, 0.004))
              .cwiseMin(Eigen::Vector3d(0.008, -0.05, 0.06));
      down = std::clamp(down + 1e-2 * down_rate, -10.0, 30.0);
      yaw = std::clamp(yaw + 1e-2 * yaw_rate, -5.0, 5.0);
      poses.push_back(hand(p.x(), p.y(), p.z(), down, yaw));
    }
    return poses;
  };
  struct Run {
    const char* scene;
    const std::vector<Eigen::Isometry3d>* poses;
    scene::MultiContactRule rule;
    model::BeamModel beam;
  };
  const std::vector<Eigen::Isometry3d> walk2 = walk(2), walk8 = walk(8);
  const auto kSeg = scene::MultiContactRule::kSegmented;
  const auto kCoupled = scene::MultiContactRule::kCoupled;
  const auto kElastica = model::BeamModel::kElastica;
  const auto kLinear = model::BeamModel::kLinear;
  const std::vector<Run> runs = {
      {"scenes/groove.yaml", &demo, kSeg, kElastica},
      {"scenes/groove-steel.yaml", &demo, kSeg, kElastica},
      {"scenes/groove.yaml", &swipe, kSeg, kLinear},
      {"scenes/groove.yaml", &drag, kSeg, kElastica},
      {"scenes/groove.yaml", &walk2, kSeg, kElastica},
      {"scenes/groove.yaml", &walk8, kCoupled, kElastica},
      {"scenes/groove.yaml", &walk8, kSeg, kLinear},
  };
  long left_out_ticks = 0, retries = 0;
  for (const Run& run : runs) {
    scene::Scene s = LoadScene(run.scene);
    s.model.multi_contact = run.rule;
    s.model.beam = run.beam;
    core::Core with(s), without(s);
    without.set_leave_out_idle_parts(false);
    const std::vector<Eigen::Isometry3d>& poses = *run.poses;
    with.Reset(poses.front());
    without.Reset(poses.front());
    int differing = 0;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const core::StepOutput& a = with.Step(1e-3 * double(k), poses[k]);
      const core::StepOutput& b = without.Step(1e-3 * double(k), poses[k]);
      left_out_ticks += with.idle_parts_left_out() > 0 ? 1 : 0;
      bool same = a.force_W_N == b.force_W_N && a.torque_W_Nm == b.torque_W_Nm &&
                  a.X_WH.matrix() == b.X_WH.matrix() && a.energy_J == b.energy_J &&
                  a.max_strain == b.max_strain && a.flags == b.flags &&
                  a.contact_count == b.contact_count;
      for (int c = 0; same && c < a.contact_count; ++c) {
        const core::ContactState& p = a.contacts[std::size_t(c)];
        const core::ContactState& q = b.contacts[std::size_t(c)];
        same = p.tube == q.tube && p.part_element == q.part_element && p.marker == q.marker &&
               p.force_W_N == q.force_W_N && p.p_WC_m == q.p_WC_m;
      }
      if (!same && differing++ == 0) {
        INFO(run.scene << ", " << poses.size() << " ticks: first difference at tick " << k);
        CHECK(same);
      }
    }
    CHECK(differing == 0);
    retries += with.idle_retries();
  }
  // Both paths ran: parts were left out on most ticks of the groove's runs, and ticks were
  // solved again (the swipe alone reaches a left-out wall within a tick ~100 times).
  CHECK(left_out_ticks > 5000);
  CHECK(retries > 100);
}

// A random pose of the held end over and in the groove: between the walls' tops and the floor
// (its centre at least a radius above the floor), tipped down up to 20 degrees, turned up to 1
// degree, shifted sideways 2 mm and along the groove up to 0.2 l.
Eigen::Isometry3d RandomGroovePose(const scene::Scene& s, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Isometry3d start = s.X_WH_start;
  const double l = s.tube.length_m, r1 = s.tube.outer_radius_m;
  const double top_z = start.translation().z();
  Eigen::Isometry3d X = start;
  X.translation() += Eigen::Vector3d(2e-3 * u(rng), 0.2 * l * u(rng), 0.0);
  X.translation().z() = r1 + 0.5e-3 + (top_z - r1) * 0.5 * (1.0 + u(rng));
  const double tip_down = 0.175 * (1.0 + u(rng));
  X.linear() = Eigen::AngleAxisd(0.0087 * u(rng), Eigen::Vector3d::UnitZ()) *
               Eigen::AngleAxisd(-tip_down, Eigen::Vector3d::UnitX()) * start.linear();
  return X;
}

// The hand from `from` to `to` over 200 ticks, then held for 100.
Eigen::Isometry3d RandomStatePath(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to,
                                  int k) {
  const double w = std::min(1.0, k / 200.0);
  Eigen::Isometry3d Y = to;
  Y.translation() = (1 - w) * from.translation() + w * to.translation();
  Y.linear() = Eigen::Quaterniond(from.linear())
                   .slerp(w, Eigen::Quaterniond(to.linear()))
                   .toRotationMatrix();
  return Y;
}

// How deep the deepest of `points` lies inside a part of the scene: past every face plane of its
// box by this much (negative: outside every part).
double DeepestInside(const scene::Scene& s, std::span<const Eigen::Vector3d> points) {
  double deepest = -std::numeric_limits<double>::infinity();
  for (const scene::BoxPart& part : s.parts) {
    const Eigen::Isometry3d X_PW = part.X_WP.inverse();
    for (const Eigen::Vector3d& x : points)
      deepest = std::max(deepest, (0.5 * part.size_m - (X_PW * x).cwiseAbs()).minCoeff());
  }
  return deepest;
}

TEST_CASE("The core holds the tube back instead of carrying it through a part", "[core][through]") {
  // Random states as below, on the rubber groove: some of them bend the tube so hard against
  // the floor that the tick's solution, taken, puts its axis more than r1/2 into the floor or a
  // wall. The same path with the guard off shows it; with it on, no tick does, and a held tick
  // keeps the tube, its held end and its CF, while the operator feels the coupling's spring and
  // damper stretched to the hand (docs/core.md, "Through a part").
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const core::Coupling coupling = core::ResolveCoupling(s.device, s.model.time_step_s);
  const double r1 = s.tube.outer_radius_m, T = s.model.time_step_s;
  core::Core on(s), off(s), guarded(s);
  off.set_hold_out_of_parts(false);
  std::array<Eigen::Vector3d, core::kMaxCapsules + 1> centre;
  const std::span<Eigen::Vector3d> points(centre.data(), std::size_t(on.capsule_count()) + 1);
  std::mt19937_64 rng(20261125);
  // Enough trials for at least three to go through with the guard off: 3 of the first 20 did
  // until stop 43, 2 since the end face pressed into a part became a bed of springs (one trial
  // pressed its end into the floor with more than K eps = 10 N and no longer goes through; 4 of
  // the 30 do).
  constexpr int kTrials = 30;
  int held_ticks = 0, trials_held = 0, trials_through_off = 0, switched_inside = 0;
  double deepest_on = -1.0, deepest_off = -1.0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const Eigen::Isometry3d X = RandomGroovePose(s, rng);
    on.Reset(s.X_WH_start);
    off.Reset(s.X_WH_start);
    double t = 0.0, deepest_off_trial = -1.0;
    bool held_in_trial = false, switched_in_trial = false;
    Eigen::Vector3d hand_before = s.X_WH_start.translation();
    for (int k = 1; k <= 300; ++k) {
      const Eigen::Isometry3d Y = RandomStatePath(s.X_WH_start, X, k);
      const core::StepOutput before = on.last();
      const std::string cf_before = on.FormationText();
      const core::StepOutput& out = on.Step(t += T, Y);
      off.Step(t, Y);
      // The centreline as Centreline draws it (the elastica's exact points, or the rod's nodes):
      // the guard judges the nodes the next tick's capsules stand on, which for the elastica lie
      // within its Hermite interpolation's error, far below 0.1 mm, of these.
      on.Centreline(points);
      deepest_on = std::max(deepest_on, DeepestInside(s, points));
      off.Centreline(points);
      const double inside_off = DeepestInside(s, points);
      deepest_off_trial = std::max(deepest_off_trial, inside_off);
      // The guard turned on with the tube already through: there is no state out of the part to
      // keep, and it is not held (it was, every tick after, while the guard judged only when on).
      // Tried on a copy of the unguarded core, the first time in a trial its axis is inside (by
      // more than the guard's nodes' 0.1 mm), held at this hand pose.
      if (!switched_in_trial && inside_off > 0.5 * r1 + 0.1e-3) {
        switched_in_trial = true;
        ++switched_inside;
        core::Core::Snapshot now;
        off.Save(now);
        REQUIRE(guarded.Restore(now));
        guarded.set_hold_out_of_parts(true);
        int held_after = 0;
        double t_guarded = t;
        for (int j = 0; j < 20; ++j)
          held_after += (guarded.Step(t_guarded += T, Y).flags & core::kHeldBack) ? 1 : 0;
        CHECK(held_after < 20);
      }
      if (out.flags & core::kHeldBack) {
        ++held_ticks;
        held_in_trial = true;
        CHECK(out.X_WH.matrix() == before.X_WH.matrix());
        CHECK(on.FormationText() == cf_before);
        CHECK(out.torque_W_Nm == before.torque_W_Nm);
        const Eigen::Vector3d h = Y.translation();
        Eigen::Vector3d pull = -(coupling.stiffness_N_per_m * (h - out.X_WH.translation()) +
                                 coupling.damping_Ns_per_m * (h - hand_before) / T);
        const bool clamped = pull.norm() > s.device.max_force_N;
        if (clamped) pull *= s.device.max_force_N / pull.norm();
        CHECK((out.force_W_N - pull).norm() <= 1e-12 * (1.0 + pull.norm()));
        // The shape sent is last tick's, with its flags; a saturated spring is a separated
        // proxy, as in a tick that moves (the judge counts those as the tube stalled).
        constexpr std::uint32_t kShapeFlags = core::kLinearFallback | core::kBeyondLinearRange |
                                              core::kRodShape | core::kShapeOffContacts;
        CHECK((out.flags & kShapeFlags) == (before.flags & kShapeFlags));
        CHECK(((out.flags & core::kProxySeparated) != 0) == clamped);
      }
      hand_before = Y.translation();
    }
    trials_held += held_in_trial ? 1 : 0;
    trials_through_off += deepest_off_trial > 0.5 * r1 ? 1 : 0;
    deepest_off = std::max(deepest_off, deepest_off_trial);
  }
  INFO(held_ticks << " held ticks in " << trials_held << " of " << kTrials
                  << " trials; without the guard " << trials_through_off
                  << " trials went deeper than r1/2, deepest " << deepest_off * 1e3
                  << " mm; with it " << deepest_on * 1e3 << " mm");
  CHECK(trials_held >= 3);
  CHECK(trials_through_off >= 3);
  CHECK(switched_inside >= 1);
  CHECK(deepest_off > 0.5 * r1);
  CHECK(deepest_on <= 0.5 * r1 + 1e-4);
}

TEST_CASE("Invariants on random states of both shipped scenes", "[core][invariants]") {
  std::mt19937_64 rng(20261122);
  for (const char* file : {"scenes/groove.yaml", "scenes/groove-steel.yaml"}) {
    for (const auto rule :
         {scene::MultiContactRule::kSegmented, scene::MultiContactRule::kCoupled}) {
      scene::Scene s = LoadScene(file);
      s.model.multi_contact = rule;
      core::Core c(s);
      const core::Coupling coupling = core::ResolveCoupling(s.device, s.model.time_step_s);
      const Eigen::Isometry3d start = s.X_WH_start;
      double t = 0.0;
      int contacts_seen = 0, at_rest = 0, held_back = 0;
      for (int trial = 0; trial < 60; ++trial) {
        // A random pose of the held end over and in the groove, each trial from the start.
        const Eigen::Isometry3d X = RandomGroovePose(s, rng);
        c.Reset(start);
        double settling_m = 0.0;  // how far the held end still moves over the last 20 ticks
        Eigen::Vector3d held_before = Eigen::Vector3d::Zero();
        for (int k = 1; k <= 300; ++k) {  // move there over 0.2 s, then hold
          const Eigen::Isometry3d Y = RandomStatePath(start, X, k);
          const Eigen::Vector3d held = c.Step(t += 1e-3, Y).X_WH.translation();
          if (k > 280) settling_m = std::max(settling_m, (held - held_before).norm());
          held_before = held;
        }
        const core::StepOutput& out = c.last();
        INFO(file << " trial " << trial << ": " << c.FormationText() << " flags " << out.flags);
        REQUIRE(out.force_W_N.allFinite());
        REQUIRE(out.torque_W_Nm.allFinite());
        REQUIRE(std::isfinite(out.energy_J));
        CHECK((out.flags & core::kSolverFault) == 0);
        contacts_seen += out.contact_count;
        // The operator's wrench is the sum of the contact wrenches about the held end.
        Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
        for (const core::ContactState& pc : out.Contacts()) {
          force += pc.force_W_N;
          moment += pc.moment_W_Nm;
          // Friction never exceeds the static limit at any load point, nor for the PC: a line
          // contact's two points share the PC's limit (FrictionShare).
          INFO("friction " << pc.friction_W_N.norm() << " N, limit " << pc.friction_limit_N
                           << " N");
          CHECK(pc.friction_ratio <= 1.0 + 1e-9);
          CHECK(pc.friction_W_N.norm() <= pc.friction_limit_N * (1 + 1e-9) + 1e-15);
          CHECK(pc.normal_force_N >= 0.0);
        }
        // The operator's wrench is the sum of the contact wrenches about the held end, unless the
        // tube was held back from going through a part: then the contacts are those of the state
        // kept (their moment still the torque sent) and the force is the coupling's, the hand
        // still here: its spring, up to the device's force.
        if (out.flags & core::kHeldBack) {
          ++held_back;
          Eigen::Vector3d pull =
              coupling.stiffness_N_per_m * (out.X_WH.translation() - X.translation());
          if (pull.norm() > s.device.max_force_N) pull *= s.device.max_force_N / pull.norm();
          CHECK((pull - out.force_W_N).norm() <= 1e-12 * (1.0 + pull.norm()));
        } else {
          CHECK((force - out.force_W_N).norm() <= 1e-12 * (1.0 + force.norm()));
        }
        CHECK((moment - out.torque_W_Nm).norm() <= 1e-12 * (1.0 + moment.norm()));
        // The CF's text round-trips.
        const states::ParseResult parsed = states::ParseContactFormation(c.FormationText());
        REQUIRE(parsed.cf.has_value());
        CHECK(*parsed.cf == c.Formation());
        // And at rest it is what the coupling spring carries: the hand held still, its damper
        // relaxed (2 N s/m over 100 ticks: (B/T / (K_c + B/T))^100 ~ 1e-8), unless the spring is
        // saturated at the device's force. (Not every state comes to rest: a soft tube bent hard
        // along a face can keep changing its contacts from tick to tick; see docs/core.md.)
        // A held tick does not move, so it looks at rest; its force was checked above (the
        // coupling's pull, clamped at the device's force).
        if (settling_m > 1e-9 || (out.flags & core::kHeldBack)) continue;
        ++at_rest;
        const Eigen::Vector3d spring =
            coupling.stiffness_N_per_m * (out.X_WH.translation() - X.translation());
        if (out.flags & core::kProxySeparated) {
          // The spring or the grip is saturated at the device's force or torque.
          const bool at_force = std::abs(out.force_W_N.norm() - s.device.max_force_N) <= 1e-6;
          // (the grip's weak regularising spring adds at most 1e-3 of the torque per radian)
          const bool at_torque = std::abs(out.torque_W_Nm.norm() - s.device.max_torque_Nm) <=
                                 1e-2 * s.device.max_torque_Nm;
          CHECK((at_force || at_torque));
        } else {
          // What the damper still carries: B times the held end's last speed (settling / T).
          const double damper_N = coupling.damping_Ns_per_m * settling_m / s.model.time_step_s;
          CHECK((out.force_W_N - spring).norm() <= 2.0 * damper_N + 1e-9 * (1.0 + spring.norm()));
        }
      }
      CHECK(contacts_seen > 20);  // the poses do reach the parts
      INFO(file << ": " << at_rest << " of 60 states came to rest, " << held_back << " held back");
      WARN(file << " " << int(rule) << ": " << at_rest << " of 60 at rest, " << held_back
                << " held back");
      CHECK(at_rest >= 10);  // and the equilibrium check is not vacuous
    }
  }
}

TEST_CASE("Degenerate inputs never make NaN leave the core", "[core][degenerate]") {
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  core::Core c(s);
  double t = 0.0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(nan, 0, 0), Eigen::Vector3d(0, inf, 0),
                                   Eigen::Vector3d(1e300, -1e300, 1e300)}) {
    Eigen::Isometry3d X = s.X_WH_start;
    X.translation() = p;
    const core::StepOutput& out = c.Step(t += 1e-3, X);
    CHECK(out.force_W_N.allFinite());
    CHECK(out.torque_W_Nm.allFinite());
    CHECK(out.X_WH.translation().allFinite());
    CHECK(std::isfinite(out.energy_J));
    if (!p.allFinite()) CHECK((out.flags & core::kSolverFault) != 0);
  }
  // A rotation that is not one (NaN) is refused the same way.
  Eigen::Isometry3d X = s.X_WH_start;
  X.linear()(0, 0) = nan;
  CHECK((c.Step(t += 1e-3, X).flags & core::kSolverFault) != 0);
  CHECK(c.last().force_W_N.isZero(0.0));
  // And the core carries on from a valid pose afterwards.
  c.Reset(s.X_WH_start);
  const core::StepOutput& after = c.Step(t += 1e-3, s.X_WH_start);
  CHECK(after.flags == 0);
  CHECK(after.contact_count == 0);
}

TEST_CASE("Free motion: the held end follows the hand and nothing is felt", "[core]") {
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  core::Core c(s);
  double t = 0.0;
  Eigen::Isometry3d X = s.X_WH_start;
  for (int k = 0; k < 200; ++k) {
    X.translation().x() = 0.01 * std::sin(0.01 * k);
    const core::StepOutput& out = c.Step(t += 1e-3, X);
    REQUIRE(out.contact_count == 0);
    // With no contact the coupling balances nothing: the proxy sits on the hand exactly.
    CHECK((out.X_WH.translation() - X.translation()).norm() <= 1e-15);
    CHECK(out.force_W_N.isZero(0.0));
    CHECK(out.energy_J == 0.0);
    CHECK(c.narrow_phase_calls() == 0);  // far from every part: the broad phase stops it all
  }
}

TEST_CASE("The chain's capsule count keeps its chord error, or is the scene's", "[core]") {
  // ChainCapsuleCount's rule, checked as the property it promises: a capsule of length l/N on an
  // arc of the largest curvature the device can bend the tube to (kappa = F_max l / (E I), the
  // linear root curvature under a tip force) lies within epsilon / 10 of the arc, unless the count
  // is at the cap. A count the scene sets replaces the rule and shapes the chain.
  for (const char* file : {"scenes/groove.yaml", "scenes/groove-steel.yaml"}) {
    scene::Scene s = LoadScene(file);
    const double l = s.tube.length_m;
    const double kappa =
        s.device.max_force_N * l / model::ComputeSection(s.tube).bending_stiffness_Nm2;
    const int n = core::ChainCapsuleCount(s);
    CAPTURE(file, n, kappa);
    CHECK(n >= core::kMinCapsules);
    CHECK(n <= core::kMaxCapsules);
    const double chord_error_m = kappa * (l / n) * (l / n) / 8.0;
    if (n < core::kMaxCapsules) CHECK(chord_error_m <= 0.1 * s.contact.threshold_m);
    // One capsule fewer would not do, unless the count is at the floor.
    if (n > core::kMinCapsules)
      CHECK(kappa * (l / (n - 1)) * (l / (n - 1)) / 8.0 > 0.1 * s.contact.threshold_m);

    s.model.capsules = 16;
    core::Core c(s);
    CHECK(c.capsule_count() == 16);
    // The coarser chain still carries the tube: pressed onto the floor it reports the floor.
    Eigen::Isometry3d X = s.X_WH_start;
    c.Reset(X);
    for (int k = 0; k < 200; ++k) {
      X.translation().z() -= 2e-4;
      const core::StepOutput& out = c.Step(1e-3 * k, X);
      REQUIRE(out.force_W_N.allFinite());
    }
    CHECK(c.last().contact_count >= 1);
  }
}
