// Candidate plans: Yen's k shortest paths against brute-force enumeration, and the synthesized
// operator trajectories against the minimum-jerk profile's closed form.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>

#include <catch2/catch.hpp>

#include <tubeplan/graph/paths.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/trajectories/synthesize.hpp>

namespace {

using namespace tubeplan;

TEST_CASE("Yen's k shortest paths match brute-force enumeration on random graphs", "[graph]") {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> cost(1.0, 3.0);
  for (int trial = 0; trial < 40; ++trial) {
    // 7 nodes, each ordered pair an arc with probability 0.4; start 0, goal 6.
    graph::ContactGraph g;
    g.nodes.resize(7);
    g.start = 0, g.goal = 6;
    std::vector<double> costs;
    for (int a = 0; a < 7; ++a) {
      for (int b = 0; b < 7; ++b) {
        if (a == b || std::uniform_real_distribution<double>(0, 1)(rng) > 0.4) continue;
        graph::Arc arc;
        arc.from = a, arc.to = b;
        g.arcs.push_back(arc);
        costs.push_back(cost(rng));
      }
    }
    // Every simple path 0 -> 6 by depth-first search, costs summed in path order.
    std::vector<graph::Path> all;
    std::vector<int> stack = {0};
    std::function<void(double)> dfs = [&](double so_far) {
      if (stack.back() == 6) {
        all.push_back({stack, so_far});
        return;
      }
      for (std::size_t i = 0; i < g.arcs.size(); ++i) {
        const graph::Arc& arc = g.arcs[i];
        if (arc.from != stack.back() ||
            std::find(stack.begin(), stack.end(), arc.to) != stack.end())
          continue;
        stack.push_back(arc.to);
        dfs(so_far + costs[i]);
        stack.pop_back();
      }
    };
    dfs(0.0);
    std::sort(all.begin(), all.end(), [](const graph::Path& a, const graph::Path& b) {
      return a.cost != b.cost ? a.cost < b.cost : a.nodes < b.nodes;
    });
    const std::vector<graph::Path> yen = graph::KShortestPaths(g, costs, 5);
    INFO("trial " << trial);
    REQUIRE(yen.size() == std::min<std::size_t>(5, all.size()));
    for (std::size_t i = 0; i < yen.size(); ++i) {
      // Random real costs make ties improbable; sums in the same order give the same bits.
      CHECK(yen[i].cost == Approx(all[i].cost).epsilon(1e-12));
      CHECK(yen[i].nodes == all[i].nodes);
    }
  }
}

TEST_CASE("The minimum-jerk profile", "[plan]") {
  using trajectories::MinimumJerk;
  CHECK(MinimumJerk(0.0) == 0.0);
  CHECK(MinimumJerk(1.0) == 1.0);
  CHECK(MinimumJerk(0.5) == Approx(0.5).epsilon(1e-15));
  for (double u : {0.1, 0.3, 0.7}) CHECK(MinimumJerk(u) + MinimumJerk(1.0 - u) == Approx(1.0));
  // Velocity and acceleration vanish at both ends: s(h) = 10 h^3 + O(h^4).
  const double h = 1e-3;
  CHECK(MinimumJerk(h) == Approx(10.0 * h * h * h).epsilon(2e-3));
  CHECK(1.0 - MinimumJerk(1.0 - h) == Approx(10.0 * h * h * h).epsilon(2e-3));
  // Peak velocity 15/8 at u = 1/2 (central difference, O(h^2) error).
  CHECK((MinimumJerk(0.5 + h) - MinimumJerk(0.5 - h)) / (2 * h) == Approx(1.875).epsilon(1e-5));
}

TEST_CASE("Synthesized trajectories pass through the waypoints at the set speed", "[plan]") {
  std::vector<Eigen::Isometry3d> waypoints(3, Eigen::Isometry3d::Identity());
  waypoints[1].translation() = Eigen::Vector3d(0.05, 0.0, -0.02);
  waypoints[1].linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  waypoints[2].translation() = Eigen::Vector3d(0.05, 0.03, -0.03);
  trajectories::SynthesisOptions o;
  const trajectories::Trajectory t = trajectories::SynthesizeTrajectory(waypoints, o);
  // Duration: holds at each of 3 waypoints plus two reaches, each max(1.875 d / v, min).
  const double d1 = waypoints[1].translation().norm();
  const double d2 = (waypoints[2].translation() - waypoints[1].translation()).norm();
  const double T1 = std::max(1.875 * d1 / o.peak_speed_m_per_s, o.min_segment_s);
  const double T2 = std::max(1.875 * d2 / o.peak_speed_m_per_s, o.min_segment_s);
  const double total = 3 * o.hold_s + T1 + T2;
  CHECK(t.samples.back().t_s == Approx(std::floor(total * 1000.0) / 1000.0).margin(1e-12));
  // At the end of each hold the hand is exactly at the waypoint.
  double peak_speed = 0.0;
  for (std::size_t i = 1; i < t.samples.size(); ++i) {
    peak_speed = std::max(peak_speed, (t.samples[i].p_WH_m - t.samples[i - 1].p_WH_m).norm() /
                                          (t.samples[i].t_s - t.samples[i - 1].t_s));
  }
  CHECK(t.samples[std::size_t(std::lround(o.hold_s * 1000))].p_WH_m.isApprox(
      waypoints[0].translation()));
  const std::size_t second = std::size_t(std::lround((2 * o.hold_s + T1) * 1000)) - 1;
  CHECK((t.samples[second].p_WH_m - waypoints[1].translation()).norm() < 1e-12);
  CHECK(Eigen::Quaterniond(waypoints[1].linear()).angularDistance(t.samples[second].q_WH) < 1e-9);
  // The peak speed is the set one (a finite difference over 1 ms of a quintic: within 1e-3).
  CHECK(peak_speed <= o.peak_speed_m_per_s * (1 + 1e-3));
  CHECK(peak_speed >= o.peak_speed_m_per_s * (1 - 1e-3));
}

TEST_CASE("A recorded hand path is retimed to the asked peak speed and held at its end", "[plan]") {
  // 200 ms along x at 40 mm/s, turning 0.1 rad about z, then 50 ms still: ticks of 1 ms.
  std::vector<trajectories::HandSample> path;
  for (int k = 0; k <= 250; ++k) {
    const double moving_s = std::min(k, 200) * 1e-3;
    path.push_back(
        {k * 1e-3, Eigen::Vector3d(0.04 * moving_s, 0.01, 0.02),
         Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * moving_s, Eigen::Vector3d::UnitZ()))});
  }
  // The largest speed between samples [m/s]. Times and speeds below are exact up to rounding
  // of a few operations on millisecond ticks: 1e-9 relative.
  const auto peak_m_per_s = [](const trajectories::Trajectory& t) {
    double speed_m_per_s = 0.0;
    for (std::size_t i = 1; i < t.samples.size(); ++i)
      speed_m_per_s =
          std::max(speed_m_per_s, (t.samples[i].p_WH_m - t.samples[i - 1].p_WH_m).norm() /
                                      (t.samples[i].t_s - t.samples[i - 1].t_s));
    return speed_m_per_s;
  };
  trajectories::SynthesisOptions o;
  // Within the asked peaks the path keeps its clock: the same poses at the same ticks, then the
  // hold at its end pose.
  o.peak_speed_m_per_s = 0.08;
  const trajectories::Trajectory same = trajectories::RetimeHandPath(path, o);
  REQUIRE(same.samples.size() == path.size() + std::size_t(std::lround(o.hold_s * 1e3)));
  for (std::size_t k = 0; k < path.size(); ++k) {
    CHECK(same.samples[k].t_s == path[k].t_s);
    CHECK(same.samples[k].p_WH_m == path[k].p_WH_m);
  }
  CHECK(same.samples.back().p_WH_m == path.back().p_WH_m);
  // Its orientation passes through slerp: the same up to rounding.
  CHECK(same.samples.back().q_WH.angularDistance(path.back().q_WH) < 1e-12);
  // Half the path's speed asked: twice its clock, 400 ms, then the hold.
  o.peak_speed_m_per_s = 0.02;
  const trajectories::Trajectory slow = trajectories::RetimeHandPath(path, o);
  CHECK(slow.samples.back().t_s == Approx(0.5 + o.hold_s).margin(1e-9));
  CHECK(peak_m_per_s(slow) == Approx(0.02).epsilon(1e-9));
  CHECK(slow.samples.back().p_WH_m == path.back().p_WH_m);
  // A turn faster than asked sets the clock: 0.5 rad/s against 0.125 asked, four times.
  o.peak_speed_m_per_s = 0.08;
  o.peak_turn_rad_per_s = 0.125;
  const trajectories::Trajectory turned = trajectories::RetimeHandPath(path, o);
  CHECK(turned.samples.back().t_s == Approx(1.0 + o.hold_s).margin(1e-9));
  CHECK(peak_m_per_s(turned) == Approx(0.01).epsilon(1e-9));
  // A slower try stretches it further: three times the turned clock.
  const trajectories::Trajectory slower = trajectories::RetimeHandPath(path, o, 3.0);
  CHECK(slower.samples.back().t_s == Approx(3.0 + o.hold_s).margin(1e-9));
  CHECK(peak_m_per_s(slower) == Approx(0.01 / 3.0).epsilon(1e-9));
  // Tremor moves the hand during the hold, within its amplitude on each axis; the 0.3 s hold
  // spans at least 2.4 periods of 8-12 Hz, so each axis passes half its amplitude.
  o.tremor_m = 1e-4;
  const trajectories::Trajectory trembling = trajectories::RetimeHandPath(path, o);
  double largest_m = 0.0;
  for (const trajectories::HandSample& s : trembling.samples)
    if (s.t_s > 1.0) largest_m = std::max(largest_m, (s.p_WH_m - path.back().p_WH_m).norm());
  CHECK(largest_m <= std::sqrt(3.0) * o.tremor_m);
  CHECK(largest_m > 0.5 * o.tremor_m);
}

