// `tubeplan graph SCENE [--dot FILE] [--json FILE] [--unpruned] [--seed N] [--random N]
// [--jobs N] [--weights friction=1,energy=1,distance=1] [--tolerance T]`: explores the scene with
// the core, prunes the contact-state graph with the paper's heuristics and writes it as DOT and
// JSON (schema in docs/graph.md). stdout: what was found, the saturation curve, the time taken.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <thread>
#include <tuple>
#include <unistd.h>
#include <variant>

#include <nlohmann/json.hpp>

#include <tubeplan/cli/app.hpp>
#include <tubeplan/core/core.hpp>
#include <tubeplan/graph/completeness.hpp>
#include <tubeplan/graph/dot.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/motion.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/graph/verdicts.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/text_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/plan/candidates.hpp>

#include "commands.hpp"
#include "graph_json.hpp"
#include "graphviz.hpp"

namespace tubeplan::cli {
namespace {

struct GraphOptions {
  std::string scene_path;
  std::string dot_path;
  std::string svg_path;  // graph only: the DOT rendered by Graphviz's dot
  std::string json_path;
  bool unpruned = false;
  std::uint64_t seed = 1;
  int random = 120;
  int budget = 3000;
  double time_limit_s = 0.0;  // 0: none
  int jobs = 0;               // 0: the machine's cores
  std::string weights;
  std::optional<double> tolerance;
  std::string verdicts_path;  // graph only: an evaluate report
  int check = 0;              // graph only: independent random motions measuring completeness
};

// The judged plans of an evaluate report (docs/evaluate.md), or nullopt after reporting why not.
std::optional<std::vector<graph::ReplayedPlan>> ReadVerdicts(const std::string& path,
                                                             std::ostream& err) {
  const std::optional<std::string> text = io::ReadTextFile(path);
  const nlohmann::json report =
      text ? nlohmann::json::parse(*text, nullptr, false) : nlohmann::json();
  std::vector<graph::ReplayedPlan> plans;
  bool ok = text && !report.is_discarded() && report.is_object() &&
            report.value("tubeplan_evaluate", 0) >= 1 &&
            report.value("tubeplan_evaluate", 0) <= 3 && report.contains("plans") &&
            report["plans"].is_array();
  for (std::size_t i = 0; ok && i < report["plans"].size(); ++i) {
    const nlohmann::json& p = report["plans"][i];
    graph::ReplayedPlan r;
    ok = p.is_object() && p.contains("transitions") && p["transitions"].is_array() &&
         p.contains("observed") && p["observed"].is_array();
    for (std::size_t k = 0; ok && k < p["transitions"].size(); ++k) {
      const nlohmann::json& t = p["transitions"][k];
      ok = t.is_object() && t.value("from", nlohmann::json()).is_string() &&
           t.value("to", nlohmann::json()).is_string() &&
           t.value("verdict", nlohmann::json()).is_string() &&
           (t.value("t_start_s", nlohmann::json()).is_number() ||
            t.value("t_start_s", nlohmann::json(0)).is_null()) &&
           (t.value("t_end_s", nlohmann::json()).is_number() ||
            t.value("t_end_s", nlohmann::json(0)).is_null());
      // A transition the replay never got to has no span (null times): no step falls in it.
      // One a live run did not finish is no verdict on the arcs.
      if (ok && t["verdict"] != "not judged")
        r.transitions.push_back({t["from"], t["to"], t["verdict"] != "infeasible",
                                 t["t_start_s"].is_null() ? 0.0 : t["t_start_s"].get<double>(),
                                 t["t_end_s"].is_null() ? 0.0 : t["t_end_s"].get<double>()});
    }
    for (std::size_t k = 0; ok && k < p["observed"].size(); ++k) {
      const nlohmann::json& o = p["observed"][k];
      ok = o.is_object() && o.value("t", nlohmann::json()).is_number() &&
           o.value("cf", nlohmann::json()).is_string();
      if (ok) r.observed.push_back({o["t"].get<double>(), o["cf"].get<std::string>()});
    }
    plans.push_back(std::move(r));
  }
  if (!ok) {
    err << path
        << ": error: not a readable tubeplan evaluate report, expected the JSON that "
           "`tubeplan evaluate --report` writes (version 1 or 2)\n";
    return std::nullopt;
  }
  return plans;
}

// "friction=1,energy=0.5,distance=2" over the scene's weights.
bool ParseWeights(const std::string& text, graph::PruneWeights& w, std::string& error) {
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    const std::size_t eq = item.find('=');
    double* target = nullptr;
    const std::string key = item.substr(0, eq);
    if (key == "friction") target = &w.friction;
    if (key == "energy") target = &w.energy;
    if (key == "distance") target = &w.distance;
    char* end = nullptr;
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    const double v = value.empty() ? -1.0 : std::strtod(value.c_str(), &end);
    if (target == nullptr || value.empty() || *end != '\0' || !(v >= 0.0 && v <= 1e6)) {
      error = "--weights: \"" + item +
              "\" is not a weight, expected name=value with name friction, energy or distance "
              "and a value between 0 and 1e6, e.g. friction=1,energy=1,distance=1";
      return false;
    }
    *target = v;
    start = comma + 1;
  }
  return true;
}

// What `graph` and `plans` share: the scene, the explored and pruned graph, the settings used.
struct Built {
  scene::Scene scene;
  graph::ContactGraph graph;
  graph::ExploreOptions explore;
  graph::PruneWeights weights;
};

// Loads the scene, explores and prunes; on bad input reports and returns the exit code.
// `before` (may be empty) sees the scene before the exploration and may end the command there
// with an exit code.
std::variant<Built, int> BuildGraph(
    const GraphOptions& o, Streams io,
    const std::function<std::optional<int>(const scene::Scene&)>& before = {}) {
  io::SceneLoadResult loaded = io::LoadSceneFile(o.scene_path);
  io.err << loaded.diagnostics.FormatAll();
  if (!loaded.scene) return kExitBadInput;
  const scene::Scene& s = *loaded.scene;

  graph::PruneWeights weights{s.heuristics.friction, s.heuristics.energy, s.heuristics.distance,
                              s.heuristics.tolerance};
  std::string error;
  if (!o.weights.empty() && !ParseWeights(o.weights, weights, error)) {
    io.err << "tubeplan graph: error: " << error << "\n";
    return kExitBadInput;
  }
  if (o.tolerance) {
    if (!(*o.tolerance >= 0.0)) {
      io.err << "tubeplan graph: error: --tolerance must be zero or more\n";
      return kExitBadInput;
    }
    weights.tolerance = *o.tolerance;
  }
  graph::ExploreOptions explore;
  explore.seed = o.seed;
  explore.random_motions = o.random;
  explore.max_motions = o.budget;
  explore.time_limit_s = o.time_limit_s;
  explore.jobs = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
  // Progress on a terminal only, about once a second, on one line (a log stays clean).
  if (isatty(STDERR_FILENO) != 0) {
    explore.status = [&io, path = o.scene_path](const graph::ExploreStatus& st) {
      char line[200];
      std::snprintf(line, sizeof line,
                    "\rexploring %s: %s, %d motions done, %d started; the graph so far %d CFs, "
                    "%d transitions; %.0f s\033[K",
                    path.c_str(), st.phase.c_str(), st.motions_done, st.motions_started, st.nodes,
                    st.arcs, st.seconds);
      io.err << line << std::flush;
    };
  }
  std::optional<std::vector<graph::ReplayedPlan>> verdicts;
  if (!o.verdicts_path.empty()) {
    verdicts = ReadVerdicts(o.verdicts_path, io.err);
    if (!verdicts) return kExitBadInput;
  }
  if (before)
    if (const std::optional<int> code = before(s)) return *code;
  graph::ContactGraph g = graph::Explore(s, explore);
  if (explore.status) io.err << "\r\033[K" << std::flush;
  explore.status = nullptr;
  graph::Prune(g, weights);
  if (verdicts) graph::ApplyVerdicts(g, *verdicts);
  return Built{s, std::move(g), explore, weights};
}

void AddGraphOptions(CLI::App* sub, GraphOptions& o) {
  sub->add_option("--seed", o.seed, "seed of the random motions")->capture_default_str();
  sub->add_option("--random", o.random,
                  "random motions after the sweeps and aims, before every state found is "
                  "probed with small motions until no new one appears (saturation)")
      ->check(CLI::Range(0, 10000))
      ->capture_default_str();
  sub->add_option("--budget", o.budget,
                  "run at most this many motions in all (a motion: one list of guarded moves of "
                  "the hand from the start pose; docs/graph.md), saturated or not (said in the "
                  "output)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  sub->add_option("--time-limit", o.time_limit_s,
                  "stop exploring after this many seconds of wall time, saturated or not (said in "
                  "the output; default: no limit)")
      ->check(CLI::Range(0.001, 1e7));
  sub->add_option("--jobs", o.jobs, "threads (default: the machine's cores)")
      ->check(CLI::Range(1, 256));
  sub->add_option("--weights", o.weights,
                  "heuristic weights over the scene's, e.g. friction=1,energy=1,distance=1");
  sub->add_option("--tolerance", o.tolerance,
                  "keep arcs whose weighted score is within this of the best (scene's default)");
}

int RunGraph(const GraphOptions& o, Streams io) {
  if (!OutputsApart("graph",
                    {{"--dot", o.dot_path}, {"--svg", o.svg_path}, {"--json", o.json_path}},
                    {{"the scene", o.scene_path}, {"--verdicts", o.verdicts_path}}, io.err))
    return kExitBadInput;
  // Graphviz is checked before the exploration: a missing `dot` should not cost one.
  if (!o.svg_path.empty()) {
    if (const SvgFromDot probe = RenderDot("digraph{}"); !probe.error.empty()) {
      io.err << "tubeplan graph: error: --svg: " << probe.error << "\n";
      return kExitBadInput;
    }
  }
  std::variant<Built, int> built = BuildGraph(o, io);
  if (const int* code = std::get_if<int>(&built)) return *code;
  const Built& b = std::get<Built>(built);
  const scene::Scene& s = b.scene;
  const graph::ContactGraph& g = b.graph;
  const graph::ExploreOptions& explore = b.explore;
  const graph::PruneWeights& weights = b.weights;

  graph::DotOptions dot;
  dot.dropped_arcs = o.unpruned;
  dot.title = "tubeplan: contact-state graph of " + s.name + (o.unpruned ? " (unpruned)" : "");
  const std::string dot_text =
      o.dot_path.empty() && o.svg_path.empty() ? std::string() : graph::FormatDot(g, dot);
  if (!o.dot_path.empty()) {
    if (const std::string e = io::WriteTextFileAtomically(o.dot_path, dot_text); !e.empty()) {
      io.err << o.dot_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  }
  if (!o.svg_path.empty()) {
    const SvgFromDot svg = RenderDot(dot_text);
    if (!svg.error.empty()) {
      io.err << "tubeplan graph: error: " << svg.error << "\n";
      return kExitBadInput;
    }
    io.err << svg.warnings;
    if (const std::string e = io::WriteTextFileAtomically(o.svg_path, svg.svg); !e.empty()) {
      io.err << o.svg_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  }
  if (!o.json_path.empty()) {
    const nlohmann::json j = GraphToJson(g, s, o.scene_path, explore, weights);
    if (const std::string e = io::WriteTextFileAtomically(o.json_path, j.dump(1) + "\n");
        !e.empty()) {
      io.err << o.json_path << ": error: " << e << "\n";
      return kExitBadInput;
    }
  }

  const long kept =
      std::count_if(g.arcs.begin(), g.arcs.end(), [](const auto& a) { return a.kept; });
  const long simultaneous =
      std::count_if(g.arcs.begin(), g.arcs.end(), [](const auto& a) { return a.simultaneous; });
  std::map<std::string, int> kinds;
  for (const graph::Motion& m : g.motions) ++kinds[m.kind.substr(0, m.kind.find(' '))];
  std::ostringstream t;
  t << std::setprecision(3);
  t << o.scene_path << ": " << g.nodes.size() << " contact formations, " << g.arcs.size()
    << " transitions (" << kept << " kept by pruning, " << simultaneous << " simultaneous) from "
    << g.motions.size() << " motions (";
  bool first = true;
  for (const auto& [kind, n] : kinds) t << (first ? "" : ", ") << n << " " << kind, first = false;
  t << "), " << g.ticks << " core ticks, " << g.refinements << " steps refined, " << g.held_back
    << " motions ended where the coupling reached the device's force (the tube no longer followed "
       "the hand); "
    << g.seconds << " s on " << explore.jobs << " thread" << (explore.jobs > 1 ? "s" : "") << "\n";
  t << "saturation (motions: nodes/arcs):";
  const std::size_t every = std::max<std::size_t>(1, g.saturation.size() / 12);
  for (std::size_t i = 0; i < g.saturation.size(); ++i) {
    if (i % every != 0 && i + 1 != g.saturation.size()) continue;
    const graph::SaturationPoint& p = g.saturation[i];
    t << " " << p.motions << ": " << p.nodes << "/" << p.arcs;
  }
  if (g.saturated) {
    constexpr int kProbes =
        2 * 3 + 2 * 2;  // graph::Explore's probe set: 3 steps, 2 turns, each way
    t << "  (saturated: every one of the " << g.probed << " states probed from a stay with "
      << kProbes << " small motions (" << explore.probe_step_m * 1e3
      << " mm along and against 3 directions, " << explore.probe_turn_rad * 180.0 / std::numbers::pi
      << " deg about 2 axes), the last round found no new state)\n";
  } else if (g.end == graph::ExploreEnd::kTimeLimit) {
    t << "  (NOT saturated: stopped by the time limit of " << explore.time_limit_s << " s after "
      << g.motions.size() << " motions, with " << g.probed << " of " << g.nodes.size()
      << " states probed)\n";
  } else {
    t << "  (NOT saturated: stopped by the budget of " << explore.max_motions << " motions, with "
      << g.probed << " of " << g.nodes.size() << " states probed)\n";
  }
  t << "start "
    << (g.start >= 0 ? g.nodes[std::size_t(g.start)].cf : "not reached (no motion ended)")
    << "; goal " << states::ToString(s.goal)
    << (g.goal >= 0 ? " reached" : " NEVER reached: no plan can be extracted") << "\n";
  t << "part elements touched: " << g.reached_elements.size()
    << "; never touched: " << g.unreached_elements.size();
  for (std::size_t i = 0; i < g.unreached_elements.size() && i < 8; ++i)
    t << (i == 0 ? " (" : ", ") << g.unreached_elements[i];
  if (!g.unreached_elements.empty()) t << (g.unreached_elements.size() > 8 ? ", ...)" : ")");
  t << "\n";
  if (!o.verdicts_path.empty()) {
    auto count = [&](graph::BatchResult result) {
      return std::count_if(g.arcs.begin(), g.arcs.end(),
                           [&](const auto& a) { return a.batch == result; });
    };
    t << "verdicts from " << o.verdicts_path << ": " << count(graph::BatchResult::kFeasible)
      << " arcs feasible, " << count(graph::BatchResult::kInfeasible) << " infeasible; "
      << std::count_if(g.nodes.begin(), g.nodes.end(), [](const auto& n) { return n.from_replay; })
      << " states and "
      << std::count_if(g.arcs.begin(), g.arcs.end(), [](const auto& a) { return a.from_replay; })
      << " transitions seen only in the replays added\n";
  }
  if (o.check > 0) {
    // Random motions of another seed than the explorer's: motions it did not make.
    const std::vector<graph::Motion> motions =
        graph::RandomMotions(s, o.seed + 1000003, 0, o.check, explore);
    const graph::Completeness c = graph::CheckCompleteness(s, g, motions, explore.dwell_s);
    const auto percent = [](long part, long all) { return all > 0 ? 100.0 * part / all : 100.0; };
    t << "completeness: " << c.motions << " independent random motions counted " << c.states_seen
      << " states, " << c.states_in_graph << " in the graph ("
      << percent(c.states_in_graph, c.states_seen) << " %), and " << c.transitions_seen
      << " transitions, " << c.transitions_in_graph << " in it ("
      << percent(c.transitions_in_graph, c.transitions_seen) << " %); by use, "
      << percent(c.ticks_in_graph, c.ticks) << " % of their ticks and "
      << percent(c.taken_in_graph, c.taken) << " % of the transitions taken\n";
    for (std::size_t i = 0; i < c.missing_states.size() && i < 8; ++i)
      t << "  missing state: " << c.missing_states[i] << "\n";
    for (std::size_t i = 0; i < c.missing_transitions.size() && i < 8; ++i)
      t << "  missing transition: " << c.missing_transitions[i].first.first << " -> "
        << c.missing_transitions[i].first.second << " (taken " << c.missing_transitions[i].second
        << (c.missing_transitions[i].second == 1 ? " time)\n" : " times)\n");
    const std::size_t more = c.missing_states.size() + c.missing_transitions.size() -
                             std::min<std::size_t>(c.missing_states.size(), 8) -
                             std::min<std::size_t>(c.missing_transitions.size(), 8);
    if (more > 0) t << "  and " << more << " more\n";
  }
  if (!o.dot_path.empty()) t << "DOT written to " << o.dot_path << "\n";
  if (!o.svg_path.empty()) t << "SVG (Graphviz dot) written to " << o.svg_path << "\n";
  if (!o.json_path.empty()) t << "JSON written to " << o.json_path << "\n";
  io.out << t.str();
  return g.goal >= 0 ? kExitOk : kExitNegative;
}

struct PlansOptions {
  GraphOptions graph;
  int k = 3;
  bool all = false;
  std::string out_dir;
  std::string tremor = "0";
  std::string quantum = "0";
  std::string speed = "80 mm/s";
};

// Why a replay was judged infeasible: its first infeasible transition and the reason.
int RunPlans(const PlansOptions& o, Streams io) {
  // Quantities first: a typo should not cost an exploration.
  double tremor_m = 0.0, quantum_m = 0.0, speed_m_per_s = 0.0;
  for (auto [option, text, dimension, target] :
       {std::tuple{"--tremor", &o.tremor, io::dim::kLength, &tremor_m},
        std::tuple{"--quantum", &o.quantum, io::dim::kLength, &quantum_m},
        std::tuple{"--speed", &o.speed, io::dim::kVelocity, &speed_m_per_s}}) {
    std::string error;
    const auto values = ParseQuantityList(option, *text, 1, 1, dimension, error);
    if (!values) {
      io.err << "tubeplan plans: error: " << error << "\n";
      return kExitBadInput;
    }
    *target = values->front();
  }
  if (tremor_m < 0.0 || tremor_m > 0.005 || quantum_m < 0.0 || quantum_m > 0.005 ||
      !(speed_m_per_s > 0.0 && speed_m_per_s <= 1.0)) {
    io.err << "tubeplan plans: error: expected --tremor and --quantum between 0 and 5 mm and "
              "--speed above 0 and at most 1 m/s\n";
    return kExitBadInput;
  }
  // The files it may write, named before the exploration: none may be the scene it reads.
  namespace fs = std::filesystem;
  if (const io::SceneLoadResult scene = io::LoadSceneFile(o.graph.scene_path); scene.scene) {
    const fs::path dir =
        o.out_dir.empty() ? fs::path(scene.scene->name + "-plans") : fs::path(o.out_dir);
    std::vector<io::RolePath> outputs;
    for (int i = 1; i <= o.k; ++i) {
      const std::string name = scene.scene->name + "-candidate-" + std::to_string(i);
      outputs.push_back({"the plan file", dir / (name + ".yaml")});
      outputs.push_back({"the plan's trajectory", dir / (name + ".csv")});
    }
    if (!OutputsApart("plans", outputs, {{"the scene", o.graph.scene_path}}, io.err))
      return kExitBadInput;
  }
  // A goal the tube starts in leaves nothing to plan: said before any exploration.
  const auto nothing_to_plan = [&](const scene::Scene& s, const std::string& start) {
    io.err << o.graph.scene_path << ": nothing to plan: the goal " << states::ToString(s.goal)
           << " is the state the tube starts in (" << start
           << " at the scene's start pose), so a plan would be that one state and no move; no "
              "plan written. Give the scene a goal the tube has to be moved to\n";
    return kExitNegative;
  };
  std::variant<Built, int> built =
      BuildGraph(o.graph, io, [&](const scene::Scene& s) -> std::optional<int> {
        core::Core core(s);
        core.Reset(graph::MotionStart(s));
        core.Step(s.model.time_step_s, graph::MotionStart(s));
        const std::string start = core.FormationText();
        if (start != states::ToString(s.goal)) return std::nullopt;
        return nothing_to_plan(s, start);
      });
  if (const int* code = std::get_if<int>(&built)) return *code;
  const Built& b = std::get<Built>(built);
  const graph::ContactGraph& g = b.graph;
  // The explorer's start state can differ from a tick at rest (its first tick moves the hand).
  if (g.goal >= 0 && g.goal == g.start)
    return nothing_to_plan(b.scene, g.nodes[std::size_t(g.start)].cf);
  if (g.goal < 0) {
    io.err << o.graph.scene_path << ": error: exploration never reached the goal "
           << states::ToString(b.scene.goal) << ", so there is no plan to extract; expected a "
           << "goal the tube can reach (try a larger --budget)\n";
    return kExitNegative;
  }
  const std::vector<graph::Path> paths =
      graph::KShortestPaths(g, graph::ArcCosts(g, b.weights), o.k);

  const fs::path out_dir =
      o.out_dir.empty() ? fs::path(b.scene.name + "-plans") : fs::path(o.out_dir);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) {
    io.err << out_dir.string() << ": error: cannot create the directory (" << ec.message()
           << "), expected a writable place for the plans\n";
    return kExitBadInput;
  }
  const std::string scene_rel =
      fs::relative(fs::absolute(o.graph.scene_path), fs::absolute(out_dir), ec).generic_string();
  plan::CandidateOptions candidate_options;
  candidate_options.synthesis.peak_speed_m_per_s = speed_m_per_s;
  candidate_options.synthesis.tremor_m = tremor_m;
  candidate_options.synthesis.quantum_m = quantum_m;
  candidate_options.synthesis.seed = o.graph.seed;
  candidate_options.dwell_s = b.explore.dwell_s;
  candidate_options.scene_ref = scene_rel;
  // Each replayed as its file will read: what `evaluate` on the written plan sees.
  std::vector<plan::Candidate> candidates =
      plan::MakeCandidates(b.scene, g, paths, candidate_options,
                           [](const plan::Trajectory& t) -> std::optional<plan::Trajectory> {
                             io::TrajectoryLoadResult read =
                                 io::LoadTrajectoryText(io::FormatTrajectoryCsv(t), "candidate");
                             return std::move(read.trajectory);
                           });
  const auto feasible =
      std::count_if(candidates.begin(), candidates.end(),
                    [](const plan::Candidate& c) { return c.judgement.feasible; });

  std::ostringstream t;
  t << std::setprecision(3);
  t << paths.size() << " candidate plan" << (paths.size() == 1 ? "" : "s") << " (of " << o.k
    << " asked) through the pruned graph of " << b.scene.name << " (" << g.nodes.size() << " CFs, "
    << std::count_if(g.arcs.begin(), g.arcs.end(), [](const auto& a) { return a.kept; })
    << " kept arcs), each replayed as `evaluate` would: " << feasible << " feasible"
    << (o.all || feasible == 0 || feasible == long(candidates.size())
            ? ""
            : " (the others are not written; --all writes them, marked)")
    << "; written to " << out_dir.string() << ":\n";
  // Fewer than asked: the pruned graph holds no more loopless paths to the goal.
  if (static_cast<int>(paths.size()) < o.k)
    t << "  (the pruned graph has no other loopless path from the start to the goal: a larger "
         "--tolerance keeps more arcs, a larger --budget explores more states)\n";
  int written = 0;
  for (plan::Candidate& c : candidates) {
    const bool write = c.judgement.feasible || o.all;
    std::ostringstream verdict_text;
    verdict_text << std::setprecision(3)
                 << (c.judgement.feasible ? "feasible"
                                          : "infeasible: " + plan::FirstFailure(c.judgement));
    if (c.tries > 1)
      verdict_text << " (try " << c.tries << ": "
                   << (c.held ? "the held end's poses" : "the hand's") << " at "
                   << c.peak_speed_m_per_s * 1e3 << " mm/s)";
    verdict_text << "; peak operator force " << c.judgement.peak_force_N << " N";
    const std::string verdict = verdict_text.str();
    std::string name = "(not written)";
    if (write) {
      name = b.scene.name + "-candidate-" + std::to_string(++written);
      c.plan.name = name;
      c.plan.trajectory = name + ".csv";
      std::ostringstream comment;
      comment << "Candidate " << written << " made by `tubeplan plans " << o.graph.scene_path
              << "` (seed " << o.graph.seed << "), cost " << c.path->cost
              << ": the hand moves by minimum jerk through the witnesses of its states. Replayed "
                 "when made: "
              << verdict << ".";
      c.plan.comment = comment.str();
      for (const auto& [file, text] :
           {std::pair{out_dir / (name + ".yaml"), io::FormatPlanYaml(c.plan)},
            std::pair{out_dir / c.plan.trajectory, io::FormatTrajectoryCsv(c.trajectory)}}) {
        if (const std::string e = io::WriteTextFileAtomically(file, text); !e.empty()) {
          io.err << file.string() << ": error: " << e << "\n";
          return kExitBadInput;
        }
      }
    }
    t << "  " << name << ": cost " << c.path->cost << ", " << c.path->nodes.size() - 1
      << (c.path->nodes.size() == 2 ? " transition, " : " transitions, ") << c.duration_s << " s:";
    for (const std::string& state : c.plan.states)
      t << " " << state << (&state == &c.plan.states.back() ? "" : " ->");
    t << "; " << verdict << "\n";
  }
  if (feasible == 0)
    t << "  no candidate replays feasible, each also tried at 1/2 and 1/4 of --speed: a larger "
         "--budget or a larger --tolerance may give one; --all writes them for inspection\n";
  io.out << t.str();
  return feasible > 0 ? kExitOk : kExitNegative;
}

}  // namespace

Command AddGraphCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<GraphOptions>();
  CLI::App* sub = app.add_subcommand(
      "graph",
      "Build the contact-state graph of a scene by exploring it with the core, prune it with the "
      "friction, bending-energy and distance heuristics, and write DOT and JSON.");
  sub->add_option("scene", options->scene_path, "scene file (.yaml)")->required();
  sub->add_option("--dot", options->dot_path, "write the graph in Graphviz DOT to FILE");
  sub->add_option("--svg", options->svg_path,
                  "write the graph's picture (SVG) to FILE, drawn by Graphviz's `dot` program");
  sub->add_option("--json", options->json_path, "write the graph as JSON to FILE (docs/graph.md)");
  sub->add_option("--verdicts", options->verdicts_path,
                  "colour arcs by an evaluate report (feasible green, infeasible red) and add the "
                  "states its replays saw that exploration missed");
  sub->add_flag("--unpruned", options->unpruned,
                "DOT: draw every arc, the dropped ones dashed with their reason (default: the "
                "pruned graph only)");
  sub->add_option("--check", options->check,
                  "after exploring, run N random guarded motions of another seed and report the "
                  "states and transitions they reach that the graph lacks (docs/graph.md)")
      ->check(CLI::Range(0, 100000));
  AddGraphOptions(sub, *options);
  return {sub, [options, streams] { return RunGraph(*options, streams); }};
}

}  // namespace tubeplan::cli

