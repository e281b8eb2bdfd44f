// Invariants of the core: a tick allocates nothing, the same inputs give the same bits in any
// thread and after a snapshot, degenerate inputs never make NaN leave it, no hand motion, however
// fast, takes the tube through a part, and the shipped insertion converges in every tick.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <thread>

#include <catch2/catch.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/trajectory_csv.hpp>

#include "../alloc_count.hpp"

using namespace tubeplan;
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

std::vector<trajectories::HandSample> InsertTicks() {
  io::TrajectoryLoadResult loaded = io::LoadTrajectoryFile(SourcePath("plans/groove-insert.csv"));
  REQUIRE(loaded.trajectory.has_value());
  return trajectories::Resample(*loaded.trajectory, 1e-3);
}

Eigen::Isometry3d Pose(const trajectories::HandSample& s) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = s.q_WH.toRotationMatrix();
  X.translation() = s.p_WH_m;
  return X;
}

// FNV-1a over the bytes of every figure a tick returns.
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

// The hash of ticks [first, last) run on `c` as it is.
std::uint64_t HashTicks(core::Core& c, const std::vector<trajectories::HandSample>& ticks,
                        std::size_t first, std::size_t last) {
  Hash hash;
  for (std::size_t k = first; k < last; ++k) {
    const core::StepOutput& out = c.Step(ticks[k].t_s, Pose(ticks[k]));
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

}  // namespace

TEST_CASE("A tick allocates nothing, with or without the shape", "[core][alloc]") {
  // The whole insertion: free motion, the rim on the floor, sliding, the side landing.
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const std::vector<trajectories::HandSample> ticks = InsertTicks();
  core::Core c(s);
  c.Reset(Pose(ticks.front()));
  c.Step(ticks[0].t_s, Pose(ticks[0]));
  std::array<Eigen::Vector3d, 21> centreline;
  int contact_ticks = 0;
  const std::int64_t before = g_allocations;
  for (std::size_t k = 1; k < ticks.size(); ++k) {
    const core::StepOutput& out = c.Step(ticks[k].t_s, Pose(ticks[k]));
    if (out.contact_count > 0) ++contact_ticks;
    if (k % 2 == 0) c.Centreline(centreline);
  }
  const std::int64_t allocations = g_allocations - before;
  CHECK(allocations == 0);
  CHECK(contact_ticks > 2000);  // the count covered contact ticks, not only free motion
}

TEST_CASE("The same inputs give the same bits, in any thread", "[core][determinism]") {
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const std::vector<trajectories::HandSample> ticks = InsertTicks();
  const auto run = [&] {
    core::Core c(s);
    c.Reset(Pose(ticks.front()));
    return HashTicks(c, ticks, 0, ticks.size());
  };
  const std::uint64_t here = run();
  std::uint64_t a = 0, b = 0;
  std::thread ta([&] { a = run(); }), tb([&] { b = run(); });
  ta.join();
  tb.join();
  CHECK(a == here);
  CHECK(b == here);
  // A core that ran something else first and was reset gives the same bits.
  core::Core used(s);
  used.Reset(Pose(ticks[3000]));
  HashTicks(used, ticks, 3000, 4000);
  used.Reset(Pose(ticks.front()));
  CHECK(HashTicks(used, ticks, 0, ticks.size()) == here);
}

TEST_CASE("A snapshot puts a core back where it was, bit for bit, in another core too",
          "[core][determinism]") {
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const std::vector<trajectories::HandSample> ticks = InsertTicks();
  // Saved while the rim presses and slides on the floor (t = 2.5 s).
  const std::size_t at = 2500;
  core::Core a(s), b(s);
  a.Reset(Pose(ticks.front()));
  HashTicks(a, ticks, 0, at);
  core::Core::Snapshot snapshot;
  a.Save(snapshot);
  REQUIRE(a.last().contact_count > 0);
  const std::uint64_t straight_on = HashTicks(a, ticks, at, ticks.size());
  b.Reset(Pose(ticks[4000]));
  HashTicks(b, ticks, 4000, 4500);
  REQUIRE(b.Restore(snapshot));
  CHECK(HashTicks(b, ticks, at, ticks.size()) == straight_on);
  REQUIRE(a.Restore(snapshot));
  CHECK(HashTicks(a, ticks, at, ticks.size()) == straight_on);
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
    if (!p.allFinite()) {
      CHECK((out.flags & core::kSolverFault) != 0);
      CHECK(out.force_W_N.isZero(0.0));
    }
  }
  // A rotation that is not one (NaN, or all zeros) is refused or made one.
  Eigen::Isometry3d X = s.X_WH_start;
  X.linear()(0, 0) = nan;
  CHECK((c.Step(t += 1e-3, X).flags & core::kSolverFault) != 0);
  CHECK(c.last().force_W_N.isZero(0.0));
  X.linear().setZero();
  CHECK(c.Step(t += 1e-3, X).force_W_N.allFinite());
  // And the core carries on from a valid pose afterwards.
  c.Reset(s.X_WH_start);
  const core::StepOutput& after = c.Step(t += 1e-3, s.X_WH_start);
  CHECK((after.flags & core::kSolverFault) == 0);
  CHECK(after.contact_count == 0);
  CHECK(after.force_W_N.allFinite());
}

