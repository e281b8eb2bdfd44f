// The contact-state graph: pruning against a hand-made graph with known dominance, DOT that
// Graphviz renders and Boost reads back, and exploration of the shipped groove scene checked by
// replaying every witness, by --jobs independence and by independent random motions.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/graphviz.hpp>
#include <catch2/catch.hpp>

#include <tubeplan/graph/completeness.hpp>
#include <tubeplan/graph/dot.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/graph/summary.hpp>
#include <tubeplan/graph/verdicts.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/report/graph_json.hpp>
#include <tubeplan/report/graph_report.hpp>
#include <tubeplan/scene/geometry.hpp>
#include <tubeplan/trajectories/synthesize.hpp>

namespace {

using namespace tubeplan;
using graph::Arc;
using graph::ContactGraph;
using graph::Node;

states::ContactFormation Cf(const char* text) {
  const states::ParseResult parsed = states::ParseContactFormation(text);
  REQUIRE(parsed.cf);
  return *parsed.cf;
}

TEST_CASE("PC changes: one per PC added, removed, re-marked or with one element changed",
          "[graph]") {
  using graph::PcChanges;
  CHECK(PcChanges(Cf("{}"), Cf("{}")) == 0);
  CHECK(PcChanges(Cf("{}"), Cf("{Ee - floor.top}")) == 1);
  CHECK(PcChanges(Cf("{Ee - floor.top}"), Cf("{Ee ~ floor.top}")) == 1);       // re-marked
  CHECK(PcChanges(Cf("{Ee ~ floor.top}"), Cf("{Fe ~ floor.top}")) == 1);       // rim to face
  CHECK(PcChanges(Cf("{Ee - floor.top}"), Cf("{Ee - floor.top_xpos}")) == 1);  // onto the edge
  CHECK(PcChanges(Cf("{}"), Cf("{Fs - floor.top, Fs - left.inner}")) == 2);
  CHECK(PcChanges(Cf("{Ee - floor.top}"), Cf("{Fs u left.inner}")) == 2);  // nothing shared
  CHECK(PcChanges(Cf("{Ee - floor.top, Fs - left.inner}"), Cf("{Fs n left.inner}")) == 2);
}

// A hand-made graph: start A, goal G, and three ways from A with values chosen so that the
// dominance and the scores are known by hand.
ContactGraph HandMade() {
  ContactGraph g;
  auto node = [&](const char* cf, double friction_limit, double energy, double distance) {
    Node n;
    n.cf = cf;
    n.friction_limit_N = friction_limit;
    n.energy_J = energy;
    n.distance_m = distance;
    g.nodes.push_back(n);
    return static_cast<int>(g.nodes.size()) - 1;
  };
  const int a = node("{}", 0.0, 0.0, 0.10);
  const int b = node("{Ee - floor.top}", 1.0, 1.0, 0.05);
  const int c = node("{Ee ~ floor.top}", 2.0, 2.0, 0.06);   // worse than B on every criterion
  const int d = node("{Fe - floor.top}", 0.5, 4.0, 0.05);   // less friction than B, more energy
  const int e = node("{Fs - left.inner}", 0.0, 0.0, 0.20);  // as many steps as A, and further
  const int f = node("{Fs - left.top}", 0.0, 0.0, 0.01);    // no way on to the goal
  const int goal = node("{Fs - floor.top}", 1.0, 0.0, 0.0);
  const int h = node("{Fe ~ left.top}", 0.0, 0.0, 0.01);  // its one way on is further
  g.start = a, g.goal = goal;
  g.nodes[std::size_t(a)].start = g.nodes[std::size_t(goal)].goal = true;
  for (auto [from, to] : std::array<std::pair<int, int>, 11>{{{a, b},
                                                              {a, c},
                                                              {a, d},
                                                              {a, e},
                                                              {a, f},
                                                              {b, goal},
                                                              {c, goal},
                                                              {d, goal},
                                                              {e, b},
                                                              {goal, a},
                                                              {h, b}}}) {
    Arc arc;
    arc.from = from, arc.to = to, arc.count = 1;
    g.arcs.push_back(arc);
  }
  return g;
}

TEST_CASE("Pruning a hand-made graph keeps the undominated arcs towards the goal", "[graph]") {
  ContactGraph g = HandMade();
  graph::PruneWeights w;  // 1, 1, 1
  w.tolerance = 0.0;      // the Pareto front only
  graph::Prune(g, w);
  auto arc = [&](int from, int to) -> const Arc& {
    for (const Arc& a : g.arcs)
      if (a.from == from && a.to == to) return a;
    FAIL("no such arc");
    return g.arcs.front();
  };
  CHECK(arc(0, 1).kept);        // A -> B
  CHECK_FALSE(arc(0, 2).kept);  // A -> C: dominated by A -> B
  CHECK(arc(0, 2).reason ==
        "dominated by -> {Ee - floor.top}: friction 1 <= 2 N, energy change 1 <= 2 J, distance "
        "0.05 <= 0.06 m; score 1.800 > best 1.000 + tolerance (-> {Ee - floor.top})");
  CHECK(arc(0, 3).kept);  // A -> D: less friction than B, more energy: not dominated
  // A -> E: further from the goal by distance, while A has nearer ways.
  CHECK_FALSE(arc(0, 4).kept);
  CHECK(arc(0, 4).reason ==
        "leads away from the goal (200.0 mm and 2 transitions from it, the source 100.0 mm and 2)");
  // H -> B: further by distance, but H has no nearer way and B is a transition nearer.
  CHECK(arc(7, 1).kept);
  CHECK_FALSE(arc(0, 5).kept);  // A -> F: dead end
  CHECK(arc(0, 5).reason == "no path from its target to the goal");
  CHECK_FALSE(arc(6, 0).kept);
  CHECK(arc(6, 0).reason == "leaves the goal");
  for (int from : {1, 2, 3}) CHECK(arc(from, 6).kept);  // the only way on from each
  CHECK(arc(4, 1).kept);

  // Scores by hand: scales f* = 2 N, E* = 4 J, d* = 0.2 m (largest magnitudes over the nodes).
  // A -> B: 1/2 + 1/4 + 0.05/0.2 = 1.0;  A -> C: 1 + 1/2 + 0.3 = 1.8;  A -> D: 0.25 + 1 + 0.25.
  CHECK(graph::ArcScore(g, arc(0, 1), w) == Approx(1.0).epsilon(1e-12));
  CHECK(graph::ArcScore(g, arc(0, 2), w) == Approx(1.8).epsilon(1e-12));
  CHECK(graph::ArcScore(g, arc(0, 3), w) == Approx(1.5).epsilon(1e-12));
  // The dominated A -> C stays when its score is within the tolerance of the best, not beyond.
  w.tolerance = 0.9;
  graph::Prune(g, w);
  CHECK(arc(0, 2).kept);
  w.tolerance = 0.7;
  graph::Prune(g, w);
  CHECK_FALSE(arc(0, 2).kept);
  // Weights move the best: friction 4, energy 0: D scores 4 (0.25) + 0.25 = 1.25, B 2.25, and
  // the dominated C 4.3 is dropped against D.
  w = {4.0, 0.0, 1.0, 0.0};
  graph::Prune(g, w);
  CHECK(arc(0, 1).kept);
  CHECK(arc(0, 3).kept);
  CHECK(arc(0, 2).reason.find("score 4.300 > best 1.250 + tolerance (-> {Fe - floor.top})") !=
        std::string::npos);
}

TEST_CASE("An unreached goal's nearest states: its contacts under other markers first", "[graph]") {
  ContactGraph g;
  auto node = [&](const char* cf, double least_force) {
    Node n;
    n.cf = cf;
    n.min_force_N = least_force;
    g.nodes.push_back(n);
  };
  node("{}", 0.0);
  node("{Fs n post.side, Fs ~ table.top}", 0.5);
  node("{Fs ~ table.top}", 0.1);
  node("{Ee ~ table.top, Fs n post.side}", 0.2);  // the table under the rim, not the side
  node("{Fs u post.side, Fs n table.top}", 0.3);
  // The same elements under other markers, by least force; the rim's state is not among them.
  const std::vector<int> near = graph::NearGoal(g, Cf("{Fs - post.side, Fs - table.top}"), 4);
  CHECK(near == std::vector<int>{4, 1});
  CHECK(graph::NearGoal(g, Cf("{Fs - post.side, Fs - table.top}"), 1) == std::vector<int>{4});
  // No state with the goal's contacts: those touching all its part elements.
  CHECK(graph::NearGoal(g, Cf("{Fe - table.top, Fs - post.side}"), 4) == std::vector<int>{3, 4, 1});
  CHECK(graph::NearGoal(g, Cf("{Fs - shelf.top}"), 4).empty());
  CHECK(graph::NearGoalText(g, Cf("{Fs - post.side, Fs - table.top}"), 4) ==
        "{Fs u post.side, Fs n table.top} (0.3 N), {Fs n post.side, Fs ~ table.top} (0.5 N)");
}

TEST_CASE("Pruning keeps a way from the start to the goal where the heuristics cut them all",
          "[graph]") {
  // A's one arc nearer by distance leads to B, whose one way on is C, whose arc nearer by
  // distance leads back to B: each heuristic, at its node, cuts the ways on (A -> X and
  // C -> D, further by distance), and the kept arcs would circle between B and C.
  ContactGraph g;
  auto node = [&](const char* cf, double distance) {
    Node n;
    n.cf = cf;
    n.distance_m = distance;
    g.nodes.push_back(n);
    return static_cast<int>(g.nodes.size()) - 1;
  };
  const int a = node("{}", 0.10), b = node("{Ee - floor.top}", 0.05);
  const int c = node("{Ee ~ floor.top}", 0.30), d = node("{Fe - floor.top}", 0.40);
  const int x = node("{Fs - left.inner}", 0.15), goal = node("{Fs - floor.top}", 0.0);
  // Z's one way to the goal is back through the start.
  const int z = node("{Fs - right.inner}", 0.50);
  g.start = a, g.goal = goal;
  for (auto [from, to] : std::array<std::pair<int, int>, 8>{
           {{a, b}, {a, x}, {x, goal}, {b, c}, {c, b}, {c, d}, {d, goal}, {z, a}}}) {
    Arc arc;
    arc.from = from, arc.to = to, arc.count = 1;
    g.arcs.push_back(arc);
  }
  graph::Prune(g, graph::PruneWeights{});
  auto kept = [&](int from, int to) {
    for (const Arc& arc : g.arcs)
      if (arc.from == from && arc.to == to) return arc.kept;
    FAIL("no such arc");
    return false;
  };
  // What each heuristic keeps stays kept.
  CHECK(kept(a, b));
  CHECK(kept(b, c));
  CHECK(kept(c, b));
  // A and C had a way to the goal but none along the kept arcs: their arcs one transition nearer
  // the goal are kept back.
  CHECK(kept(a, x));
  CHECK(kept(c, d));
  // None back into the start.
  CHECK_FALSE(kept(z, a));
  // The goal is reached from the start along kept arcs.
  std::vector<bool> reached(g.nodes.size(), false);
  reached[std::size_t(a)] = true;
  for (bool grew = true; grew;) {
    grew = false;
    for (const Arc& arc : g.arcs)
      if (arc.kept && reached[std::size_t(arc.from)] && !reached[std::size_t(arc.to)])
        reached[std::size_t(arc.to)] = grew = true;
  }
  CHECK(reached[std::size_t(goal)]);
}

// Runs a command, returns its exit status and its standard error.
int Run(const std::string& command, std::string& err) {
  const std::string err_file = "graph_test_stderr.txt";
  const int status = std::system((command + " 2> " + err_file).c_str());
  std::ifstream in(err_file);
  std::stringstream s;
  s << in.rdbuf();
  err = s.str();
  std::remove(err_file.c_str());
  return status;
}

// Boost 1.74's read_graphviz cannot read HTML strings at all (even `label=<a>` fails with
// "Unclosed HTML string"; Graphviz reads them), so the structure check swaps each HTML label for
// the quoted string "html" first. The file as written is what the Graphviz check renders.
std::string WithoutHtmlLabels(const std::string& dot) {
  std::string out;
  for (std::size_t i = 0; i < dot.size();) {
    if (dot.compare(i, 7, "label=<") != 0) {
      out += dot[i++];
      continue;
    }
    std::size_t j = i + 6;  // at the opening '<'
    for (int depth = 0; j < dot.size(); ++j) {
      if (dot[j] == '<') ++depth;
      if (dot[j] == '>' && --depth == 0) break;
    }
    out += "label=\"html\"";
    i = j + 1;
  }
  return out;
}

TEST_CASE("DOT renders with Graphviz without warnings and reads back into Boost", "[graph]") {
  ContactGraph g = HandMade();
  graph::PruneWeights w;
  w.tolerance = 0.6;  // A -> B and A -> D both kept (scores 1.0 and 1.5, above)
  graph::Prune(g, w);
  for (const bool unpruned : {true, false}) {
    graph::DotOptions options;
    options.dropped_arcs = unpruned;
    options.title = "hand-made \"graph\"";
    const std::string dot = graph::FormatDot(g, options);
    {
      std::ofstream out("graph_test.dot");
      out << dot;
    }
    std::string err;
    CHECK(Run("dot -Tsvg graph_test.dot -o graph_test.svg", err) == 0);
    CHECK(err.empty());
    std::remove("graph_test.dot");
    std::remove("graph_test.svg");

    boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS,
                          boost::property<boost::vertex_name_t, std::string>,
                          boost::property<boost::edge_name_t, std::string>>
        read;
    boost::dynamic_properties dp(boost::ignore_other_properties);
    dp.property("node_id", boost::get(boost::vertex_name, read));
    std::istringstream in(WithoutHtmlLabels(dot));
    REQUIRE(boost::read_graphviz(in, read, dp));
    // Unpruned: all 8 nodes and 11 arcs. Pruned: the nodes on a kept way from A to G (A, B, D,
    // G) and the kept arcs among them (A->B, A->D, B->G, D->G).
    CHECK(boost::num_vertices(read) == (unpruned ? 8u : 4u));
    CHECK(boost::num_edges(read) == (unpruned ? 11u : 4u));
  }
}

TEST_CASE("Batch verdicts colour the arcs replays went along and add what they saw", "[graph]") {
  ContactGraph g = HandMade();
  graph::Prune(g, graph::PruneWeights{});
  graph::ReplayedPlan ok;  // {} -> goal, feasible, through B
  ok.transitions = {{"{}", "{Fs - floor.top}", true, 0.0, 3.0}};
  ok.observed = {{0.0, "{}"}, {1.0, "{Ee - floor.top}"}, {2.0, "{Fs - floor.top}"}};
  graph::ReplayedPlan bad;  // {} -> F planned, infeasible; the replay met a state never explored
  bad.transitions = {{"{}", "{Fs - left.top}", false, 0.0, 2.0}};
  bad.observed = {{0.0, "{}"}, {1.5, "{Fs u right.inner}"}};
  CHECK(graph::ApplyVerdicts(g, {ok, bad}) == 1);
  auto arc = [&](const std::string& from, const std::string& to) -> const Arc& {
    for (const Arc& a : g.arcs)
      if (g.nodes[std::size_t(a.from)].cf == from && g.nodes[std::size_t(a.to)].cf == to) return a;
    FAIL("no arc " << from << " -> " << to);
    return g.arcs.front();
  };
  CHECK(arc("{}", "{Ee - floor.top}").batch == graph::BatchResult::kFeasible);
  CHECK(arc("{Ee - floor.top}", "{Fs - floor.top}").batch == graph::BatchResult::kFeasible);
  CHECK(arc("{}", "{Fs - left.top}").batch == graph::BatchResult::kInfeasible);  // as planned
  const Arc& seen = arc("{}", "{Fs u right.inner}");
  CHECK(seen.batch == graph::BatchResult::kInfeasible);
  CHECK(seen.from_replay);
  CHECK(g.nodes.back().cf == "{Fs u right.inner}");
  CHECK(g.nodes.back().from_replay);
  CHECK(arc("{}", "{Ee ~ floor.top}").batch == graph::BatchResult::kUntried);
  // The coloured graph renders without a warning, pruned and unpruned.
  for (const bool unpruned : {false, true}) {
    graph::DotOptions options;
    options.dropped_arcs = unpruned;
    {
      std::ofstream out("graph_test_verdicts.dot");
      out << graph::FormatDot(g, options);
    }
    std::string err;
    CHECK(Run("dot -Tsvg graph_test_verdicts.dot -o graph_test_verdicts.svg", err) == 0);
    CHECK(err.empty());
    std::remove("graph_test_verdicts.dot");
    std::remove("graph_test_verdicts.svg");
  }
}

TEST_CASE("The paper's notation in DOT labels", "[graph]") {
  CHECK(graph::PaperNotation("{}") == "&#8709;");
  CHECK(graph::PaperNotation("{Fe ~ left.inner}") == "F&#771;<SUB>e</SUB> &#8211; left.inner");
  CHECK(graph::PaperNotation("{Fs u left.top_inner, Fe - floor.top}") ==
        "F<SUB>e</SUB> &#8211; floor.top<BR/>F<SUB>s</SUB> &#8995; left.top_inner");
  CHECK(graph::PaperNotation("{Fs n floor.top}") == "F<SUB>s</SUB> &#8994; floor.top");
}

scene::Scene Groove() {
  io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/groove.yaml");
  REQUIRE(loaded.scene);
  return *loaded.scene;
}

// The groove's floor alone: the same kinds of states as the groove (ends and sides on faces and
// edges, stuck and sliding, the rod and the elastica) in fewer of them (~55 against ~270).
scene::Scene FloorOnly() {
  scene::Scene floor = Groove();
  floor.parts.resize(1);
  REQUIRE(floor.parts[0].name == "floor");
  return floor;
}

// The scene the exploration tests explore: the floor alone runs the same code as the groove
// (every kind of motion, probes to saturation, refinements, resumed runs), sooner.
scene::Scene ExploredScene() { return FloorOnly(); }

// A small exploration, shared by the tests below (it costs seconds).
const ContactGraph& SmallGraph(int jobs) {
  static std::map<int, ContactGraph> graphs;
  if (!graphs.contains(jobs)) {
    graph::ExploreOptions o;
    o.random_motions = 5;
    o.max_motions = 110;  // the sweeps and aims, 5 random motions, probes and their replays
    o.jobs = jobs;
    graphs[jobs] = graph::Explore(ExploredScene(), o);
  }
  return graphs[jobs];
}

// The exploration with the library's default options, as `tubeplan graph scenes/groove.yaml
// --time-limit 0` runs it.
const ContactGraph& DefaultGraph(int jobs) {
  static std::map<int, ContactGraph> graphs;
  if (!graphs.contains(jobs)) {
    graph::ExploreOptions o;
    o.jobs = jobs;
    graphs[jobs] = graph::Explore(ExploredScene(), o);
  }
  return graphs[jobs];
}

// Two explorations give the same graph: motions, nodes, witnesses and arcs.
void CheckSameGraph(const ContactGraph& a, const ContactGraph& b) {
  CHECK(a.saturated == b.saturated);
  CHECK(a.closing_rounds == b.closing_rounds);
  CHECK(a.probed == b.probed);
  CHECK(a.ticks == b.ticks);
  REQUIRE(a.motions.size() == b.motions.size());
  for (std::size_t i = 0; i < a.motions.size(); ++i) CHECK(a.motions[i].kind == b.motions[i].kind);
  REQUIRE(a.nodes.size() == b.nodes.size());
  REQUIRE(a.arcs.size() == b.arcs.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    CHECK(a.nodes[i].cf == b.nodes[i].cf);
    CHECK(a.nodes[i].ticks == b.nodes[i].ticks);
    CHECK(a.nodes[i].witness.motion == b.nodes[i].witness.motion);
    CHECK(a.nodes[i].witness.tick == b.nodes[i].witness.tick);
    CHECK(a.nodes[i].energy_J == b.nodes[i].energy_J);
    // The stays of least force choose what the closing rounds replay.
    CHECK(a.nodes[i].min_force_N == b.nodes[i].min_force_N);
    CHECK(a.nodes[i].X_WH_least.matrix() == b.nodes[i].X_WH_least.matrix());
  }
  for (std::size_t i = 0; i < a.arcs.size(); ++i) {
    CHECK(a.arcs[i].from == b.arcs[i].from);
    CHECK(a.arcs[i].to == b.arcs[i].to);
    CHECK(a.arcs[i].count == b.arcs[i].count);
    CHECK(a.arcs[i].simultaneous == b.arcs[i].simultaneous);
  }
}

TEST_CASE("Random motions tip and swing a tube that starts plumb", "[graph]") {
  // The shipped pocket's tube hangs plumb: no level direction square to it to tip about, and
  // a turn about up leaves it where it is. Its random motions tip it -5..30 deg and swing it
  // +-8 deg as they do a level tube, about two level directions square to each other.
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/pocket.yaml");
  REQUIRE(loaded.scene);
  const scene::Scene& s = *loaded.scene;
  const Eigen::Vector3d axis0 = s.X_WH_start.linear().col(2);
  REQUIRE(axis0.z() < -0.999999);
  double most_deg = 0.0;
  Eigen::Vector2d spread_lo(0.0, 0.0), spread_hi(0.0, 0.0);
  for (const graph::Motion& m : graph::RandomMotions(s, 7, 0, 60, graph::ExploreOptions{})) {
    for (const graph::Move& move : m.moves) {
      const Eigen::Vector3d axis = move.q_W * Eigen::Vector3d::UnitZ();
      most_deg = std::max(
          most_deg, std::acos(std::clamp(axis.dot(axis0), -1.0, 1.0)) * 180.0 / std::numbers::pi);
      spread_lo = spread_lo.cwiseMin(axis.head<2>());
      spread_hi = spread_hi.cwiseMax(axis.head<2>());
    }
  }
  // Up to the 30 deg tip and the 8 deg swing together (sqrt(30^2 + 8^2) = 31 deg); of some 170
  // turns drawn uniformly, one within the top third of the tip's range is all but certain.
  CHECK(most_deg > 20.0);
  CHECK(most_deg < 31.1);
  // The end turned both ways in both level directions (the tip reaches -5 deg, the swing
  // +-8 deg): by more than sin 3 deg off plumb each way.
  for (int i = 0; i < 2; ++i) {
    INFO("level direction " << i);
    CHECK(spread_lo[i] < -0.052);
    CHECK(spread_hi[i] > 0.052);
  }
}

TEST_CASE("A motion's prefix puts the core where the motion had it, bit for bit",
          "[graph][explore]") {
  const scene::Scene s = Groove();
  const graph::ExploreOptions o;
  core::Core core(s), again(s);
  for (const graph::Motion& m : graph::RandomMotions(s, 99, 0, 3, o)) {
    core.Reset(s.X_WH_start);
    graph::MotionRunner runner(m, s.X_WH_start, s.model.time_step_s);
    for (int k = 1; !runner.Done(); ++k) {
      core.Step(k * s.model.time_step_s, runner.Next(core.last()));
      if (k % 397 != 0) continue;
      // The prefix with a move appended: identical up to tick k, then the new move.
      graph::Motion cut;
      cut.moves = graph::Prefix(m, runner.move(), runner.move_tick());
      graph::Move away;
      away.p_W_m = core.last().X_W_hand.translation() + Eigen::Vector3d(0.0, 0.0, 0.02);
      cut.moves.push_back(away);
      INFO("tick " << k);
      graph::ReplayTo(again, cut, graph::TickRef{0, k, 0, 0});
      CHECK(again.last().X_W_hand.translation() == core.last().X_W_hand.translation());
      CHECK(again.last().X_WH.translation() == core.last().X_WH.translation());
      CHECK(again.last().energy_J == core.last().energy_J);
      CHECK(again.FormationText() == core.FormationText());
      // The tick after: the appended move starts from where the hand was.
      const Eigen::Vector3d p = again.last().X_W_hand.translation();
      graph::ReplayTo(again, cut, graph::TickRef{0, k + 1, 0, 0});
      const Eigen::Vector3d step = again.last().X_W_hand.translation() - p;
      CHECK(step.z() > 0.0);
      CHECK(step.head<2>().norm() < 1e-12);
    }
  }
}

TEST_CASE("A relative move goes on from where a guard stopped the move before",
          "[graph][explore]") {
  const scene::Scene s = Groove();
  // Straight down, far below the floor's top, until the floor pushes back with 1 N; then 10 mm
  // across from there, and 10 mm further kept inside a box that ends 4 mm on.
  const Eigen::Vector3d p0 = s.X_WH_start.translation();
  const Eigen::Quaterniond q0(s.X_WH_start.linear());
  graph::Motion m;
  graph::Move down;
  down.p_W_m = p0 - Eigen::Vector3d(0.0, 0.0, 0.2);
  down.q_W = q0;
  down.speed_m_per_s = 0.05;
  down.guard_dir_W = Eigen::Vector3d::UnitZ();
  down.guard_N = 1.0;
  graph::Move across = down;
  across.relative = true;
  across.p_W_m = Eigen::Vector3d(0.01, 0.0, 0.0);
  across.guard_N = 0.0;
  graph::Move clamped = across;
  clamped.within_W = Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1.0),
                                         Eigen::Vector3d(p0.x() + 0.014, 1.0, 1.0));
  m.moves = {down, across, clamped};
  core::Core core(s);
  core.Reset(s.X_WH_start);
  graph::MotionRunner runner(m, s.X_WH_start, s.model.time_step_s);
  std::array<Eigen::Vector3d, 3> end_of{};
  for (int k = 1; !runner.Done(); ++k) {
    const Eigen::Isometry3d X = runner.Next(core.last());
    if (runner.Done()) break;
    end_of[std::size_t(runner.move())] = X.translation();
    core.Step(k * s.model.time_step_s, X);
  }
  // The guard stopped the descent on the floor, far above its target.
  CHECK(end_of[0].z() > down.p_W_m.z() + 0.1);
  CHECK(end_of[0].z() < p0.z());
  // Across from there at that height, not on towards the descent's target.
  CHECK((end_of[1] - end_of[0] - across.p_W_m).norm() < 1e-12);
  // The last move stopped at the box's side, 4 mm on.
  CHECK(end_of[2].x() == Approx(p0.x() + 0.014).margin(1e-12));
  CHECK(end_of[2].z() == end_of[0].z());
}