TEST_CASE("Synthesized trajectories round-trip through the CSV format; quantised and trembling",
          "[plan]") {
  std::vector<Eigen::Isometry3d> waypoints(2, Eigen::Isometry3d::Identity());
  waypoints[1].translation() = Eigen::Vector3d(0.0, 0.04, -0.01);
  trajectories::SynthesisOptions o;
  o.tremor_m = 1e-4;
  o.quantum_m = 3e-5;
  const trajectories::Trajectory t = trajectories::SynthesizeTrajectory(waypoints, o);
  double largest_offset = 0.0;
  for (const trajectories::HandSample& s : t.samples) {
    for (int axis = 0; axis < 3; ++axis) {
      const double steps = s.p_WH_m[axis] / o.quantum_m;
      CHECK(std::abs(steps - std::round(steps)) < 1e-6);
    }
    if (s.t_s < o.hold_s) largest_offset = std::max(largest_offset, s.p_WH_m.norm());
  }
  // During the first hold only tremor moves the hand: at most sqrt(3) amplitudes plus half a
  // quantum per axis, and it does move.
  CHECK(largest_offset <= std::sqrt(3.0) * (o.tremor_m + 0.5 * o.quantum_m));
  CHECK(largest_offset > 0.5 * o.tremor_m);

  const io::TrajectoryLoadResult loaded =
      io::LoadTrajectoryText(io::FormatTrajectoryCsv(t), "synthesized.csv");
  REQUIRE(loaded.trajectory);
  REQUIRE(loaded.trajectory->samples.size() == t.samples.size());
  CHECK(loaded.trajectory->nominal_rate_Hz == 1000.0);
  for (std::size_t i = 0; i < t.samples.size(); i += 97) {
    // Written to 1e-9 m and 1e-9 in the quaternion.
    CHECK((loaded.trajectory->samples[i].p_WH_m - t.samples[i].p_WH_m).norm() < 1e-9);
    CHECK(loaded.trajectory->samples[i].t_s == Approx(t.samples[i].t_s).margin(1e-9));
  }
}

TEST_CASE("Plan files are written in format version 1", "[plan]") {
  plan::Plan p;
  p.name = "groove-candidate-1";
  p.scene = "../scenes/groove.yaml";
  p.trajectory = "groove-candidate-1.csv";
  p.states = {"{}", "{Fs - floor.top}"};
  p.comment = "made by a test\non two lines";
  CHECK(io::FormatPlanYaml(p) ==
        "# made by a test\n"
        "# on two lines\n"
        "tubeplan: 1\n"
        "plan: \"groove-candidate-1\"\n"
        "scene: \"../scenes/groove.yaml\"\n"
        "trajectory: \"groove-candidate-1.csv\"\n"
        "states:\n"
        "  - \"{}\"\n"
        "  - \"{Fs - floor.top}\"\n"
        "limits: {max_force: 8.5 N, max_strain: 0.2, max_penetration: 0.2 mm, dwell: 20 ms, "
        "stall: 1 s}\n");
}

}  // namespace