TEST_CASE("No hand motion takes the tube through a part", "[core][through]") {
  // The tube lying in the groove on the floor (top z = 0, 10 mm thick; walls' inner faces at
  // x = -10 mm and +10 mm, 20 mm high). The hand jumps in one sample 100 mm down (through the
  // floor), or 40 mm sideways (across the right wall), and stays there 1 s. The tube's axis
  // must stay on the near side of the part: the penalty and the coupling's saturation at the
  // device's force hold it; the operator feels the device's limit (flag kProxySeparated).
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const double r1 = s.tube.outer_radius_m;
  Eigen::Isometry3d lying = s.X_WH_start;
  lying.translation().z() = r1 + 0.5 * s.contact.threshold_m;
  struct Jump {
    const char* what;
    Eigen::Vector3d by_m;
  };
  for (const Jump& jump : {Jump{"100 mm down", {0.0, 0.0, -0.100}},
                           Jump{"40 mm across the right wall", {0.040, 0.0, 0.0}},
                           Jump{"40 mm across the left wall", {-0.040, 0.0, 0.0}}}) {
    DYNAMIC_SECTION(jump.what) {
      core::Core c(s);
      c.Reset(lying);
      double t = 0.0;
      for (int k = 0; k < 200; ++k) c.Step(t += 1e-3, lying);
      Eigen::Isometry3d X = lying;
      X.translation() += jump.by_m;
      std::array<Eigen::Vector3d, 41> centre;
      // Over all ticks, and over those after the first 100 ms (settled).
      double lowest_m = 1.0, rightmost_m = -1.0, leftmost_m = 1.0;
      double settled_lowest_m = 1.0, settled_rightmost_m = -1.0, settled_leftmost_m = 1.0;
      bool separated = false;
      for (int k = 0; k < 1000; ++k) {
        const core::StepOutput& out = c.Step(t += 1e-3, X);
        REQUIRE(out.force_W_N.allFinite());
        CHECK(out.force_W_N.norm() <= s.device.max_force_N * (1.0 + 1e-9));
        separated = separated || (out.flags & core::kProxySeparated) != 0;
        c.Centreline(centre);
        for (const Eigen::Vector3d& p : centre) {
          lowest_m = std::min(lowest_m, p.z());
          rightmost_m = std::max(rightmost_m, p.x());
          leftmost_m = std::min(leftmost_m, p.x());
          if (k < 100) continue;
          settled_lowest_m = std::min(settled_lowest_m, p.z());
          settled_rightmost_m = std::max(settled_rightmost_m, p.x());
          settled_leftmost_m = std::min(settled_leftmost_m, p.x());
        }
      }
      INFO("lowest " << lowest_m << " m, x from " << leftmost_m << " to " << rightmost_m
                     << " m; settled: " << settled_lowest_m << ", " << settled_leftmost_m << " to "
                     << settled_rightmost_m << " m");
      // In every tick the tube's surface presses into a part by less than a millimetre (the
      // device's 8.5 N on K = 10 N/mm is 0.85 mm), settled or not.
      CHECK(lowest_m > s.tube.outer_radius_m - 1e-3);
      CHECK(rightmost_m < 0.010 - s.tube.outer_radius_m + 1e-3);
      CHECK(leftmost_m > -0.010 + s.tube.outer_radius_m - 1e-3);
      CHECK(settled_lowest_m > s.tube.outer_radius_m - 1e-3);
      CHECK(settled_rightmost_m < 0.010 - s.tube.outer_radius_m + 1e-3);
      CHECK(settled_leftmost_m > -0.010 + s.tube.outer_radius_m - 1e-3);
      CHECK(separated);
    }
  }
}