TEST_CASE("Sweeps over a round rail stay within the explorer's force limit", "[graph][explore]") {
  // Lowered onto the rail until it pushes back, a sweep's slides go on from there: none plunges
  // on towards its lowering's target until the operator force passes half the device's.
  io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/rail.yaml");
  REQUIRE(loaded.scene);
  graph::ExploreOptions o;
  o.random_motions = 0;
  o.max_motions = 50;  // the sweeps: two tilts at 25 lateral offsets
  const ContactGraph g = graph::Explore(*loaded.scene, o);
  REQUIRE(g.motions.size() == 50);
  for (const graph::Motion& m : g.motions) REQUIRE(m.kind == "sweep");
  CHECK(g.held_back == 0);
  CHECK(std::any_of(g.nodes.begin(), g.nodes.end(),
                    [](const Node& n) { return n.cf.find("rail.side") != std::string::npos; }));
}

TEST_CASE("Every node's witness, replayed through the core, gives that node's CF",
          "[graph][explore]") {
  const scene::Scene s = ExploredScene();
  const ContactGraph& g = SmallGraph(2);
  REQUIRE(g.nodes.size() > 20);
  CHECK(g.goal >= 0);
  CHECK(g.nodes[std::size_t(g.start)].cf == "{}");
  // Some witnesses are in probe motions, which replay another motion's prefix first.
  CHECK(std::any_of(g.nodes.begin(), g.nodes.end(), [&](const Node& n) {
    return g.motions[std::size_t(n.witness.motion)].prefix_ticks > 0;
  }));
  core::Core core(s);
  for (const Node& n : g.nodes) {
    INFO(n.cf << " witness motion " << n.witness.motion << " tick " << n.witness.tick);
    graph::ReplayTo(core, g.motions[std::size_t(n.witness.motion)], n.witness);
    CHECK(core.FormationText() == n.cf);
    // The witness data is the core's at that tick (the same bits: the core is deterministic).
    CHECK(core.last().energy_J == n.energy_J);
    CHECK(core.last().X_WH.translation() == n.X_WH.translation());
    CHECK(core.last().force_W_N.norm() == n.force_N);
    // Within half the device's force wherever some stay of the node was.
    CHECK(n.min_force_N <= n.force_N);
    if (n.min_force_N <= 0.5 * s.device.max_force_N) CHECK(n.force_N <= 0.5 * s.device.max_force_N);
  }
  // Every arc's witness tick is in the arc's target CF... except where the core re-entered the
  // source within the dwell time; the first tick of the target must at least exist.
  for (const Arc& a : g.arcs) CHECK(a.witness.tick >= 1);
}

