// Candidate plans made from graph paths: each is replayed through the judge at each distinct
// aim (the witnesses' hand poses, their held end's poses, the stays of least force, the end
// brought in along the tube), slower while none is feasible; the feasible try of least force is
// kept, and the feasible candidates come first.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/batch/plans.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/motion.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/plan/candidates.hpp>
#include <tubeplan/report/plans_report.hpp>

namespace {

using namespace tubeplan;

constexpr double kPi = 3.14159265358979323846;

// The groove's start and goal as a two-node graph whose goal witness has the hand at height z
// over the floor and the held end at height held_z, with the tube turned as the shipped lay-flat
// plan ends.
graph::ContactGraph LayFlatGraph(const scene::Scene& scene, double hand_z_m, double held_z_m) {
  graph::ContactGraph g;
  g.nodes.resize(2);
  g.nodes[0].cf = "{}";
  g.nodes[0].X_W_hand = g.nodes[0].X_WH = scene.X_WH_start;
  g.nodes[1].cf = "{Fs - floor.top}";
  g.nodes[1].X_W_hand.linear() =
      Eigen::Quaterniond(0.737277337, -0.675590208, 0.0, 0.0).toRotationMatrix();
  g.nodes[1].X_WH.linear() = g.nodes[1].X_W_hand.linear();
  g.nodes[1].X_W_hand.translation() = Eigen::Vector3d(0.0, -0.09, hand_z_m);
  g.nodes[1].X_WH.translation() = Eigen::Vector3d(0.0, -0.09, held_z_m);
  g.start = 0;
  g.goal = 1;
  return g;
}

// The candidates of `paths` at 80 mm/s with the judge's 20 ms dwell, each try replayed as it is
// (counted in `replays`).
std::vector<plan::Candidate> CountedCandidates(const scene::Scene& scene,
                                               const graph::ContactGraph& g,
                                               const std::vector<graph::Path>& paths,
                                               int& replays) {
  plan::CandidateOptions options;
  options.synthesis.peak_speed_m_per_s = 0.08;
  options.dwell_s = 0.02;
  options.scene_ref = "groove.yaml";
  return plan::MakeCandidates(scene, g, paths, options, [&](const trajectories::Trajectory& t) {
    ++replays;
    return std::optional<trajectories::Trajectory>(t);
  });
}

// The start and a goal witnessed (hand, held end and stay of least force) at X_goal, reached
// with min_force_N at least.
graph::ContactGraph StartAndGoal(const scene::Scene& scene, const std::string& goal_cf,
                                 const Eigen::Isometry3d& X_goal, double min_force_N) {
  graph::ContactGraph g;
  g.nodes.resize(2);
  g.nodes[0].cf = "{}";
  g.nodes[0].X_W_hand = g.nodes[0].X_WH = scene.X_WH_start;
  g.nodes[1].cf = goal_cf;
  g.nodes[1].X_W_hand = g.nodes[1].X_WH = g.nodes[1].X_WH_least = X_goal;
  g.nodes[1].min_force_N = min_force_N;
  g.start = 0;
  g.goal = 1;
  return g;
}

// The judge's verdict on a reach through `waypoints` from {} to `goal_cf` at 80 mm/s, with the
// device's force and a 20 ms dwell.
plan::Judgement JudgeReach(const scene::Scene& scene,
                           const std::vector<Eigen::Isometry3d>& waypoints,
                           const std::string& goal_cf) {
  trajectories::SynthesisOptions synthesis;
  synthesis.peak_speed_m_per_s = 0.08;
  plan::Limits limits;
  limits.max_force_N = scene.device.max_force_N;
  limits.dwell_s = 0.02;
  return plan::Judge(scene, trajectories::SynthesizeTrajectory(waypoints, synthesis),
                     {"{}", goal_cf}, limits);
}

}  // namespace

TEST_CASE("plans: a feasible candidate that passed unplanned states says which, in evaluate's word",
          "[plan]") {
  plan::Candidate c;
  c.judgement.feasible = true;
  c.judgement.transitions.resize(2);
  c.judgement.transitions[0] = {
      .from = "{}", .to = "{Fs n post.top}", .verdict = plan::Verdict::kFeasible};
  c.judgement.transitions[1] = {.from = "{Fs n post.top}",
                                .to = "{Fe - post.top}",
                                .verdict = plan::Verdict::kFeasibleWithDetour,
                                .detour = {"{Fs n post.side}", "{}"}};
  const std::string text = plan::VerdictText(c);
  CHECK(text.rfind("feasible-with-detour ({Fs n post.top} -> {Fe - post.top} via {Fs n "
                   "post.side} {}); peak operator force",
                   0) == 0);
  c.judgement.transitions[1].verdict = plan::Verdict::kFeasible;
  CHECK(plan::VerdictText(c).rfind("feasible; peak operator force", 0) == 0);
}