namespace tubeplan::cli {

Command AddPlansCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<PlansOptions>();
  CLI::App* sub = app.add_subcommand(
      "plans",
      "Build and prune the scene's contact-state graph, then take the k best start -> goal paths, "
      "each with a synthesized (minimum-jerk) operator trajectory, replay each as `evaluate` "
      "would, and write the feasible ones as plan files.");
  sub->add_option("scene", options->graph.scene_path, "scene file (.yaml)")->required();
  sub->add_option("--k", options->k, "how many plans")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  sub->add_option("--out-dir", options->out_dir,
                  "where to write NAME-candidate-I.yaml and .csv (default: SCENE_NAME-plans)");
  sub->add_flag("--all", options->all,
                "also write the candidates whose replay is infeasible (after the feasible ones, "
                "their comment saying why)");
  sub->add_option("--speed", options->speed, "peak hand speed, e.g. \"80 mm/s\"")
      ->capture_default_str();
  sub->add_option("--tremor", options->tremor,
                  "amplitude of 8-12 Hz tremor added to the hand, e.g. \"0.1 mm\" (default none)");
  sub->add_option("--quantum", options->quantum,
                  "round positions to this device resolution, e.g. \"0.03 mm\" (default none)");
  AddGraphOptions(sub, options->graph);
  return {sub, [options, streams] { return RunPlans(*options, streams); }};
}

}  // namespace tubeplan::cli