TEST_CASE("Resuming runs from snapshots explores the same graph as replaying them",
          "[graph][explore]") {
  // Probes of nodes that probes found start from stays those probes found, whose runs were
  // themselves resumed: the chain the snapshots cut short. Against the explorer replaying every
  // prefix and every refinement from the motion's start (an independent path to the same bits).
  // The groove's floor alone, explored until it probes nodes that probes found.
  const scene::Scene floor = FloorOnly();
  graph::ExploreOptions o;
  o.random_motions = 0;
  // Probing alone: closing rounds resume their runs the same way and would only add time.
  o.closing_motions = 0;
  o.replay_copies = 0;
  // The sweeps and aims (45 motions), a probe of each node they found (34) and some more.
  o.max_motions = 90;
  o.jobs = 2;
  const ContactGraph resumed = graph::Explore(floor, o);
  o.resume_runs = false;
  const ContactGraph replayed = graph::Explore(floor, o);
  // The budget reaches the probes of nodes that probes found: more motions than the sweeps and
  // aims and a probe for every node they found.
  const std::size_t before_probes = std::size_t(
      std::count_if(resumed.motions.begin(), resumed.motions.end(),
                    [](const graph::Motion& m) { return m.kind.rfind("probe", 0) != 0; }));
  REQUIRE(resumed.motions.size() >
          before_probes + std::size_t(resumed.saturation[before_probes - 1].nodes));
  REQUIRE(resumed.nodes.size() == replayed.nodes.size());
  REQUIRE(resumed.arcs.size() == replayed.arcs.size());
  for (std::size_t i = 0; i < resumed.nodes.size(); ++i) {
    const Node &a = resumed.nodes[i], &b = replayed.nodes[i];
    CHECK(a.cf == b.cf);
    CHECK(a.ticks == b.ticks);
    CHECK(a.witness.motion == b.witness.motion);
    CHECK(a.witness.tick == b.witness.tick);
    CHECK(a.energy_J == b.energy_J);
    CHECK(a.X_WH.translation() == b.X_WH.translation());
  }
  for (std::size_t i = 0; i < resumed.arcs.size(); ++i) {
    const Arc &a = resumed.arcs[i], &b = replayed.arcs[i];
    CHECK(a.from == b.from);
    CHECK(a.to == b.to);
    CHECK(a.count == b.count);
    CHECK(a.simultaneous == b.simultaneous);
    CHECK(a.witness.tick == b.witness.tick);
  }
  CHECK(resumed.refinements == replayed.refinements);
  // And it is the point: fewer ticks run.
  WARN("ticks resumed " << resumed.ticks << ", replayed " << replayed.ticks << "; "
                        << resumed.nodes.size() << " nodes, " << resumed.motions.size()
                        << " motions, " << before_probes << " before probing");
  CHECK(resumed.ticks < replayed.ticks);
}

