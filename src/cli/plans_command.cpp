// `tubeplan plans SCENE [--k N] [--out-dir DIR] [--all] [--speed V] [--tremor A] [--quantum Q]`
// and the exploration's options: the k best start -> goal paths of the pruned contact-state
// graph, each with a minimum-jerk hand trajectory through its witnesses, replayed as `evaluate`
// would; the feasible ones written as plan files.
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <tuple>
#include <variant>
#include <vector>

#include <tubeplan/graph/motion.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/plan/candidates.hpp>
#include <tubeplan/states/contact_formation.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "graph_build.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

namespace fs = std::filesystem;

struct PlansOptions {
  GraphOptions graph;
  int k = 3;
  bool all = false;
  std::string out_dir;
  std::string tremor = "0";
  std::string quantum = "0";
  std::string speed = "80 mm/s";
};

// --tremor, --quantum and --speed in SI, each checked; nullopt after saying what is wrong.
std::optional<plan::SynthesisOptions> ParseSynthesis(const PlansOptions& o, std::ostream& err) {
  double tremor_m = 0.0, quantum_m = 0.0, speed_m_per_s = 0.0;
  for (auto [option, text, dimension, target] :
       {std::tuple{"--tremor", &o.tremor, io::dim::kLength, &tremor_m},
        std::tuple{"--quantum", &o.quantum, io::dim::kLength, &quantum_m},
        std::tuple{"--speed", &o.speed, io::dim::kVelocity, &speed_m_per_s}}) {
    std::string error;
    const auto values = ParseQuantityList(option, *text, 1, 1, dimension, error);
    if (!values) {
      err << "tubeplan plans: error: " << error << "\n";
      return std::nullopt;
    }
    *target = values->front();
  }
  if (tremor_m < 0.0 || tremor_m > 0.005 || quantum_m < 0.0 || quantum_m > 0.005 ||
      !(speed_m_per_s > 0.0 && speed_m_per_s <= 1.0)) {
    err << "tubeplan plans: error: expected --tremor and --quantum between 0 and 5 mm and "
           "--speed above 0 and at most 1 m/s\n";
    return std::nullopt;
  }
  plan::SynthesisOptions synthesis;
  synthesis.peak_speed_m_per_s = speed_m_per_s;
  synthesis.tremor_m = tremor_m;
  synthesis.quantum_m = quantum_m;
  synthesis.seed = o.graph.seed;
  return synthesis;
}

fs::path OutDir(const PlansOptions& o, const std::string& scene_name) {
  return o.out_dir.empty() ? fs::path(scene_name + "-plans") : fs::path(o.out_dir);
}

// The files it may write, named before the exploration: none may be the scene it reads.
bool PlanFilesApart(const PlansOptions& o, std::ostream& err) {
  const io::SceneLoadResult scene = io::LoadSceneFile(o.graph.scene_path);
  if (!scene.scene) return true;  // the exploration reports the scene's problems
  const fs::path dir = OutDir(o, scene.scene->name);
  std::vector<io::RolePath> outputs;
  for (int i = 1; i <= o.k; ++i) {
    const std::string name = scene.scene->name + "-candidate-" + std::to_string(i);
    outputs.push_back({"the plan file", dir / (name + ".yaml")});
    outputs.push_back({"the plan's trajectory", dir / (name + ".csv")});
  }
  return OutputsApart("plans", outputs, {{"the scene", o.graph.scene_path}}, err);
}

int NothingToPlan(const PlansOptions& o, const scene::Scene& s, const std::string& start,
                  std::ostream& err) {
  err << o.graph.scene_path << ": nothing to plan: the goal " << states::ToString(s.goal)
      << " is the state the tube starts in (" << start
      << " at the scene's start pose), so a plan would be that one state and no move; no "
         "plan written. Give the scene a goal the tube has to be moved to\n";
  return kExitNegative;
}

// The candidates' first line: how many, of how many asked, through which graph, written where.
void PrintHeader(std::ostream& t, const PlansOptions& o, const Built& b, std::size_t paths,
                 std::size_t candidates, long feasible, const fs::path& out_dir) {
  const graph::ContactGraph& g = b.graph;
  t << paths << " candidate plan" << (paths == 1 ? "" : "s") << " (of " << o.k
    << " asked) through the pruned graph of " << b.scene.name << " (" << g.nodes.size() << " CFs, "
    << std::count_if(g.arcs.begin(), g.arcs.end(), [](const auto& a) { return a.kept; })
    << " kept arcs), each replayed as `evaluate` would: " << feasible << " feasible"
    << (o.all || feasible == 0 || feasible == long(candidates)
            ? ""
            : " (the others are not written; --all writes them, marked)")
    << "; written to " << out_dir.string() << ":\n";
  // Fewer than asked: the pruned graph holds no more loopless paths to the goal.
  if (static_cast<int>(paths) < o.k)
    t << "  (the pruned graph has no other loopless path from the start to the goal: a larger "
         "--tolerance keeps more arcs, a larger --budget explores more states)\n";
}

// "feasible" or "infeasible: why", the try kept when not the first, and the peak force.
std::string VerdictText(const plan::Candidate& c) {
  std::ostringstream text;
  text << std::setprecision(3)
       << (c.judgement.feasible ? "feasible" : "infeasible: " + plan::FirstFailure(c.judgement));
  if (c.tries > 1)
    text << " (try " << c.tries << ": " << (c.held ? "the held end's poses" : "the hand's")
         << " at " << c.peak_speed_m_per_s * 1e3 << " mm/s)";
  text << "; peak operator force " << c.judgement.peak_force_N << " N";
  return text.str();
}