TEST_CASE("plans: the hints name the limit that stopped the exploration", "[plan]") {
  graph::ContactGraph g;
  g.nodes.resize(56);
  g.probed = 0;
  g.end = graph::ExploreEnd::kTimeLimit;
  CHECK(batch::ExploreMoreHint(g) ==
        "a larger --time-limit (the exploration stopped at its time limit with 0 of 56 states "
        "probed)");
  // No path and nothing feasible: nothing is written, and more time is what is hinted at.
  batch::PlansRequest request;
  batch::Plans plans;
  plans.out_dir = "pin-plans";
  std::ostringstream out;
  report::PrintPlans(out, request, "pin", g, plans);
  INFO(out.str());
  CHECK(out.str().find("0 feasible; none written:") != std::string::npos);
  CHECK(out.str().find("pin-plans") == std::string::npos);
  CHECK(out.str().find("a larger --time-limit (the exploration stopped") != std::string::npos);
  CHECK(out.str().find("--budget") == std::string::npos);
  // --all writes them all, whatever their verdicts.
  request.all = true;
  std::ostringstream all;
  report::PrintPlans(all, request, "pin", g, plans);
  CHECK(all.str().find("; written to pin-plans:") != std::string::npos);
  g.end = graph::ExploreEnd::kBudget;
  CHECK(batch::ExploreMoreHint(g) == "a larger --budget");
  // Saturated: exploring on finds nothing new, so it is not hinted at.
  g.end = graph::ExploreEnd::kSaturated;
  CHECK(batch::ExploreMoreHint(g).empty());
}

TEST_CASE("Candidates: a path whose replays reach the goal by other states is planned on those",
          "[plan]") {
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/groove.yaml");
  REQUIRE(loaded.scene);
  const scene::Scene& scene = *loaded.scene;
  // The lay-flat goal behind a state witnessed at the start pose, where the tube touches
  // nothing: no replay of the path passes that state, and every one lays the tube flat.
  graph::ContactGraph g = LayFlatGraph(scene, 0.00816, 0.00816);
  graph::Node passed_by = g.nodes[0];
  passed_by.cf = "{Fs - left.top}";
  g.nodes.insert(g.nodes.begin() + 1, passed_by);
  g.goal = 2;
  const std::vector<graph::Path> paths = {{{0, 1, 2}, 1.0}};
  int replays = 0;
  const std::vector<plan::Candidate> c = CountedCandidates(scene, g, paths, replays);
  REQUIRE(c.size() == 1);
  INFO(plan::VerdictText(c[0]));
  CHECK(c[0].judgement.feasible);
  CHECK(c[0].restated);
  REQUIRE(c[0].plan.states.size() >= 2);
  CHECK(c[0].plan.states.front() == "{}");
  CHECK(c[0].plan.states.back() == "{Fs - floor.top}");
  CHECK(std::find(c[0].plan.states.begin(), c[0].plan.states.end(), "{Fs - left.top}") ==
        c[0].plan.states.end());
  CHECK(c[0].path.nodes.front() == 0);
  CHECK(c[0].path.nodes.back() == 2);
  CHECK(plan::VerdictText(c[0]).find("its states those its replay passed through") !=
        std::string::npos);
  // The path's one distinct aim at each of the three speeds, then the first, which reached the
  // goal, once more on the states it passed.
  CHECK(c[0].tries == 1);
  CHECK(replays == 3 + 1);
  // The trajectory is cut in its stay in the goal, after the goal counts: the goal is the last
  // state the replay counted, entered a dwell (20 ms) or more before the trajectory's end.
  const std::vector<plan::Observation>& seen = c[0].judgement.observed;
  REQUIRE(!seen.empty());
  CHECK(seen.back().cf == "{Fs - floor.top}");
  CHECK(c[0].trajectory.samples.back().t_s >= seen.back().t_s + 0.02);
  CHECK(c[0].duration_s == c[0].trajectory.samples.back().t_s);
}