TEST_CASE("A replayed trajectory puts the hand on it at every move's end", "[graph][motion]") {
  const scene::Scene s = Groove();
  const double T = s.model.time_step_s;
  Eigen::Isometry3d to = s.X_WH_start;
  to.translation() += Eigen::Vector3d(0.02, 0.0, -0.03);
  to.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix() * to.linear();
  const std::array<Eigen::Isometry3d, 2> waypoints = {s.X_WH_start, to};
  const trajectories::Trajectory t =
      trajectories::SynthesizeTrajectory(waypoints, trajectories::SynthesisOptions{});
  const std::vector<trajectories::HandSample> ticks = trajectories::Resample(t, T);
  const graph::Motion m = graph::MotionAlong(t, T, 20, 0.08, "replay");
  CHECK(m.kind == "replay");
  // The start is the trajectory's first pose: no move to it takes time; then one move per 20
  // ticks, the last one shorter.
  REQUIRE(m.moves.size() == 1 + (ticks.size() - 1 + 19) / 20);
  graph::MotionRunner runner(m, s.X_WH_start, T);
  core::StepOutput rest;
  std::size_t k = 0;
  double chord_m = 0.0;
  while (!runner.Done()) {
    const Eigen::Isometry3d X = runner.Next(rest);
    if (runner.Done()) break;
    ++k;
    const trajectories::HandSample& want = ticks[std::min(k - 1, ticks.size() - 1)];
    chord_m = std::max(chord_m, (X.translation() - want.p_WH_m).norm());
    if ((k - 1) % 20 == 0 || k == ticks.size()) {
      INFO("tick " << k);
      CHECK((X.translation() - want.p_WH_m).norm() < 1e-12);
      CHECK(Eigen::Quaterniond(X.linear()).angularDistance(want.q_WH) < 1e-9);
    }
  }
  // The first tick holds the start (a move to where the hand is), then one tick per sample.
  CHECK(k == ticks.size());
  // Between, the hand is on the chord: within 0.05 mm of the trajectory (the explorer's bound
  // for its quickest reach; this one's peak acceleration gives about 0.015 mm).
  CHECK(chord_m < 5e-5);
  CHECK(chord_m > 1e-6);
}

