// The core against the shooting reference (reference/shooting_elastica.hpp): an inextensible
// elastica integrated along its arc and shot by Newton's method, its contact forces unknowns of
// that solve, written apart from the core and by another method. The tube is held in the world's
// (x, z) plane, the hand moved from hold to hold slowly and held until the state settles, and
// the operator force compared hold by hold.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/model/tube.hpp>
#include <tubeplan/reference/shooting_elastica.hpp>

#include "core_scenes.hpp"

using namespace tubeplan;
namespace sh = tubeplan::reference::shooting;
using Eigen::Vector2d;

namespace {

constexpr double kPi = std::numbers::pi;

// The held end at (x, z) of the plane, its axis turned phi from +z towards +x (the reference's
// tangent angle).
Eigen::Isometry3d HandPose(const sh::Hold& h) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(h.root_angle_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(h.hand_m.x(), 0.0, h.hand_m.y());
  return X;
}

// A tube (testing::RubberScene or SteelScene: a shipped scene's tube and contact law) with the
// given friction and one part, held at `start`; the grip a spring of 400 N/m without damping, as
// the reference's.
scene::Scene WithPart(scene::Scene s, const scene::Friction& friction, scene::Part part,
                      const sh::Hold& start) {
  s.friction = friction;
  s.parts.push_back(std::move(part));
  s.X_WH_start = HandPose(start);
  return s;
}

// A floor whose top is the plane z = 0.
scene::Part Floor() {
  scene::Part floor;
  floor.name = "floor";
  floor.size_m = {0.8, 0.2, 0.02};
  floor.X_WP.translation() = Eigen::Vector3d(0.2, 0.0, -0.01);
  return floor;
}

// A 40 mm cube turned 45 degrees about y, on the +x side of its edge along y at (x, z) of the
// plane.
scene::Part EdgeBlock(const Vector2d& edge_m) {
  scene::Part block;
  block.name = "block";
  block.size_m = {0.04, 0.04, 0.04};
  block.X_WP.linear() = Eigen::AngleAxisd(kPi / 4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  block.X_WP.translation() = Eigen::Vector3d(edge_m.x() + 0.02 * std::sqrt(2.0), 0.0, edge_m.y());
  return block;
}

sh::Rod ReferenceRod(const scene::Scene& s) {
  sh::Rod rod;
  rod.length_m = s.tube.length_m;
  rod.bending_stiffness_Nm2 = model::ComputeSection(s.tube).bending_stiffness_Nm2;
  rod.radius_m = s.tube.outer_radius_m;
  return rod;
}

// What the core felt at the end of each hold, the hand ramped there over `ramp` ticks (a line),
// then held `settle` ticks; and over every tick, whether it converged and followed the hand,
// and the work done on the tube at its held end.
struct CoreHold {
  Vector2d force_N = Vector2d::Zero();  ///< on the hand
  bool touching = false;
  bool sliding = false;  ///< at the last tick of the ramp
  double energy_J = 0.0, work_J = 0.0;
};
struct CoreRun {
  std::vector<CoreHold> holds;
  int unconverged = 0, held_back = 0;
};

CoreRun RunCore(const scene::Scene& s, const std::vector<sh::Hold>& holds, int ramp, int settle) {
  core::Core c(s);
  double t = 0.0, work_J = 0.0;
  Eigen::Isometry3d from = s.X_WH_start;
  Eigen::Vector3d p_held = s.X_WH_start.translation(), f_on_tube = Eigen::Vector3d::Zero();
  CoreRun run;
  for (const sh::Hold& h : holds) {
    const Eigen::Isometry3d to = HandPose(h);
    CoreHold r;
    for (int i = 1; i <= ramp + settle; ++i) {
      Eigen::Isometry3d X = to;
      const double u = std::min(1.0, double(i) / ramp);
      X.translation() = (1.0 - u) * from.translation() + u * to.translation();
      const core::StepOutput& o = c.Step(t += s.model.time_step_s, X);
      run.unconverged += (o.flags & core::kNotConverged) != 0;
      run.held_back += (o.flags & (core::kProxySeparated | core::kSolverFault)) != 0;
      // The grip turns with the hand, which does not turn here: only the force works.
      work_J += 0.5 * (f_on_tube - o.force_W_N).dot(o.X_WH.translation() - p_held);
      f_on_tube = -o.force_W_N;
      p_held = o.X_WH.translation();
      // Sliding into the hold: at the last tick the hand moves (held still, a contact sticks).
      if (i == ramp)
        for (const core::ContactState& pc : o.Contacts()) r.sliding = r.sliding || pc.sliding;
    }
    from = to;
    r.force_N = {c.last().force_W_N.x(), c.last().force_W_N.z()};
    r.energy_J = c.last().energy_J;
    r.work_J = work_J;
    r.touching = !c.last().Contacts().empty();
    run.holds.push_back(r);
  }
  return run;
}

const char* PhaseName(sh::ContactPhase p) {
  return p == sh::ContactPhase::kOpen    ? "open"
         : p == sh::ContactPhase::kStuck ? "stuck"
                                         : "sliding";
}

// The core and the reference (with the core's friction law: the load exponent on the kinetic
// force too, the stuck contact's spring K) along the holds, the part and the obstacle the same
// surface; each hold reached in 100 ms, held 100 ms. Returns the largest relative error of the
// operator force at the holds of 0.1 N or more.
double ComparePath(const scene::Scene& tube, const scene::Friction& friction,
                   const scene::Part& part, sh::Obstacle obstacle,
                   const std::vector<sh::Hold>& holds, int min_stuck, int min_sliding) {
  const scene::Scene s = WithPart(tube, friction, part, holds[0]);
  sh::Setup setup;
  setup.coupling_N_per_m = *s.device.coupling_stiffness_N_per_m;
  setup.law = {s.contact.stiffness_N_per_m, s.contact.threshold_m};
  obstacle.friction = {friction.static_coefficient, friction.kinetic_coefficient, friction.exponent,
                       friction.reference_load_N, true};
  setup.obstacles.push_back(obstacle);
  const sh::PathResult ref = sh::FollowPath(ReferenceRod(s), setup, holds);
  REQUIRE(ref.ok);

  const CoreRun core = RunCore(s, holds, 100, 100);
  CHECK(core.unconverged == 0);
  CHECK(core.held_back == 0);
  int compared = 0, stuck = 0, sliding = 0;
  double largest_error = 0.0;
  for (std::size_t k = 0; k < holds.size(); ++k) {
    const sh::HoldResult& h = ref.holds[k];
    const CoreHold& c = core.holds[k];
    // The reference gives the force on the tube, the core the force on the hand.
    const Vector2d f_ref = h.solution.operator_force_N;
    INFO("hold " << k << ": reference " << f_ref.transpose() << " N (" << PhaseName(h.phase[0])
                 << "), core " << (-c.force_N).transpose() << " N ("
                 << (c.sliding ? "sliding" : "stuck") << ")");
    // Touching where the reference touches, but for a contact at the band's edge (below 1 mN,
    // 0.1 um inside it), where the two solvers' roundings decide.
    if (h.phase[0] == sh::ContactPhase::kOpen || h.solution.contacts[0].normal_N > 1e-3)
      CHECK(c.touching == (h.phase[0] != sh::ContactPhase::kOpen));
    // The tube stores no more than the hand put in (1 % for the trapezoids where a contact
    // engages between two ticks).
    CHECK(c.energy_J <= 1.01 * c.work_J + 1e-12);
    if (f_ref.norm() < 0.1) continue;
    // Stuck or sliding as the reference is (a frictionless contact has no friction state).
    if (!friction.IsFrictionless()) CHECK(c.sliding == (h.phase[0] == sh::ContactPhase::kSliding));
    ++compared;
    stuck += h.phase[0] == sh::ContactPhase::kStuck;
    sliding += h.phase[0] == sh::ContactPhase::kSliding;
    const double error = (c.force_N + f_ref).norm() / f_ref.norm();
    largest_error = std::max(largest_error, error);
    // 5 %: the margin a verdict near a force limit can carry (docs/accuracy.md).
    CHECK(error <= 0.05);
  }
  CHECK(compared >= 30);
  CHECK(stuck >= min_stuck);
  CHECK(sliding >= min_sliding);
  return largest_error;
}

// The tube held at 45 degrees, the end's lower corner 5 mm over a floor, lowered in `down` holds
// of `down_step_m`, then pushed along +x in `along` holds of `along_step_m`: the reference's
// obstacle the end's deeper corner on the floor.
double LoweredAndPushed(const scene::Scene& tube, const scene::Friction& friction, int down,
                        double down_step_m, int along, double along_step_m) {
  const double phi0 = 3 * kPi / 4;
  const double l = tube.tube.length_m, r1 = tube.tube.outer_radius_m;
  const Vector2d start(0.0, -(l * std::cos(phi0) - r1 * std::sin(phi0)) + 5e-3);
  std::vector<sh::Hold> holds;
  for (int k = 0; k <= down; ++k) holds.push_back({start + Vector2d(0.0, -down_step_m * k), phi0});
  for (int k = 1; k <= along; ++k)
    holds.push_back({holds[std::size_t(down)].hand_m + Vector2d(along_step_m * k, 0.0), phi0});
  sh::Obstacle floor;
  floor.kind = sh::ObstacleKind::kPlaneRim;
  return ComparePath(tube, friction, Floor(), floor, holds, 6, 6);
}

}  // namespace

TEST_CASE(
    "The rubber tube lowered at 45 degrees onto a floor and pushed along it, stuck then sliding: "
    "the operator force within 5 % of the shooting reference's",
    "[core][shooting]") {
  // 30 mm down, 30 mm along, in holds of 0.5 mm: the end's corner lands, sticks and slides in
  // turn as the tube bends, then the push drags it along (measured: within 0.96 % at 111 holds,
  // 89 stuck and 22 sliding).
  const double error =
      LoweredAndPushed(testing::RubberScene(), {0.7, 0.08, 2.0 / 3.0, 1.0}, 60, 0.5e-3, 60, 0.5e-3);
  INFO("largest relative error " << error);
}

TEST_CASE(
    "The steel tube lowered at 45 degrees onto a floor and pushed along it, stuck then sliding: "
    "the operator force within 5 % of the shooting reference's",
    "[core][shooting]") {
  // 6 mm down in holds of 0.1 mm (the stiff tube barely bends: the grip's spring takes the
  // travel, 2 N in all), then 30 mm along in holds of 0.5 mm (measured: within 0.54 % at 77
  // holds, 17 stuck and 60 sliding).
  const double error =
      LoweredAndPushed(testing::SteelScene(), {0.3, 0.2, 1.0, 1.0}, 60, 0.1e-3, 60, 0.5e-3);
  INFO("largest relative error " << error);
}

TEST_CASE(
    "The rubber tube's side pressed onto a frictionless edge and drawn along it over the edge: "
    "the operator force within 5 % of the shooting reference's",
    "[core][shooting]") {
  // The tube along +z, an edge 2 mm off its side at two thirds of its length: the hand presses
  // the side onto the edge along +x, 20 mm, then draws the tube back along its axis, 20 mm, the
  // contact sliding along the side towards the free end (measured: within 0.35 % at 70 holds).
  const scene::Scene tube = testing::RubberScene();
  const double l = tube.tube.length_m, r1 = tube.tube.outer_radius_m;
  const Vector2d edge(r1 + 2e-3, 2.0 * l / 3.0);
  std::vector<sh::Hold> holds;
  for (int k = 0; k <= 40; ++k) holds.push_back({Vector2d(0.5e-3 * k, 0.0), 0.0});
  for (int k = 1; k <= 40; ++k)
    holds.push_back({holds[40].hand_m + Vector2d(0.0, -0.5e-3 * k), 0.0});
  sh::Obstacle ob;
  ob.kind = sh::ObstacleKind::kEdge;
  ob.point_m = edge;
  const double error = ComparePath(tube, scene::Friction{}, EdgeBlock(edge), ob, holds, 0, 0);
  INFO("largest relative error " << error);
}

namespace {

// The rubber tube's side pressed 20 mm onto an edge with friction (as the frictionless edge
// above), stuck throughout, at contact band eps. In fine holds up to 2.5 mm: the reference places
// its first anchor by interpolating between holds, which at holds of 0.5 mm puts up to 0.012 N
// more along the tube into its spring (10 % of the first compared hold's force at eps = 0.3 mm).
double StuckOnEdge(double eps_m) {
  scene::Scene tube = testing::RubberScene();
  tube.contact.threshold_m = eps_m;
  const double l = tube.tube.length_m, r1 = tube.tube.outer_radius_m;
  const Vector2d edge(r1 + 2e-3, 2.0 * l / 3.0);
  std::vector<sh::Hold> holds;
  for (int k = 0; k <= 80; ++k) holds.push_back({Vector2d(0.5e-3 / 16.0 * k, 0.0), 0.0});
  for (int k = 6; k <= 40; ++k) holds.push_back({Vector2d(0.5e-3 * k, 0.0), 0.0});
  sh::Obstacle ob;
  ob.kind = sh::ObstacleKind::kEdge;
  ob.point_m = edge;
  return ComparePath(tube, {0.7, 0.08, 2.0 / 3.0, 1.0}, EdgeBlock(edge), ob, holds, 30, 0);
}

}  // namespace

TEST_CASE(
    "The rubber tube's side pressed onto an edge with friction, stuck: within 5 % of the "
    "shooting reference's at the shipped contact band and at a tenth of it",
    "[core][shooting]") {
  // A stuck point is held where it touches the edge, across the band's gap: the tube turning
  // about the edge stretches no spring (measured 1.0 % at eps = 1 mm, 0.37 % at 0.1 mm; 20 %
  // at 1 mm with the point held on the tube's surface).
  SECTION("eps = 1 mm") { INFO("largest relative error " << StuckOnEdge(1e-3)); }
  SECTION("eps = 0.1 mm") { INFO("largest relative error " << StuckOnEdge(1e-4)); }
}