// Names candidate `number` and writes its plan file and trajectory into `out_dir`, the plan's
// comment saying how it was made; an empty string on success, else the message.
std::string WriteCandidate(plan::Candidate& c, int number, const std::string& verdict,
                           const PlansOptions& o, const std::string& scene_name,
                           const fs::path& out_dir) {
  const std::string name = scene_name + "-candidate-" + std::to_string(number);
  c.plan.name = name;
  c.plan.trajectory = name + ".csv";
  std::ostringstream comment;
  comment << "Candidate " << number << " made by `tubeplan plans " << o.graph.scene_path
          << "` (seed " << o.graph.seed << "), cost " << c.path->cost
          << ": the hand moves by minimum jerk through the witnesses of its states. Replayed "
             "when made: "
          << verdict << ".";
  c.plan.comment = comment.str();
  for (const auto& [file, text] :
       {std::pair{out_dir / (name + ".yaml"), io::FormatPlanYaml(c.plan)},
        std::pair{out_dir / c.plan.trajectory, io::FormatTrajectoryCsv(c.trajectory)}}) {
    if (const std::string e = io::WriteTextFileAtomically(file, text); !e.empty())
      return file.string() + ": error: " + e;
  }
  return {};
}

// One candidate's line: its name (or "(not written)"), cost, length, states and verdict.
void PrintCandidate(std::ostream& t, const std::string& name, const plan::Candidate& c,
                    const std::string& verdict) {
  t << "  " << name << ": cost " << c.path->cost << ", " << c.path->nodes.size() - 1
    << (c.path->nodes.size() == 2 ? " transition, " : " transitions, ") << c.duration_s << " s:";
  for (const std::string& state : c.plan.states)
    t << " " << state << (&state == &c.plan.states.back() ? "" : " ->");
  t << "; " << verdict << "\n";
}

int RunPlans(const PlansOptions& o, Streams io) {
  // Quantities first: a typo should not cost an exploration.
  const std::optional<plan::SynthesisOptions> synthesis = ParseSynthesis(o, io.err);
  if (!synthesis || !PlanFilesApart(o, io.err)) return kExitBadInput;
  // A goal the tube starts in leaves nothing to plan: said before any exploration.
  std::variant<Built, int> built =
      BuildGraph(o.graph, io, [&](const scene::Scene& s) -> std::optional<int> {
        const std::string start = graph::RestingFormation(s);
        if (start != states::ToString(s.goal)) return std::nullopt;
        return NothingToPlan(o, s, start, io.err);
      });
  if (const int* code = std::get_if<int>(&built)) return *code;
  const Built& b = std::get<Built>(built);
  const graph::ContactGraph& g = b.graph;
  // The explorer's start state can differ from a tick at rest (its first tick moves the hand).
  if (g.goal >= 0 && g.goal == g.start)
    return NothingToPlan(o, b.scene, g.nodes[std::size_t(g.start)].cf, io.err);
  if (g.goal < 0) {
    io.err << o.graph.scene_path << ": error: exploration never reached the goal "
           << states::ToString(b.scene.goal) << ", so there is no plan to extract; expected a "
           << "goal the tube can reach (try a larger --budget)\n";
    return kExitNegative;
  }
  const std::vector<graph::Path> paths =
      graph::KShortestPaths(g, graph::ArcCosts(g, b.weights), o.k);

  const fs::path out_dir = OutDir(o, b.scene.name);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) {
    io.err << out_dir.string() << ": error: cannot create the directory (" << ec.message()
           << "), expected a writable place for the plans\n";
    return kExitBadInput;
  }
  plan::CandidateOptions candidate_options;
  candidate_options.synthesis = *synthesis;
  candidate_options.dwell_s = b.explore.dwell_s;
  candidate_options.scene_ref =
      fs::relative(fs::absolute(o.graph.scene_path), fs::absolute(out_dir), ec).generic_string();
  // Each replayed as its file will read: what `evaluate` on the written plan sees.
  std::vector<plan::Candidate> candidates =
      plan::MakeCandidates(b.scene, g, paths, candidate_options, io::TrajectoryAsWritten);
  const long feasible =
      std::count_if(candidates.begin(), candidates.end(),
                    [](const plan::Candidate& c) { return c.judgement.feasible; });

  std::ostringstream t;
  t << std::setprecision(3);
  PrintHeader(t, o, b, paths.size(), candidates.size(), feasible, out_dir);
  int written = 0;
  for (plan::Candidate& c : candidates) {
    const std::string verdict = VerdictText(c);
    std::string name = "(not written)";
    if (c.judgement.feasible || o.all) {
      name = b.scene.name + "-candidate-" + std::to_string(++written);
      if (const std::string e = WriteCandidate(c, written, verdict, o, b.scene.name, out_dir);
          !e.empty()) {
        io.err << e << "\n";
        return kExitBadInput;
      }
    }
    PrintCandidate(t, name, c, verdict);
  }
  if (feasible == 0)
    t << "  no candidate replays feasible, each also tried at 1/2 and 1/4 of --speed: a larger "
         "--budget or a larger --tolerance may give one; --all writes them for inspection\n";
  io.out << t.str();
  return feasible > 0 ? kExitOk : kExitNegative;
}

}  // namespace

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
  // Plans need paths to the goal, which probing finds: no closing rounds unless asked for (they
  // make the graph complete and take several times as long).
  options->graph.closing = 0;
  AddGraphOptions(sub, options->graph);
  return {sub, [options, streams] { return RunPlans(*options, streams); }};
}

}  // namespace tubeplan::cli