TEST_CASE("The floor's default exploration saturates and closes", "[graph][explore]") {
  // One exploration, shared by the sections.
  SECTION("The default exploration saturates within the default budget") {
    const ContactGraph& g = DefaultGraph(2);
    // Every node probed, the last closing round found no new one.
    CHECK(g.saturated);
    CHECK(g.probed == static_cast<int>(g.nodes.size()));
    CHECK(g.motions.size() < std::size_t(graph::ExploreOptions{}.max_motions));
    WARN("default exploration: " << g.nodes.size() << " CFs, " << g.arcs.size() << " transitions, "
                                 << g.motions.size() << " motions, " << g.ticks << " ticks; "
                                 << g.seconds << " s on 2 threads");
  }

  SECTION("Probing starts on the candidate plans' paths, each group followed by their replays") {
    const scene::Scene s = ExploredScene();
    const ContactGraph& g = DefaultGraph(2);
    std::size_t first_probe = 0;
    while (first_probe < g.motions.size() && !g.motions[first_probe].kind.starts_with("probe "))
      ++first_probe;
    REQUIRE(first_probe < g.motions.size());
    // The graph as probing started: the same exploration, its budget ending there. Its cheapest
    // paths, pruned as `plans` prunes: their states are the first probed, path by path, in order.
    graph::ExploreOptions o;
    o.jobs = 2;
    o.max_motions = static_cast<int>(first_probe);
    ContactGraph before = graph::Explore(s, o);
    REQUIRE(before.goal >= 0);
    const graph::PruneWeights w{s.heuristics.friction, s.heuristics.energy, s.heuristics.distance,
                                s.heuristics.tolerance};
    graph::Prune(before, w);
    std::vector<std::string> on_paths;
    for (const graph::Path& p :
         graph::KShortestPaths(before, graph::ArcCosts(before, w), o.replay_paths))
      for (const int n : p.nodes)
        if (std::find(on_paths.begin(), on_paths.end(), before.nodes[std::size_t(n)].cf) ==
            on_paths.end())
          on_paths.push_back(before.nodes[std::size_t(n)].cf);
    REQUIRE(on_paths.size() >= 2);
    for (std::size_t i = 0; i < std::min<std::size_t>(on_paths.size(), 16); ++i)
      CHECK(g.motions[first_probe + i].kind == "probe " + on_paths[i]);
    // Up to the first closing round: groups of at most 16 probes, each followed by perturbed
    // copies of every candidate plan.
    int groups = 0;
    std::size_t i = first_probe;
    while (i < g.motions.size() && g.motions[i].kind.starts_with("probe ")) {
      std::size_t probes = 0, replays = 0;
      for (; i < g.motions.size() && g.motions[i].kind.starts_with("probe "); ++i) ++probes;
      for (; i < g.motions.size() && g.motions[i].kind == "replay"; ++i) ++replays;
      CHECK(probes <= 16);
      CHECK(replays > 0);
      CHECK(replays % std::size_t(o.replay_copies) == 0);
      ++groups;
    }
    CHECK(groups >= 2);
    REQUIRE(i < g.motions.size());
    CHECK(g.motions[i].kind == "random");
  }

  SECTION("Closing rounds go on until one adds no state and no transition") {
    const ContactGraph& g = DefaultGraph(2);
    const graph::ExploreOptions o;
    const int round = o.closing_motions;
    REQUIRE(g.saturated);
    REQUIRE(g.closing_rounds >= 1);
    // The last round's motions (nothing new: no probes after them) are the graph's last ones: its
    // random motions, then its perturbed replays of each candidate plan, aimed up to three ways,
    // and of the explorer's motion to the goal, of the graph as the round started.
    std::size_t replays = 0;
    while (replays < g.motions.size() && g.motions[g.motions.size() - 1 - replays].kind == "replay")
      ++replays;
    CHECK(replays > 0);
    CHECK(replays % std::size_t(o.replay_copies) == 0);
    CHECK(replays <= std::size_t((3 * o.replay_paths + 1) * o.replay_copies));
    const std::size_t last = g.saturation.size() - replays;
    REQUIRE(last > std::size_t(round));
    const graph::SaturationPoint& before = g.saturation[last - 1 - std::size_t(round)];
    CHECK(before.nodes == static_cast<int>(g.nodes.size()));
    CHECK(before.arcs == static_cast<int>(g.arcs.size()));
    for (std::size_t i = last - std::size_t(round); i < last; ++i)
      CHECK(g.motions[i].kind == "random");
    // The random motions are the exploration's own and `round` per closing round, each round whole.
    int random = 0;
    for (const graph::Motion& m : g.motions) random += m.kind == "random";
    CHECK(random == graph::ExploreOptions{}.random_motions + round * g.closing_rounds);
  }

  SECTION("Perturbed replays of the candidate plans stay inside the explored graph") {
    const scene::Scene s = ExploredScene();
    const graph::ExploreOptions o;
    const ContactGraph& g = DefaultGraph(2);
    // The explorer's own replays, run again as the check runs motions: every state they kept
    // for the dwell, and every transition between two such states, was merged into the graph.
    std::vector<graph::Motion> own;
    for (const graph::Motion& m : g.motions)
      if (m.kind == "replay") own.push_back(m);
    REQUIRE(own.size() >= std::size_t(2 * o.replay_copies));
    const graph::Completeness mine =
        graph::CheckCompleteness(s, g, own, o.dwell_s, graph::ExploreForceLimit(s, o));
    CHECK(mine.states_seen >= 3);
    CHECK(mine.states_in_graph == mine.states_seen);
    CHECK(mine.transitions_in_graph == mine.transitions_seen);

    // The completeness check's second measure: replays of another seed, counted after the same
    // dwell. Offsets of up to 4 mm near the floor's edge reach rare states the explorer's own
    // copies did not (the end on the top and the side face at once); the share by use, the ticks
    // an operator following the plans spends in states the graph has, must stay high.
    const std::vector<graph::Completeness> found = graph::CheckCompleteness(s, g, o, 24);
    REQUIRE(found.size() == 2);
    const graph::Completeness& c = found[1];
    CHECK(c.motions_of == "perturbed candidate replays");
    CHECK(c.motions >= 24);
    for (const std::string& n : c.missing_states) UNSCOPED_INFO("CF not in the graph: " << n);
    CHECK(c.states_seen >= 3);
    CHECK(double(c.ticks_in_graph) >= 0.95 * double(c.ticks));

    // The trajectories replayed: one per candidate plan's aim, then the explorer's own motion to
    // the goal, up to the goal's witness tick (sample 0 is the start pose), retimed on the
    // scene's step within the explorer's speed: from the same start to the same end.
    const std::vector<trajectories::Trajectory> nominals = graph::CandidateTrajectories(s, g, o);
    const std::vector<trajectories::HandSample> path = graph::GoalMotionPath(s, g);
    const int goal = g.FindNode(states::ToString(s.goal));
    REQUIRE(goal >= 0);
    REQUIRE(path.size() >= 2);
    CHECK(path.size() == std::size_t(g.nodes[std::size_t(goal)].witness.tick) + 1);
    CHECK(nominals.size() == graph::CandidateWaypoints(s, g, o).size() + 1);
    CHECK((nominals.back().samples.front().p_WH_m - path.front().p_WH_m).norm() < 1e-12);
    CHECK((nominals.back().samples.back().p_WH_m - path.back().p_WH_m).norm() < 1e-12);
    CHECK(nominals.back().samples.back().t_s >= path.back().t_s);
    CHECK(nominals.back().samples[1].t_s == Approx(s.model.time_step_s).epsilon(1e-9));
    CHECK(trajectories::PeakSpeed(nominals.back().samples) <= o.speed_m_per_s * (1.0 + 1e-6));

    // Without a goal there is no plan to replay.
    CHECK(graph::CandidateWaypoints(s, graph::ContactGraph{}, o).empty());
    CHECK(graph::CandidateTrajectories(s, graph::ContactGraph{}, o).empty());
    CHECK(graph::GoalMotionPath(s, graph::ContactGraph{}).empty());

    // The printout says the goal was reached, and only in passing where no stay of it counted.
    const auto reach_line = [&](const ContactGraph& shown) {
      std::ostringstream out;
      report::PrintGraph(out, "floor.yaml", s, shown, o, "", {}, {});
      std::string line;
      for (std::istringstream in(out.str()); std::getline(in, line);)
        if (line.rfind("start ", 0) == 0) return line;
      return std::string();
    };
    CHECK(reach_line(g) == "start {}; goal " + states::ToString(s.goal) + " reached");
    ContactGraph passed = g;
    passed.nodes[std::size_t(goal)].ticks = 0;
    CHECK(reach_line(passed) == "start {}; goal " + states::ToString(s.goal) +
                                    " reached only in passing (no stay of it lasted the dwell)");
  }

  SECTION("The graph's JSON keeps the moves of the motions its witnesses lie in") {
    const scene::Scene s = ExploredScene();
    const ContactGraph& g = DefaultGraph(2);
    const nlohmann::json j =
        report::GraphToJson(g, s, "floor.yaml", graph::ExploreOptions{}, graph::PruneWeights{});
    // The layout docs/graph.md describes.
    CHECK(j["tubeplan_graph"] == 2);
    std::set<int> witnessed;
    for (const Node& n : g.nodes) witnessed.insert(n.witness.motion);
    for (const graph::Arc& a : g.arcs) witnessed.insert(a.witness.motion);
    REQUIRE(j["motions"].size() == g.motions.size());
    std::size_t bare = 0;
    for (std::size_t i = 0; i < g.motions.size(); ++i) {
      const nlohmann::json& m = j["motions"][i];
      CHECK(m["kind"] == g.motions[i].kind);
      if (witnessed.contains(static_cast<int>(i))) {
        REQUIRE(m.contains("moves"));
        CHECK(m["moves"].size() == g.motions[i].moves.size());
      } else {
        CHECK(!m.contains("moves"));
        ++bare;
      }
    }
    // A motion holds a witness only where it had a state's or a transition's longest stay: most
    // of the closing rounds' motions, which found nothing new, hold none.
    CHECK(bare >= std::size_t(graph::ExploreOptions{}.closing_motions));
  }

  SECTION("Independent random motions stay inside the explored graph") {
    // Motions from another seed, run through the core by the completeness check (a CF counts
    // after the same 20 ms dwell), against the graph explored with the default options.
    const scene::Scene s = ExploredScene();
    const graph::ExploreOptions o;
    const ContactGraph& g = DefaultGraph(2);
    const std::vector<graph::Motion> motions = graph::RandomMotions(s, 1234567, 0, 30, o);
    const graph::Completeness c =
        graph::CheckCompleteness(s, g, motions, o.dwell_s, graph::ExploreForceLimit(s, o));
    for (const std::string& n : c.missing_states) UNSCOPED_INFO("CF not in the graph: " << n);
    for (const auto& [a, taken] : c.missing_transitions)
      UNSCOPED_INFO("transition not in the graph: "
                    << a.first << " -> " << a.second << " ("
                    << graph::PcChanges(Cf(a.first.c_str()), Cf(a.second.c_str()))
                    << " PC changes), taken " << taken << " times");
    const double tick_coverage = double(c.ticks_in_graph) / double(c.ticks);
    const double taken_coverage = double(c.taken_in_graph) / double(c.taken);
    WARN("coverage of 30 independent random motions: CFs "
         << c.states_in_graph << "/" << c.states_seen << ", transitions " << c.transitions_in_graph
         << "/" << c.transitions_seen << "; by use: ticks " << 100.0 * tick_coverage
         << " %, transitions taken " << c.taken_in_graph << "/" << c.taken << " ("
         << 100.0 * taken_coverage << " %)");
    // The counts are the lists' (the report is consistent).
    CHECK(c.states_seen - c.states_in_graph == long(c.missing_states.size()));
    CHECK(c.transitions_seen - c.transitions_in_graph == long(c.missing_transitions.size()));
    CHECK(c.states_seen >= 3);
    // The exploration saturates (every CF it found was probed, docs/graph.md), yet probes from
    // one stay per node miss rare states (a tip hooked under the floor's edge with the side on its
    // top). On the floor alone these motions reach only a handful of CFs, so one rare miss moves
    // the CF share by 15 %: the counts allow one missed CF, and the shares by use (ticks spent,
    // transitions taken) must stay high, so that an exploration missing common states fails.
    CHECK(c.states_in_graph + 1 >= c.states_seen);
    CHECK(tick_coverage >= 0.99);
    CHECK(taken_coverage >= 0.95);
  }
}

}  // namespace