TEST_CASE("Candidates: each distinct aim at each speed, slower until feasible, least force first",
          "[plan]") {
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/groove.yaml");
  REQUIRE(loaded.scene);
  const scene::Scene& scene = *loaded.scene;
  // One graph, three witnesses of the goal: the lay-flat plan's pose (8.16 mm over the floor);
  // the hand 40 mm lower, through the floor to the device's limit, with the tube held at the
  // lay-flat pose (the coupling stretched); and the held end down there too.
  const double z = 0.00816, deep = z - 0.040;
  graph::ContactGraph g = LayFlatGraph(scene, z, z);
  g.nodes.push_back(LayFlatGraph(scene, deep, z).nodes[1]);
  g.nodes.push_back(LayFlatGraph(scene, deep, deep).nodes[1]);
  const std::vector<graph::Path> paths = {{{0, 3}, 1.0}, {{0, 2}, 1.5}, {{0, 1}, 2.0}};
  int replays = 0;
  const std::vector<plan::Candidate> c = CountedCandidates(scene, g, paths, replays);
  REQUIRE(c.size() == 3);
  // The stretched witness fails aimed at the hand's pose and replays feasible aimed at the held
  // end's, at the asked speed; the feasible come first in the paths' order.
  CHECK(c[0].path.nodes == paths[1].nodes);
  CHECK(c[0].judgement.feasible);
  CHECK(c[0].tries == 2);
  CHECK(c[0].aim == graph::Aim::kHeld);
  CHECK(c[0].peak_speed_m_per_s == 0.08);
  CHECK(c[0].judgement.peak_force_N < 1.0);
  // The reachable witness replays feasible at once: its hand and held end are at one pose, so
  // the held aim coincides with the hand's and is not tried again.
  CHECK(c[1].path.nodes == paths[2].nodes);
  CHECK(c[1].judgement.feasible);
  CHECK(c[1].tries == 1);
  CHECK(c[1].aim == graph::Aim::kHand);
  CHECK(c[1].judgement.peak_force_N < scene.device.max_force_N);
  CHECK(c[1].plan.states == std::vector<std::string>{"{}", "{Fs - floor.top}"});
  // The witness whose tube was pushed through the floor too (hand and held end at one pose:
  // one straight aim, then the detour over the parts) stays infeasible after all three speeds,
  // at the device's limit, with the slowest try's longer trajectory.
  CHECK(c[2].path.nodes == paths[0].nodes);
  CHECK_FALSE(c[2].judgement.feasible);
  CHECK(c[2].tries == 6);
  CHECK(c[2].aim == graph::Aim::kOver);
  CHECK(c[2].peak_speed_m_per_s == Approx(0.02));
  CHECK(c[2].duration_s > 2.0 * c[1].duration_s);
  CHECK(c[2].judgement.peak_force_N == Approx(scene.device.max_force_N));
  // Its reason is the judge's, not a load failure (pushed through the floor, the tube leaves
  // the goal's lying-flat state).
  const std::string failure = plan::FirstFailure(c[2].judgement);
  CHECK(failure.find("after the goal") != std::string::npos);
  // Its tries passed the path's own states, {} then the goal: none is judged again on others.
  CHECK_FALSE(c[2].restated);
  CHECK(replays == 2 + 1 + 6);
}

TEST_CASE("Candidates: of two feasible aims, the one of least peak force is kept", "[plan]") {
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/groove.yaml");
  REQUIRE(loaded.scene);
  const scene::Scene& scene = *loaded.scene;
  // The goal's witness with the hand 3 mm below the held end (the coupling pulling the tube
  // onto the floor with about 1.2 N), and the same hand pose with the held end there too.
  const double z = 0.00816, pressed_z = z - 0.003;
  const graph::ContactGraph g = LayFlatGraph(scene, pressed_z, z);
  const graph::ContactGraph pressed = LayFlatGraph(scene, pressed_z, pressed_z);
  const std::vector<graph::Path> paths = {{{0, 1}, 1.0}};
  plan::CandidateOptions options;
  options.synthesis.peak_speed_m_per_s = 0.08;
  options.dwell_s = 0.02;
  options.scene_ref = "groove.yaml";
  const auto as_is = [](const trajectories::Trajectory& t) {
    return std::optional<trajectories::Trajectory>(t);
  };
  const std::vector<plan::Candidate> c = plan::MakeCandidates(scene, g, paths, options, as_is);
  const std::vector<plan::Candidate> p =
      plan::MakeCandidates(scene, pressed, paths, options, as_is);
  REQUIRE(c.size() == 1);
  REQUIRE(p.size() == 1);
  // Aimed at the hand's pose the replay is feasible at the asked speed, pressing harder.
  REQUIRE(p[0].judgement.feasible);
  REQUIRE(p[0].tries == 1);
  REQUIRE(p[0].peak_speed_m_per_s == 0.08);
  CHECK(c[0].judgement.feasible);
  CHECK(c[0].aim == graph::Aim::kHeld);
  CHECK(c[0].tries == 2);
  CHECK(c[0].judgement.peak_force_N < p[0].judgement.peak_force_N - 0.5);
}