TEST_CASE("The shipped insertion reaches the solve's tolerance in every tick", "[core][converge]") {
  // The tube's side lands on the floor barely touching it while its sections join the contact one
  // by one: were a joining section to make the contact's energy jump, Newton would stall against
  // the jump and end ticks short of the tolerance.
  core::Core c(LoadScene("scenes/groove.yaml"));
  int unconverged = 0;
  for (const trajectories::HandSample& tick : InsertTicks()) {
    const core::StepOutput& out = c.Step(tick.t_s, Pose(tick));
    unconverged += (out.flags & core::kNotConverged) != 0;
  }
  CHECK(unconverged == 0);
  CHECK(c.FormationText() == "{Fs - floor.top}");
}

TEST_CASE("A tube held still on a floor with friction stays put and dissipates nothing",
          "[core][friction]") {
  // The rubber tube of scenes/groove.yaml lowered onto the groove's floor, its clamp tipped
  // down 3 deg so that it bends where it lies (its sections meet the floor at an angle), then
  // held still for a second. Friction holds it (mu 0.7): every contact point sticks, so no
  // friction work is done and nothing moves. A friction point re-anchored anywhere but at its
  // own material point would drag the tube a little every tick, sliding it and dissipating.
  const scene::Scene s = LoadScene("scenes/groove.yaml");
  const double r1 = s.tube.outer_radius_m;
  Eigen::Isometry3d X = s.X_WH_start;
  X.linear() =
      X.linear() * Eigen::AngleAxisd(-3.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitX());
  X.translation().z() = 0.9 * r1;
  core::Core c(s);
  double t = 0.0;
  const Eigen::Isometry3d from = c.last().X_W_hand;
  for (int k = 1; k <= 500; ++k) {
    Eigen::Isometry3d Y = X;
    const double u = k / 500.0;
    Y.translation() = (1.0 - u) * from.translation() + u * X.translation();
    c.Step(t += 1e-3, Y);
  }
  for (int k = 0; k < 200; ++k) c.Step(t += 1e-3, X);
  REQUIRE(c.last().contact_count > 0);
  std::array<Eigen::Vector3d, 19> before, after;
  c.Centreline(before);
  double work_J = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const core::StepOutput& out = c.Step(t += 1e-3, X);
    for (const core::ContactState& pc : out.Contacts()) work_J += pc.friction_work_J;
  }
  c.Centreline(after);
  double moved_m = 0.0;
  for (std::size_t i = 0; i < before.size(); ++i)
    moved_m = std::max(moved_m, (after[i] - before[i]).norm());
  INFO(c.FormationText());
  // Rounding of the solve (its tolerance on a rest the contacts hold) moves nothing by a
  // micrometre, nor dissipates a nanojoule, in a second.
  CHECK(work_J < 1e-9);
  CHECK(moved_m < 1e-6);
}