TEST_CASE("An exploration is the same on one thread and on two", "[graph][explore]") {
  SECTION("Sweeps, aims, random motions and probes with refinements: the floor") {
    REQUIRE(SmallGraph(1).refinements > 0);
    CheckSameGraph(SmallGraph(1), SmallGraph(2));
  }
  SECTION("Saturation, then closing rounds with perturbed replays: the rail's default") {
    io::SceneLoadResult loaded =
        io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/rail.yaml");
    REQUIRE(loaded.scene);
    graph::ExploreOptions o;
    o.jobs = 1;
    const ContactGraph one = graph::Explore(*loaded.scene, o);
    o.jobs = 2;
    const ContactGraph two = graph::Explore(*loaded.scene, o);
    REQUIRE(one.saturated);
    REQUIRE(one.closing_rounds >= 1);
    REQUIRE(std::any_of(one.motions.begin(), one.motions.end(),
                        [](const graph::Motion& m) { return m.kind == "replay"; }));
    CheckSameGraph(one, two);
  }
}

TEST_CASE("The budget bounds the motions exactly, the same on any number of threads",
          "[graph][explore]") {
  // The groove's sweeps are 14 motions: a budget of 1 cuts them, one of 20 cuts the aims.
  for (const int budget : {1, 20}) {
    graph::ExploreOptions o;
    o.max_motions = budget;
    o.jobs = 1;
    const ContactGraph one = graph::Explore(FloorOnly(), o);
    o.jobs = 2;
    const ContactGraph two = graph::Explore(FloorOnly(), o);
    CHECK(one.motions.size() == std::size_t(budget));
    CHECK(one.saturation.size() == std::size_t(budget));
    CHECK(one.end == graph::ExploreEnd::kBudget);
    CHECK_FALSE(one.saturated);
    CHECK(one.start == 0);
    CheckSameGraph(one, two);
  }
}