TEST_CASE("Candidates: a state's stay of least force is aimed at as another witness", "[plan]") {
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/groove.yaml");
  REQUIRE(loaded.scene);
  const scene::Scene& scene = *loaded.scene;
  // The goal's witness with the hand and the held end 40 mm down, through the floor to the
  // device's limit; its stay of least force at the lay-flat pose (8.16 mm over the floor).
  const double z = 0.00816, deep = z - 0.040;
  graph::ContactGraph g = LayFlatGraph(scene, deep, deep);
  const graph::ContactGraph flat = LayFlatGraph(scene, z, z);
  g.nodes[1].min_force_N = 0.1;
  g.nodes[1].X_W_hand_least = flat.nodes[1].X_W_hand;
  g.nodes[1].X_WH_least = flat.nodes[1].X_WH;
  const std::vector<graph::Path> paths = {{{0, 1}, 1.0}};
  int replays = 0;
  const std::vector<plan::Candidate> c = CountedCandidates(scene, g, paths, replays);
  REQUIRE(c.size() == 1);
  // The hand's and the held end's poses coincide (one try); the stay of least force is the
  // second, and replays feasible at the asked speed, well within the device.
  CHECK(replays == 2);
  CHECK(c[0].judgement.feasible);
  CHECK(c[0].aim == graph::Aim::kLeastForce);
  CHECK(c[0].tries == 2);
  CHECK(c[0].peak_speed_m_per_s == 0.08);
  CHECK(c[0].judgement.peak_force_N < 1.0);
  CHECK(plan::VerdictText(c[0]).find("(try 2: the held end's poses of least force at 80 mm/s)") !=
        std::string::npos);
}

TEST_CASE(
    "Candidates: an end brought in along the tube lies flat where a slanting reach lands "
    "on its rim",
    "[plan]") {
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/tests/data/scenes/ramp.yaml");
  REQUIRE(loaded.scene);
  const scene::Scene& scene = *loaded.scene;
  // The goal's stay of least force as the explorer found it (`plans --budget 300 --time-limit 0`
  // on this scene): the held end 151 mm out along the ramp's normal n, 42 mm down the slope and
  // 2 mm aside from the origin. The start is 165 mm out, 20 mm the other way aside: a straight
  // reach comes in at 73 deg to n.
  const Eigen::Vector3d n(0.0, -std::sin(kPi / 12.0), std::cos(kPi / 12.0));
  Eigen::Isometry3d X_goal = scene.X_WH_start;
  X_goal.translation() = Eigen::Vector3d(-1.855182e-3, -79.205638e-3, 135.090790e-3);
  const graph::ContactGraph g = StartAndGoal(scene, "{Fe - ramp.top}", X_goal, 0.2);
  const std::vector<graph::Path> paths = {{{0, 1}, 1.0}};
  // The straight reach at the goal's pose: the end meets the ramp moving sideways, lands on its
  // rim and never lies flat.
  const std::vector<Eigen::Isometry3d> straight =
      graph::PathWaypoints(scene, g, paths[0], graph::Aim::kLeastForce);
  const std::vector<Eigen::Isometry3d> along =
      graph::PathWaypoints(scene, g, paths[0], graph::Aim::kAlongAxis);
  REQUIRE(straight.size() == 2);
  REQUIRE(along.size() == 3);
  // Drawn back along the held end's axis by r1 + eps (9 mm), then straight in.
  CHECK((along[1].translation() - (X_goal.translation() + 9e-3 * n)).norm() < 1e-12);
  CHECK(along[1].linear() == X_goal.linear());
  // Only where the end comes to touch: not again into a state whose end touched already, nor
  // into one where only the side does.
  graph::ContactGraph longer = g;
  longer.nodes.push_back(g.nodes[1]);
  longer.nodes[2].cf = "{Fe - ramp.top, Fs - table.top}";
  longer.nodes.push_back(g.nodes[1]);
  longer.nodes[3].cf = "{Fs - table.top}";
  CHECK(graph::PathWaypoints(scene, longer, {{0, 1, 2}, 1.0}, graph::Aim::kAlongAxis).size() == 4);
  CHECK(graph::PathWaypoints(scene, longer, {{0, 3, 2}, 1.0}, graph::Aim::kAlongAxis).size() == 4);
  CHECK(graph::PathWaypoints(scene, longer, {{0, 3}, 1.0}, graph::Aim::kAlongAxis).size() == 2);
  const plan::Judgement slanting = JudgeReach(scene, straight, g.nodes[1].cf);
  INFO(plan::FirstFailure(slanting));
  CHECK_FALSE(slanting.feasible);
  CHECK(plan::FirstFailure(slanting).find("{Fe - ramp.top} never reached") != std::string::npos);
  // The candidate tries the hand's pose (the held end's and the least force's are the same
  // poses) and then the end brought in along the tube, which holds the goal, straight.
  int replays = 0;
  const std::vector<plan::Candidate> c = CountedCandidates(scene, g, paths, replays);
  REQUIRE(c.size() == 1);
  INFO(plan::VerdictText(c[0]));
  CHECK(replays == 2);
  CHECK(c[0].judgement.feasible);
  CHECK(c[0].aim == graph::Aim::kAlongAxis);
  CHECK(c[0].judgement.peak_force_N < 1.0);
  CHECK(plan::VerdictText(c[0]).find("the end brought in along the tube at 80 mm/s") !=
        std::string::npos);
}