TEST_CASE("A tiny tube's exploration ends within its budget", "[graph][explore]") {
  // A 0.1 mm tube, 1 mm long, on the groove: its sweeps alone are 1202 motions (offsets a
  // radius apart across 60 mm), which a budget of 3 must cut to three.
  scene::Scene tiny = Groove();
  tiny.tube.outer_radius_m = 1e-4;
  tiny.tube.inner_radius_m = 5e-5;
  tiny.tube.length_m = 1e-3;
  graph::ExploreOptions o;
  o.max_motions = 3;
  o.jobs = 2;
  const ContactGraph g = graph::Explore(tiny, o);
  CHECK(g.motions.size() == 3);
  CHECK(g.end == graph::ExploreEnd::kBudget);
  CHECK(g.seconds < 20.0);
}

namespace {

// The sweeps, the aims and the first probes (the budget's rest) of a scene of tests/data/scenes.
ContactGraph SweepsAndAims(const std::string& file, int motions) {
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/tests/data/scenes/" + file);
  REQUIRE(loaded.scene);
  graph::ExploreOptions o;
  o.random_motions = 0;
  o.closing_motions = 0;
  o.replay_copies = 0;
  o.max_motions = motions;
  o.jobs = 2;
  return graph::Explore(*loaded.scene, o);
}

}  // namespace

TEST_CASE("Aims reach goals the sweeps do not", "[graph][explore]") {
  struct Case {
    const char* file;
    int motions;  // the sweeps and the first aims (the goal's first), or all and the first probes
    const char* goal;
    // The goal's least operator force at most: set down, not pushed in (the aims stop at the
    // first touch of 0.02 N), or pressed no more than the goal needs; and the kind of motion
    // whose stay is its witness, where it must be the aim at the goal as a whole.
    double gentle_N;
    const char* witness_kind;
    // An element another part covers (nothing can touch it): not aimed at, and not listed among
    // the elements never touched, as an uncovered one these motions do not touch is.
    const char* covered = nullptr;
    const char* untouched = nullptr;
  };
  for (const Case& c : {
           // The shipped pocket, parts and start turned 30 deg about world x: the start still
           // hangs the tube over the pocket along its axis, but lowering in world z, or tipping
           // off the floor's normal, runs its end into a wall. The aim at the pocket's floor
           // comes in along its normal. (Without it no motion reaches the goal in a default
           // exploration of 3000 motions.)
           Case{"pocket-turned.yaml", 250, "{Fe - base.top}", 0.1, nullptr},
           // The tube lying straight on a table along a wall: aimed at one face, it bends before
           // it meets the other; the aim at the goal's two PCs together lays it in the corner
           // (measured 0.006 N).
           Case{"corner.yaml", 60, "{Fs - table.top, Fs - wall.xneg}", 0.1, "aim goal",
                "wall.bottom", "wall.top"},
           // The tube lying on a floor, its end face against a step's riser: aimed along the
           // floor into the riser (measured 0.11 N).
           Case{"step.yaml", 40, "{Fe - step.yneg, Fs - floor.top}", 0.2, "aim goal"},
           // The tube lying on a floor under a bar: set down short of the bar and slid in along
           // its axis. Within epsilon of both faces the penalty presses from both sides
           // (0.26 N).
           Case{"slot.yaml", 40, "{Fs - bar.bottom, Fs - floor.top}", 0.5, "aim goal"},
           // The end to stand flat on a plate pitched 18 deg, the tube hanging plumb: the aim at
           // the goal's face comes in along its normal first (measured 0.006 N). Leaning 30 deg
           // off it, as at other faces, the end lands on its rim and bends before it lies flat,
           // and no motion of a default exploration holds the goal.
           Case{"incline.yaml", 51, "{Fe - ramp.top}", 0.1, "aim ramp.top"},
           // The steel tube's end into a hole pitched 20 deg, the tube hanging plumb: the aim at
           // the hole's floor comes in along its axis from a quarter of the tube's length back,
           // the farthest the workspace holds (measured 0.006 N). Lowered plumb from over the
           // floor instead, the end runs into the hole's wall, and no motion of a default
           // exploration holds the goal.
           Case{"hole-tilted.yaml", 47, "{Fe - base.top}", 0.1, "aim base.top"},
           // The tube to lie along a trough that its start's axis crosses at 20 deg: laid along
           // that axis, or square to it, the tube would cross the trough's walls; the aim at
           // the goal's floor turns it 20 deg about the floor's normal (measured 0.006 N).
           Case{"trough.yaml", 64, "{Fs - trough.floor}", 0.1, "aim trough.floor"},
           // The end's rim to catch on a ledge's edge, the tube bent by it: the aim at the goal's
           // edge brings the end along the edge's normal, a radius back, so that one point of
           // its rim lands on the edge, and its press bends the tube (measured 0.84 N; bound:
           // the press, not the device's 8.5 N, under twice that). Leaning,
           // the rim meets the edge from beside and slips off it down the front.
           Case{"ledge.yaml", 51, "{Ee ~ block.top_xpos}", 1.5, "aim block.top_xpos"},
       }) {
    INFO(c.file);
    const ContactGraph g = SweepsAndAims(c.file, c.motions);
    const io::SceneLoadResult loaded =
        io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/tests/data/scenes/" + c.file);
    REQUIRE(loaded.scene);
    const scene::Scene& scene = *loaded.scene;
    // Every reach of an aim towards its target (past the lift at the start's height) stops
    // where the operator force pushes back along it with the explorer's push.
    for (const graph::Motion& m : g.motions) {
      if (m.kind.rfind("aim", 0) != 0) continue;
      INFO(m.kind);
      REQUIRE(!m.moves.empty());
      Eigen::Vector3d at = m.moves.front().p_W_m;
      Eigen::Quaterniond q = m.moves.front().q_W;
      for (std::size_t k = 1; k < m.moves.size() && !m.moves[k].relative; ++k) {
        const graph::Move& move = m.moves[k];
        if ((move.p_W_m - at).norm() > 1e-9) {
          CHECK(move.guard_N == graph::ExploreOptions{}.push_N);
          CHECK(move.guard_dir_W.dot(move.p_W_m - at) < 0.0);
        }
        at = move.p_W_m;
        q = move.q_W;
      }
      // The pose the aim reaches down to was clear: the straight tube there crosses no part
      // (its axis, every millimetre; a pose across a plate thinner than an element shows no
      // contact to a tick of the core).
      const int millimetres = static_cast<int>(std::lround(scene.tube.length_m * 1e3));
      for (int k = 0; k <= millimetres; ++k) {
        const Eigen::Vector3d p_W =
            at + (scene.tube.length_m * k / millimetres) * (q * Eigen::Vector3d::UnitZ());
        CHECK(std::none_of(scene.parts.begin(), scene.parts.end(),
                           [&](const scene::Part& part) { return scene::Contains(part, p_W); }));
      }
    }
    if (c.covered != nullptr) {
      const auto listed = [&](const std::vector<std::string>& names, const std::string& name) {
        return std::find(names.begin(), names.end(), name) != names.end();
      };
      CHECK_FALSE(listed(g.unreached_elements, c.covered));
      CHECK_FALSE(listed(g.reached_elements, c.covered));
      CHECK(std::none_of(g.motions.begin(), g.motions.end(), [&](const graph::Motion& m) {
        return m.kind == std::string("aim ") + c.covered;
      }));
      CHECK(listed(g.unreached_elements, c.untouched));
    }
    CHECK(g.goal >= 0);
    if (g.goal < 0) continue;
    const Node& goal = g.nodes[std::size_t(g.goal)];
    CHECK(goal.cf == c.goal);
    CHECK(goal.min_force_N < c.gentle_N);
    if (c.witness_kind != nullptr)
      CHECK(g.motions[std::size_t(goal.witness.motion)].kind == c.witness_kind);
  }
}

TEST_CASE("The time limit stops exploring; the graph is the one of the motions kept",
          "[graph][explore]") {
  graph::ExploreOptions o;
  o.jobs = 2;
  o.time_limit_s = 0.5;
  o.status_interval_s = 0.05;
  std::vector<graph::ExploreStatus> seen;
  o.status = [&](const graph::ExploreStatus& s) { seen.push_back(s); };
  const ContactGraph limited = graph::Explore(FloorOnly(), o);
  CHECK(limited.end == graph::ExploreEnd::kTimeLimit);
  CHECK_FALSE(limited.saturated);
  // The limit holds once the goal has a stay: it has one, whatever the machine's speed.
  REQUIRE(limited.goal >= 0);
  CHECK(limited.nodes[std::size_t(limited.goal)].ticks > 0);
  REQUIRE(!seen.empty());
  CHECK(seen.back().motions_done == int(limited.motions.size()));
  CHECK(seen.back().nodes == int(limited.nodes.size()));
  // A budget of the motions it kept explores the same graph.
  graph::ExploreOptions b;
  b.jobs = 1;
  b.max_motions = int(limited.motions.size());
  CheckSameGraph(limited, graph::Explore(FloorOnly(), b));
}