TEST_CASE("Candidates: a first reach over the parts goes round the rim a straight one runs into",
          "[plan]") {
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/tests/data/scenes/pocket-beside.yaml");
  REQUIRE(loaded.scene);
  const scene::Scene& scene = *loaded.scene;
  // The goal's stay of least force as the explorer found it (`graph --budget 300 --time-limit 0`
  // on this scene): the tube plumb over the pocket's middle, its held end 151 mm over the floor.
  // The start is 180 mm up, 57 mm aside, the end 10 mm over the walls' tops.
  Eigen::Isometry3d X_goal = scene.X_WH_start;
  X_goal.translation() = Eigen::Vector3d(0.0, 0.0, 0.151);
  const graph::ContactGraph g = StartAndGoal(scene, "{Fe - base.top}", X_goal, 0.006);
  const std::vector<graph::Path> paths = {{{0, 1}, 1.0}};
  const std::vector<Eigen::Isometry3d> straight =
      graph::PathWaypoints(scene, g, paths[0], graph::Aim::kAlongAxis);
  const std::vector<Eigen::Isometry3d> over =
      graph::PathWaypoints(scene, g, paths[0], graph::Aim::kOver);
  REQUIRE(straight.size() == 3);
  REQUIRE(over.size() == 4);
  // Over the goal's pose at the start's height, turned as there; then as the end brought in
  // along the tube.
  CHECK((over[1].translation() - Eigen::Vector3d(0.0, 0.0, 0.180)).norm() < 1e-12);
  CHECK(over[1].linear() == X_goal.linear());
  CHECK(over[2].matrix() == straight[1].matrix());
  CHECK(over[3].matrix() == X_goal.matrix());
  // A first state above the start is gone to straight: no pose over it.
  graph::ContactGraph high = g;
  high.nodes[1].X_WH_least.translation().z() = 0.2;
  CHECK(graph::SamePoses(graph::PathWaypoints(scene, high, paths[0], graph::Aim::kOver),
                         graph::PathWaypoints(scene, high, paths[0], graph::Aim::kAlongAxis)));
  // The straight reach: the end comes down onto the walls' tops and never reaches the floor.
  const plan::Judgement cut = JudgeReach(scene, straight, g.nodes[1].cf);
  INFO(plan::FirstFailure(cut));
  CHECK_FALSE(cut.feasible);
  CHECK(plan::FirstFailure(cut).find("{Fe - base.top} never reached") != std::string::npos);
  // The candidate tries every aim; only the one over the parts holds the goal.
  int replays = 0;
  const std::vector<plan::Candidate> c = CountedCandidates(scene, g, paths, replays);
  REQUIRE(c.size() == 1);
  INFO(plan::VerdictText(c[0]));
  CHECK(c[0].judgement.feasible);
  CHECK(c[0].aim == graph::Aim::kOver);
  CHECK(c[0].judgement.peak_force_N < 0.1);
  CHECK(plan::VerdictText(c[0]).find("over the parts first at 80 mm/s") != std::string::npos);
}

TEST_CASE("Candidates: the explorer's own motion to the goal is a feasible plan",
          "[plan][explore]") {
  // The tube slid under a bar onto the floor beneath: the explorer's aim reaches the goal in its
  // first 40 motions, through states where the tube's end catches the bar's edge and bends.
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/tests/data/scenes/slot.yaml");
  REQUIRE(loaded.scene);
  const scene::Scene& scene = *loaded.scene;
  graph::ExploreOptions explore;
  explore.max_motions = 40;
  explore.jobs = 2;
  const graph::ContactGraph g = graph::Explore(scene, explore);
  REQUIRE(g.goal >= 0);
  const graph::Node& goal = g.nodes[std::size_t(g.goal)];
  plan::CandidateOptions options;
  options.synthesis.peak_speed_m_per_s = explore.speed_m_per_s;
  options.dwell_s = explore.dwell_s;
  options.scene_ref = "slot.yaml";
  const auto as_is = [](const trajectories::Trajectory& t) {
    return std::optional<trajectories::Trajectory>(t);
  };
  const std::optional<plan::Candidate> c = plan::MotionCandidate(scene, g, options, as_is);
  REQUIRE(c);
  INFO(plan::VerdictText(*c));
  CHECK(c->from_motion);
  CHECK(c->judgement.feasible);
  CHECK(c->tries == 1);
  // Its states: from the start to the goal, each once, each a state of the graph.
  REQUIRE(c->plan.states.size() >= 3);
  CHECK(c->plan.states.front() == g.nodes[std::size_t(g.start)].cf);
  CHECK(c->plan.states.back() == goal.cf);
  for (std::size_t i = 0; i < c->plan.states.size(); ++i)
    CHECK(std::count(c->plan.states.begin(), c->plan.states.end(), c->plan.states[i]) == 1);
  CHECK(std::count(c->path.nodes.begin(), c->path.nodes.end(), -1) == 0);
  // At the explorer's speed the hand moves as the explorer's did, tick for tick (every 7th tick
  // compared: the run is about 6000 ticks), up to the middle of the goal's first stay, at or
  // before the witness's tick; then it holds, and the replay ends in the goal.
  core::Core core(scene);
  const std::vector<trajectories::HandSample> hand =
      graph::HandPath(core, g.motions[std::size_t(goal.witness.motion)], goal.witness.tick);
  const std::size_t held = std::size_t(std::lround(options.synthesis.hold_s * 1e3));
  REQUIRE(c->trajectory.samples.size() > held);
  const std::size_t moving = c->trajectory.samples.size() - held;
  REQUIRE(moving <= hand.size());
  for (std::size_t k = 0; k < moving; k += 7) {
    CHECK(c->trajectory.samples[k].t_s == hand[k].t_s);
    CHECK(c->trajectory.samples[k].p_WH_m == hand[k].p_WH_m);
    CHECK(c->trajectory.samples[k].q_WH.angularDistance(hand[k].q_WH) == 0.0);
  }
  CHECK(c->judgement.observed.back().cf == goal.cf);
  // The operator force stays within the explorer's limit, as it did there.
  CHECK(c->judgement.peak_force_N <= graph::ExploreForceLimit(scene, explore));
}

TEST_CASE("Candidates: a run's states to its goal, each loop cut out for good", "[plan]") {
  const auto seen = [](std::initializer_list<const char*> cfs) {
    plan::Judgement j;
    double t_s = 0.0;
    for (const char* cf : cfs) j.observed.push_back({t_s += 0.1, cf});
    return j;
  };
  using States = std::vector<std::string>;
  // Straight there.
  CHECK(plan::StatesToGoal(seen({"A", "B", "G"}), "G") == States{"A", "B", "G"});
  // Back in B: C is cut, and met again after D it is a detour, not a planned state (the judge
  // fails a run that meets a planned state before the one planned ahead of it).
  CHECK(plan::StatesToGoal(seen({"A", "B", "C", "B", "D", "C", "G"}), "G") ==
        States{"A", "B", "D", "G"});
  // Back at the start: everything since is cut.
  CHECK(plan::StatesToGoal(seen({"A", "B", "A", "B", "C", "G", "B"}), "G") ==
        States{"A", "C", "G"});
  // The goal not reached, or the run starting in it: no plan.
  CHECK(plan::StatesToGoal(seen({"A", "B", "C"}), "G").empty());
  CHECK(plan::StatesToGoal(seen({"G", "A"}), "G").empty());
}
