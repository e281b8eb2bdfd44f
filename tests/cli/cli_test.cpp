// The command line as a user drives it: argument strings in, exit code and text out.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "../scratch.hpp"
#include "cli/app.hpp"
#include "run_tool.hpp"

namespace {

using tubeplan::testing::Outcome;
using tubeplan::testing::RunTool;
using tubeplan::testing::SourcePath;

// A steel tube well inside the linear range: r1 3 mm, r2 2.5 mm, l 300 mm, E 200 GPa.
const std::vector<std::string> kSteelTube = {
    "--outer-radius",   "3 mm",    "--inner-radius",  "2.5mm", "--length", "0.3",
    "--youngs-modulus", "200 GPa", "--poisson-ratio", "0.3"};

std::vector<std::string> Beam(std::vector<std::string> extra) {
  std::vector<std::string> args = {"beam"};
  args.insert(args.end(), kSteelTube.begin(), kSteelTube.end());
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

TEST_CASE("graph: bad weights and options are errors before any exploration", "[cli]") {
  Outcome r = RunTool({"graph", SourcePath("scenes/groove.yaml"), "--weights", "friction=-1"});
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--weights: \"friction=-1\" is not a weight") != std::string::npos);
  r = RunTool({"graph", SourcePath("scenes/groove.yaml"), "--weights", "speed=1"});
  CHECK(r.exit_code == 2);
  r = RunTool({"plans", SourcePath("scenes/groove.yaml"), "--tremor", "3 N"});
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--tremor") != std::string::npos);
  r = RunTool({"graph", SourcePath("scenes/no-such-scene.yaml")});
  CHECK(r.exit_code == 2);
}

TEST_CASE("plans: writes each candidate as a plan file and a trajectory that loads",
          "[cli][explore]") {
  const std::string dir = "cli_test_plans";
  std::filesystem::remove_all(dir);
  const Outcome r = RunTool({"plans", SourcePath("scenes/groove.yaml"), "--k", "2", "--budget",
                             "100", "--time-limit", "0", "--jobs", "2", "--out-dir", dir});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  // Up to k: a small exploration's pruned graph may hold fewer ways to the goal; the written
  // ones are those whose replay was feasible, and evaluate judges their files the same.
  REQUIRE(r.out.find("groove-candidate-1: cost") != std::string::npos);
  const Outcome judged = RunTool({"evaluate", dir});
  INFO(judged.out);
  CHECK(judged.exit_code == 0);
  for (const std::string name : {"groove-candidate-1", "groove-candidate-2"}) {
    if (r.out.find(name + ": cost") == std::string::npos) continue;
    const std::string yaml = dir + "/" + name + ".yaml";
    REQUIRE(std::filesystem::exists(yaml));
    const std::size_t line = r.out.find(name + ": cost");
    const std::string said = r.out.substr(line, r.out.find('\n', line) - line);
    // Feasible, with the peak force that evaluate finds on its files.
    CHECK(said.find("; feasible") != std::string::npos);
    const std::string peak = "; peak operator force ";
    REQUIRE(said.find(peak) != std::string::npos);
    const std::string newtons = said.substr(said.find(peak) + peak.size());
    CHECK(newtons.ends_with(" N"));
    CHECK(judged.out.find("peak force " + newtons) != std::string::npos);
    const Outcome check = RunTool({"check", dir + "/" + name + ".csv"});
    CHECK(check.exit_code == 0);
    std::ifstream in(yaml);
    std::stringstream text;
    text << in.rdbuf();
    // The plan names its scene relative to itself, starts at {} and ends at the goal.
    CHECK(text.str().find("  - \"{}\"\n") != std::string::npos);
    CHECK(text.str().find("  - \"{Fs - floor.top}\"\nlimits:") != std::string::npos);
    const std::filesystem::path scene =
        std::filesystem::path(dir) /
        text.str().substr(text.str().find("scene: \"") + 8,
                          text.str().find("\"\ntrajectory") - text.str().find("scene: \"") - 8);
    CHECK(std::filesystem::equivalent(scene, SourcePath("scenes/groove.yaml")));
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("plans: the shelf scene from its file alone gives a verified plan", "[cli][explore]") {
  // A task of another kind than the groove: the tube carried over a shelf's edge and laid on its
  // top. 400 motions (about what the default 10 s explore on 2 cores), without the time limit so
  // that any machine explores the same graph, reach the goal; the best candidate replays feasible
  // within the device's force, and evaluate agrees on the written files.
  const std::filesystem::path dir = tubeplan::testing::ScratchDir("plans-shelf") / "out";
  const Outcome r = RunTool({"plans", SourcePath("scenes/shelf.yaml"), "--budget", "400",
                             "--time-limit", "0", "--jobs", "2", "--out-dir", dir.string()});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const std::size_t line = r.out.find("shelf-candidate-1: cost");
  REQUIRE(line != std::string::npos);
  const std::string said = r.out.substr(line, r.out.find('\n', line) - line);
  CHECK(said.find("-> {Fs - shelf.top}; feasible") != std::string::npos);
  const double peak_N = std::stod(said.substr(said.rfind("force ") + 6));
  CHECK(peak_N > 0.0);
  CHECK(peak_N < 8.5);
  const Outcome judged = RunTool({"evaluate", dir.string()});
  INFO(judged.out);
  CHECK(judged.exit_code == 0);
  std::filesystem::remove_all(tubeplan::testing::ScratchDir("plans-shelf"));
}

TEST_CASE("graph --check measures the graph against motions it did not make", "[cli][explore]") {
  // A budget of 40 motions leaves the shelf's graph unsaturated: 30 random motions of another
  // seed then find what it lacks, and the line's figures agree with each other. The graph
  // reaches the goal, so perturbed replays of its candidate plans are counted too.
  const Outcome r = RunTool({"graph", SourcePath("scenes/shelf.yaml"), "--budget", "40",
                             "--time-limit", "0", "--jobs", "2", "--check", "30"});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code != 2);
  const std::size_t at = r.out.find("completeness: 30 independent random guarded motions counted ");
  REQUIRE(at != std::string::npos);
  long states = 0, states_in = 0, arcs = 0, arcs_in = 0;
  REQUIRE(std::sscanf(r.out.c_str() + at,
                      "completeness: 30 independent random guarded motions counted %ld states, %ld "
                      "in the graph (%*f %%), and %ld transitions, %ld in it",
                      &states, &states_in, &arcs, &arcs_in) == 4);
  CHECK(states_in <= states);
  CHECK(arcs_in <= arcs);
  CHECK(states >= 3);
  // An unsaturated graph lacks something those motions reach, and each missing one is listed.
  CHECK(states_in + arcs_in < states + arcs);
  CHECK(r.out.find("  missing ") != std::string::npos);
  const std::size_t replays = r.out.find(" independent perturbed candidate replays counted ", at);
  REQUIRE(replays != std::string::npos);
  int replayed = 0;
  REQUIRE(std::sscanf(r.out.c_str() + r.out.rfind("completeness: ", replays),
                      "completeness: %d independent perturbed", &replayed) == 1);
  // As many copies of each candidate trajectory as make at least 30.
  CHECK(replayed >= 30);
}

// Runs `plans` on a shipped scene with 300 motions and checks its best candidate: it replays
// feasible into `goal`, with a peak operator force in (0, max_peak_N), and evaluate agrees on
// every plan written. Returns what `plans` printed.
std::string CheckBestPlanFeasible(const std::string& scene, const std::string& goal,
                                  double max_peak_N) {
  const std::string tag = "plans-" + scene;
  const std::filesystem::path dir = tubeplan::testing::ScratchDir(tag) / "out";
  const Outcome r = RunTool({"plans", SourcePath("scenes/" + scene + ".yaml"), "--budget", "300",
                             "--time-limit", "0", "--jobs", "2", "--out-dir", dir.string()});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const std::size_t line = r.out.find(scene + "-candidate-1: cost");
  REQUIRE(line != std::string::npos);
  const std::string said = r.out.substr(line, r.out.find('\n', line) - line);
  CHECK(said.find("-> " + goal + "; feasible") != std::string::npos);
  const double peak_N = std::stod(said.substr(said.rfind("force ") + 6));
  CHECK(peak_N > 0.0);
  CHECK(peak_N < max_peak_N);
  const Outcome judged = RunTool({"evaluate", dir.string()});
  INFO(judged.out);
  CHECK(judged.exit_code == 0);
  std::filesystem::remove_all(tubeplan::testing::ScratchDir(tag));
  return r.out;
}

// The states of a candidate's line of `plans`: "{} -> ... -> GOAL".
std::string PlannedStates(const std::string& out, const std::string& name) {
  const std::size_t line = out.find(name + ": ");
  if (line == std::string::npos) return {};
  const std::size_t from = out.find(" s: ", line) + 4;
  return out.substr(from, out.find("; ", from) - from);
}

TEST_CASE("plans: the pocket scene gives a verified plan that puts the tube's end in",
          "[cli][explore]") {
  // A hole entered end first: the tube hangs over a blind pocket and its end goes down onto the
  // pocket's floor. The goal's witness has the hand pushing on; the plan that holds comes from
  // aiming at the held end's poses. 300 motions keep the test short (about 10 s).
  // Set down, not pushed: under 1 N, where the device gives 8.5 N.
  CheckBestPlanFeasible("pocket", "{Fe - base.top}", 1.0);
}

TEST_CASE("check --elements lists a box's 26 elements and a cylinder's 5 by name", "[cli]") {
  const Outcome r = RunTool({"check", SourcePath("scenes/rail.yaml"), "--elements"});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  // The base plate: 6 faces, 12 edges, 8 vertices; the rail: 3 faces, 2 rims, no vertex.
  int faces = 0, edges = 0, vertices = 0;
  std::istringstream lines(r.out);
  for (std::string l; std::getline(lines, l);) {
    faces += l.rfind("  face ", 0) == 0;
    edges += l.rfind("  edge ", 0) == 0;
    vertices += l.rfind("  vertex ", 0) == 0;
  }
  CHECK(faces == 6 + 3);
  CHECK(edges == 12 + 2);
  CHECK(vertices == 8);
  for (const char* name : {"  face rail.side\n", "  edge rail.top_side\n",
                           "  edge rail.bottom_side\n", "  vertex base.top_xpos_ypos\n"})
    CHECK(r.out.find(name) != std::string::npos);
}

TEST_CASE("check --elements lists a mesh's elements, its edges convex or concave", "[cli]") {
  // The shipped clip on two floor slabs (a gap for its post), the scene and a copy of the clip
  // in a scratch directory: the mesh is read next to the scene file.
  const std::filesystem::path dir = tubeplan::testing::ScratchDir("check-clip");
  std::filesystem::copy_file(SourcePath("scenes/clip.obj"), dir / "clip.obj",
                             std::filesystem::copy_options::overwrite_existing);
  const std::string scene = tubeplan::testing::WriteScratch(
      "check-clip", "clip.yaml",
      "tubeplan: 1\nname: clip\n"
      "tube: {outer_radius: 5 mm, inner_radius: 4 mm, length: 150 mm, youngs_modulus: 3 MPa, "
      "poisson_ratio: 0.5}\n"
      "parts:\n"
      "  - name: floor\n"
      "    box: {size: [25 mm, 200 mm, 10 mm], position: [-17.5 mm, 0, -5 mm]}\n"
      "  - name: right\n"
      "    box: {size: [25 mm, 200 mm, 10 mm], position: [17.5 mm, 0, -5 mm]}\n"
      "  - name: clip\n"
      "    mesh: {file: clip.obj, scale: 0.001, position: [0, 20 mm, 0]}\n"
      "start: {position: [0, -90 mm, 40 mm]}\n"
      "goal: \"{Fs - clip.floor}\"\n");
  const Outcome r = RunTool({"check", scene, "--elements"});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  // Two boxes' 26 each; the clip's 16 faces, 38 edges (5 concave), 24 vertices
  // (tests/io/clip_mesh_test.cpp).
  int faces = 0, edges = 0, vertices = 0, convex = 0, concave = 0;
  std::istringstream lines(r.out);
  for (std::string l; std::getline(lines, l);) {
    faces += l.rfind("  face ", 0) == 0;
    edges += l.rfind("  edge ", 0) == 0;
    vertices += l.rfind("  vertex ", 0) == 0;
    convex += l.find(" (convex)") != std::string::npos;
    concave += l.find(" (concave)") != std::string::npos;
  }
  CHECK(faces == 2 * 6 + 16);
  CHECK(edges == 2 * 12 + 38);
  CHECK(vertices == 2 * 8 + 24);
  CHECK(convex == 33);
  CHECK(concave == 5);
  for (const char* name : {"  face clip.floor\n", "  edge clip.right_inner_floor (concave)\n",
                           "  edge clip.post_post_end (convex)\n", "  edge floor.top_xpos\n"})
    CHECK(r.out.find(name) != std::string::npos);
  // In JSON, a mesh edge carries "convex"; no other element does.
  const Outcome j = RunTool({"check", scene, "--elements", "--json"});
  REQUIRE(j.exit_code == 0);
  const auto elements = nlohmann::json::parse(j.out)["files"][0]["elements"];
  int with_convexity = 0;
  for (const auto& e : elements) {
    if (!e.contains("convex")) continue;
    ++with_convexity;
    CHECK(e["name"].get<std::string>().rfind("clip.", 0) == 0);
    CHECK(e["kind"] == "edge");
  }
  CHECK(with_convexity == 38);
}

TEST_CASE("plans: the rail scene gives a verified plan that hangs the tube over a round part",
          "[cli][explore]") {
  // A cylinder met along its curved side: the tube's side laid across a round rail, bent over
  // it. 300 motions reach the goal (about 12 s); the plan's replay ends there within the
  // device's force.
  CheckBestPlanFeasible("rail", "{Fs n rail.side}", 8.5);  // the device's force
}

TEST_CASE("check --elements lists a mesh part's elements as its file names them", "[cli]") {
  const Outcome r = RunTool({"check", SourcePath("scenes/clip.yaml"), "--elements"});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  // The base plate's 26 elements; the clip's 16 faces, 38 edges (5 concave: the U's four inner
  // corners and the post's foot) and 24 vertices (tools/make-clip-obj draws them).
  int faces = 0, edges = 0, concave = 0, vertices = 0;
  std::istringstream lines(r.out);
  for (std::string l; std::getline(lines, l);) {
    faces += l.rfind("  face ", 0) == 0;
    edges += l.rfind("  edge ", 0) == 0;
    concave += l.rfind("  edge ", 0) == 0 && l.find("(concave)") != std::string::npos;
    vertices += l.rfind("  vertex ", 0) == 0;
  }
  CHECK(faces == 6 + 16);
  CHECK(edges == 12 + 38);
  CHECK(concave == 5);
  CHECK(vertices == 8 + 24);
  for (const char* name : {"  face clip.floor\n", "  face clip.post\n"})
    CHECK(r.out.find(name) != std::string::npos);
}

TEST_CASE("plans: the clip scene gives a verified plan that lays the tube into a mesh part",
          "[cli][explore]") {
  // A part read from an OBJ file: the tube lowered between the clip's lips onto its floor. 300
  // motions reach the goal (about 16 s); the best candidate's replay ends there within the
  // device's force, and evaluate agrees.
  const std::string out = CheckBestPlanFeasible("clip", "{Fs n clip.floor}", 8.5);
  // The other two paths replay feasible too (evaluate judged every written one above), each
  // through states of its own.
  INFO(out);
  for (const char* name : {"clip-candidate-2: cost", "clip-candidate-3: cost"}) {
    const std::size_t at = out.find(name);
    REQUIRE(at != std::string::npos);
    CHECK(out.substr(at, out.find('\n', at) - at).find("-> {Fs n clip.floor}; feasible") !=
          std::string::npos);
  }
  const std::string states = PlannedStates(out, "clip-candidate-3");
  CHECK(states.starts_with("{} -> "));
  CHECK(states != PlannedStates(out, "clip-candidate-1"));
  CHECK(states != PlannedStates(out, "clip-candidate-2"));
  CHECK(PlannedStates(out, "clip-candidate-2") != PlannedStates(out, "clip-candidate-1"));
}

TEST_CASE("plans: the tilted groove's two-PC goal gives verified plans on a small budget",
          "[cli][explore]") {
  // Parts turned about a non-vertical axis and a goal of two PCs (the tube seated in the corner
  // of the floor and the left wall). 250 motions (a twelfth of the default budget) reach the goal;
  // every written candidate ends there and replays feasible within the device's force.
  const std::filesystem::path dir = tubeplan::testing::ScratchDir("plans-tilted") / "out";
  const Outcome r = RunTool({"plans", SourcePath("scenes/groove-tilted.yaml"), "--jobs", "2",
                             "--budget", "250", "--time-limit", "0", "--out-dir", dir.string()});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  int written = 0;
  for (std::size_t at = r.out.find("groove-tilted-candidate-"); at != std::string::npos;
       at = r.out.find("groove-tilted-candidate-", at + 1)) {
    const std::string said = r.out.substr(at, r.out.find('\n', at) - at);
    // Feasible, perhaps on a later try (which the line names), with its peak force.
    CHECK(said.find("-> {Fs n floor.top, Fs n left.inner}; feasible") != std::string::npos);
    CHECK(said.find("; peak operator force ") != std::string::npos);
    CHECK(std::stod(said.substr(said.rfind("force ") + 6)) < 8.5);
    ++written;
  }
  CHECK(written >= 1);
  const Outcome judged = RunTool({"evaluate", dir.string()});
  INFO(judged.out);
  CHECK(judged.exit_code == 0);
  std::filesystem::remove_all(tubeplan::testing::ScratchDir("plans-tilted"));
}

}  // namespace

// The groove scene with one line changed (`from` replaced by `to`), written to the scratch
// directory `tag`.
std::string GrooveWith(const std::string& tag, const std::string& from, const std::string& to) {
  std::string text = tubeplan::testing::Slurp(SourcePath("scenes/groove.yaml"));
  const std::size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  text.replace(at, from.size(), to);
  return tubeplan::testing::WriteScratch(tag, "scene.yaml", text);
}

TEST_CASE("plans: a goal the tube starts in is said, and no plan is written", "[cli]") {
  const std::string scene = GrooveWith("plans-start", "goal: \"{Fs - floor.top}\"", "goal: \"{}\"");
  const std::filesystem::path dir = tubeplan::testing::ScratchDir("plans-start") / "out";
  const Outcome r = RunTool({"plans", scene, "--out-dir", dir.string(), "--budget", "20"});
  CHECK(r.exit_code == 1);
  CHECK(r.out.empty());
  CHECK(r.err == scene +
                     ": nothing to plan: the goal {} is the state the tube starts in ({} at the "
                     "scene's start pose), so a plan would be that one state and no move; no plan "
                     "written. Give the scene a goal the tube has to be moved to\n");
  CHECK_FALSE(std::filesystem::exists(dir));
  std::filesystem::remove_all(tubeplan::testing::ScratchDir("plans-start"));
}

TEST_CASE("simulate: a strain beyond the material's elastic range gets evaluate's warning",
          "[cli]") {
  // A short fat tube held upright over a high-friction floor; the hand goes down 60 mm and aside
  // 10 mm, so the stuck tip folds the tube. At E = 10 kPa it folds to a bend radius near its
  // own radius (strain near 3, beyond the 0.5 an elastomer bends elastically to); at 3 MPa the
  // 100 N fold load is beyond the device and the tube stays almost straight.
  const std::string scene_text =
      "tubeplan: 1\nname: fold\n"
      "tube: {outer_radius: 20 mm, inner_radius: 15 mm, length: 100 mm, youngs_modulus: E, "
      "poisson_ratio: 0.5}\n"
      "contact: {stiffness: 10 N/mm, threshold: 1 mm}\n"
      "friction: {static: 2.0, kinetic: 1.5}\n"
      "parts:\n  - name: floor\n"
      "    box: {size: [300 mm, 300 mm, 10 mm], position: [0, 0, -5 mm]}\n"
      "start: {position: [0, 0, 103 mm], rpy: [180 deg, 0, 0]}\n"
      "goal: \"{Ee - floor.top}\"\n";
  const auto scene = [&](const std::string& E) {
    std::string text = scene_text;
    text.replace(text.find("E,"), 1, E);
    return tubeplan::testing::WriteScratch("simulate-fold", "fold-" + E.substr(0, 2) + ".yaml",
                                           text);
  };
  std::string csv = "t,px,py,pz,qw,qx,qy,qz\n";
  for (int k = 0; k <= 3000; ++k) {
    const double t = 1e-3 * k, u = std::min(t / 2.5, 1.0), s = u * u * (3.0 - 2.0 * u);
    char row[96];
    std::snprintf(row, sizeof row, "%.4f,%.6f,0,%.6f,0,1,0,0\n", t, 0.01 * s, 0.103 - 0.06 * s);
    csv += row;
  }
  const std::string trajectory = tubeplan::testing::WriteScratch("simulate-fold", "t.csv", csv);
  const Outcome r = RunTool({"simulate", scene("10 kPa"), trajectory});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  // The warning names the run's peak strain and its time, as the summary line gives them.
  const std::size_t peak = r.out.find("peak strain ");
  REQUIRE(peak != std::string::npos);
  const std::string at = r.out.substr(peak + 12, r.out.find(';', peak) - peak - 12);
  double strain = 0.0;
  REQUIRE(std::sscanf(at.c_str(), "%lf", &strain) == 1);
  CHECK(strain > 0.5);
  CHECK(r.out.find("\nwarning: strain " + at +
                   " is beyond the tube material's elastic range "
                   "(0.5 for E < 10 GPa)") != std::string::npos);
  const Outcome j = RunTool({"simulate", scene("10 kPa"), trajectory, "--json"});
  REQUIRE(j.exit_code == 0);
  const nlohmann::json json = nlohmann::json::parse(j.out);
  REQUIRE(json["warnings"].size() == 1);
  // The same sentence evaluate gives a plan (one function makes both).
  CHECK(r.out.find(json["warnings"][0].get<std::string>()) != std::string::npos);
  // The stiff tube stays within its range: no warning.
  const Outcome stiff = RunTool({"simulate", scene("3 MPa"), trajectory});
  CHECK(stiff.exit_code == 0);
  CHECK(stiff.out.find("warning:") == std::string::npos);
  std::filesystem::remove_all(tubeplan::testing::ScratchDir("simulate-fold"));
}

TEST_CASE("graph: the printout says which limit stopped the exploration", "[cli][explore]") {
  Outcome r = RunTool({"graph", SourcePath("scenes/groove.yaml"), "--budget", "1", "--time-limit",
                       "0", "--jobs", "2"});
  CHECK(r.exit_code == 1);  // one sweep does not reach the goal
  CHECK(r.out.find(" from 1 motions (1 sweep)") != std::string::npos);
  CHECK(r.out.find("(NOT saturated: stopped by the budget of 1 motions, with 0 of ") !=
        std::string::npos);
  CHECK(r.out.find("(saturated") == std::string::npos);
  // A limit shorter than any motion holds only once the goal is reached: the exploration goes on
  // until a group of motions reaches it (the sweeps and aims here), then stops, and says so.
  r = RunTool({"graph", SourcePath("scenes/groove.yaml"), "--time-limit", "0.001", "--json",
               tubeplan::testing::ScratchDir("graph-limit").string() + "/g.json"});
  CHECK(r.exit_code == 0);
  CHECK(r.out.find("(NOT saturated: stopped by the time limit of 0.001 s after ") !=
        std::string::npos);
  CHECK(r.out.find("goal {Fs - floor.top} reached") != std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(
      tubeplan::testing::Slurp(tubeplan::testing::ScratchDir("graph-limit") / "g.json"));
  CHECK(j["stats"]["ended_by"] == "time_limit");
  CHECK(j["parameters"]["time_limit_s"] == 0.001);
  // More than the first sweep, and far fewer than the budget's 3000 motions: the sweeps and aims
  // reach the goal.
  CHECK(j["motions"].size() > 1);
  CHECK(j["motions"].size() < 300);
  std::filesystem::remove_all(tubeplan::testing::ScratchDir("graph-limit"));
}

TEST_CASE("beam --json reports the cantilever's analytic tip figures", "[cli]") {
  const Outcome r = RunTool(Beam({"--tip-force", "0.5 N", "--json", "--at", "0,0,300 mm"}));
  REQUIRE(r.exit_code == 0);
  const auto doc = nlohmann::json::parse(r.out);
  // Independent of the library: I = pi (r1^4 - r2^4) / 4, delta = F l^3 / (3 E I).
  const double r1 = 3e-3, r2 = 2.5e-3, l = 0.3, E = 200e9, F = 0.5;
  const double I = std::numbers::pi * (std::pow(r1, 4) - std::pow(r2, 4)) / 4.0;
  const double EI = E * I;
  // The CLI prints what the library computed from parsed text: exact to a few ulps.
  const double kRel = 1e-12;
  CHECK(doc["tip_deflection"].get<double>() == Approx(F * l * l * l / (3 * EI)).epsilon(kRel));
  CHECK(doc["tip_angle"].get<double>() == Approx(F * l * l / (2 * EI)).epsilon(kRel));
  CHECK(doc["energy"].get<double>() == Approx(F * F * l * l * l / (6 * EI)).epsilon(kRel));
  CHECK(doc["strain"].get<double>() == Approx(r1 * F * l / EI).epsilon(kRel));
  CHECK(doc["alpha"].get<double>() == Approx(F * l * l / EI).epsilon(kRel));
  // The linear model does not shorten the tube.
  CHECK(doc["tip_shortening"].get<double>() == 0.0);
  // The displacement of the tip centre is the tip deflection along the force (x).
  REQUIRE(doc["points"].size() == 1);
  const auto& u = doc["points"][0]["displacement"];
  CHECK(u[0].get<double>() == Approx(F * l * l * l / (3 * EI)).epsilon(kRel));
  CHECK(u[1].get<double>() == 0.0);
}

TEST_CASE("beam: the elastica and the linear model agree for a small load", "[cli]") {
  // alpha ~ 1e-4 here: the elastica's deflection is below the linear one by ~ (2/7)... at order
  // alpha^2, i.e. ~1e-8 relative; 1e-6 leaves room and still fails for any real mismatch.
  const Outcome linear = RunTool(Beam({"--tip-force", "0.001", "--json"}));
  const Outcome elastica = RunTool(Beam({"--tip-force", "0.001", "--json", "--model", "elastica"}));
  REQUIRE(linear.exit_code == 0);
  REQUIRE(elastica.exit_code == 0);
  const auto a = nlohmann::json::parse(linear.out);
  const auto b = nlohmann::json::parse(elastica.out);
  CHECK(b["tip_deflection"].get<double>() ==
        Approx(a["tip_deflection"].get<double>()).epsilon(1e-6));
  CHECK(b["tip_shortening"].get<double>() > 0.0);
}

TEST_CASE("beam: a quantity with a unit equals the same quantity in SI", "[cli]") {
  const Outcome mm = RunTool(Beam({"--tip-force", "1000 mN", "--json"}));
  const Outcome si = RunTool(Beam({"--tip-force", "1", "--json"}));
  REQUIRE(mm.exit_code == 0);
  REQUIRE(si.exit_code == 0);
  CHECK(nlohmann::json::parse(mm.out)["tip_deflection"] ==
        nlohmann::json::parse(si.out)["tip_deflection"]);
}

TEST_CASE("beam: bad input is exit code 2 with a message naming the problem", "[cli]") {
  SECTION("a unit of the wrong dimension") {
    const Outcome r = RunTool(Beam({"--tip-force", "5 mm"}));
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--tip-force") && Catch::Contains("length") &&
                          Catch::Contains("force"));
  }
  SECTION("an inner radius not below the outer one") {
    const Outcome r = RunTool({"beam", "--outer-radius", "3mm", "--inner-radius", "3mm", "--length",
                               "1", "--youngs-modulus", "1GPa", "--poisson-ratio", "0.3"});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("inner_radius"));
  }
  SECTION("no tube at all") {
    const Outcome r = RunTool({"beam", "--tip-force", "1"});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--scene"));
  }
  SECTION("an unknown option") {
    const Outcome r = RunTool(Beam({"--bogus"}));
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--bogus"));
  }
  SECTION("an unknown model") {
    const Outcome r = RunTool(Beam({"--model", "timoshenko"}));
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("timoshenko"));
  }
  SECTION("a load beyond the elastica's range") {
    // alpha = 1e6 * 0.09 / 6.59 ~ 1.4e4 > 1e4.
    const Outcome r = RunTool(Beam({"--tip-force", "1e6", "--model", "elastica"}));
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("beyond the elastica's range"));
  }
  SECTION("a load whose results overflow") {
    const Outcome r = RunTool(Beam({"--tip-force", "1e300"}));
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("overflow"));
  }
  SECTION("a tube whose section underflows") {
    const Outcome r = RunTool({"beam", "--outer-radius", "1e-90", "--inner-radius", "0", "--length",
                               "1", "--youngs-modulus", "1e-100", "--poisson-ratio", "0.3"});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("bending stiffness"));
  }
  SECTION("a scene file that does not exist") {
    const Outcome r = RunTool({"beam", "--scene", "no/such/scene.yaml"});
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::StartsWith("no/such/scene.yaml: error:"));
  }
}

TEST_CASE("check: every shipped scene is valid and summarised in one line", "[cli]") {
  std::vector<std::string> args = {"check"};
  for (const auto& entry : std::filesystem::directory_iterator(SourcePath("scenes")))
    if (entry.path().extension() == ".yaml") args.push_back(entry.path().string());
  REQUIRE(args.size() >= 3);  // groove.yaml and groove-steel.yaml at least
  const Outcome r = RunTool(args);
  CHECK(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK(static_cast<std::size_t>(std::count(r.out.begin(), r.out.end(), '\n')) == args.size() - 1);
}

TEST_CASE("check: a broken scene is exit code 2 with file:line:col diagnostics", "[cli]") {
  const std::string broken = SourcePath("tests/data/scenes/cli-several-errors.yaml");
  const std::string good = SourcePath("scenes/groove.yaml");
  const Outcome r = RunTool({"check", good, broken});
  CHECK(r.exit_code == 2);
  // The good file is still summarised; every diagnostic line is about the broken one.
  CHECK_THAT(r.out, Catch::Contains(good + ": ok:"));
  std::istringstream lines(r.err);
  int count = 0;
  for (std::string line; std::getline(lines, line); ++count)
    CHECK_THAT(line, Catch::StartsWith(broken + ":") && Catch::Contains(": error: "));
  CHECK(count >= 2);

  const Outcome json = RunTool({"check", "--json", broken});
  CHECK(json.exit_code == 2);
  const auto doc = nlohmann::json::parse(json.out);
  CHECK(doc["files"][0]["valid"] == false);
  CHECK(doc["files"][0]["diagnostics"].size() == static_cast<std::size_t>(count));
}

TEST_CASE("bench prints one finite figure set per scenario", "[cli][bench-report]") {
  // Only the shape of the report is tested: speed is measured by running `tubeplan bench`,
  // never asserted in a test.
  const Outcome r =
      RunTool({"bench", "--samples", "10", "--json", "--scene", SourcePath("scenes/groove.yaml")});
  REQUIRE(r.exit_code == 0);
  const auto doc = nlohmann::json::parse(r.out);
  REQUIRE(doc["scenarios"].size() == 16);
  std::map<std::string, int> pcs;
  std::map<std::string, std::string> shape;
  for (const auto& s : doc["scenarios"]) {
    const double median = s["median_us"].get<double>();
    CHECK(std::isfinite(median));
    CHECK(median > 0.0);
    CHECK(s["p99_us"].get<double>() >= median);
    CHECK(s["max_us"].get<double>() >= s["p99_us"].get<double>());
    if (s.contains("state")) {
      // A core scenario's ticks are also timed on replica cores with the same history (exit 0:
      // their results agreed); a tick's own cost is the least of its times, so every order
      // statistic of the own figures is at most the same one of the first core's.
      REQUIRE(s.contains("own"));
      CHECK(s["replicas"].get<int>() == 3);
      CHECK(s["target_p999_judged_on"] == "own.p999_us");
      CHECK(s["own"]["median_us"].get<double>() <= median);
      CHECK(s["own"]["p999_us"].get<double>() <= s["p999_us"].get<double>());
      CHECK(s["own"]["max_us"].get<double>() <= s["max_us"].get<double>());
      CHECK(s["own"]["p999_us"].get<double>() >= s["own"]["median_us"].get<double>());
      pcs[s["name"].get<std::string>()] = s["state"]["pcs"].get<int>();
      shape[s["name"].get<std::string>()] = s["state"]["model"].get<std::string>();
    }
  }
  // The core scenarios measure the states their names say.
  CHECK(pcs["core.free"] == 0);
  CHECK(pcs["core.end_stuck"] == 1);
  CHECK(pcs["core.end_sliding"] == 1);
  CHECK(pcs["core.side_on_floor"] == 1);
  CHECK(pcs["core.two_pcs"] == 2);
  CHECK(pcs["core.three_pcs"] == 3);
  CHECK(pcs["core.three_pcs.linear"] == pcs["core.three_pcs"]);
  // The floor as a mesh holds the tube as the box does.
  CHECK(pcs["core.end_stuck.mesh10k"] == 1);
  CHECK(pcs["core.side_on_floor.mesh10k"] == 1);
  // And the models their names say.
  CHECK(shape["core.end_stuck"] == "rod");
  CHECK(shape["core.end_stuck.linear"] == "linear");

  // --only keeps the scenarios whose names start with it; a prefix no name has is an error.
  const Outcome only = RunTool({"bench", "--samples", "10", "--json", "--only", "core.end_stuck",
                                "--scene", SourcePath("scenes/groove.yaml")});
  REQUIRE(only.exit_code == 0);
  const auto only_doc = nlohmann::json::parse(only.out);
  CHECK(only_doc["scenarios"].size() == 4);  // core.end_stuck, .mesh10k, .mesh, .linear
  const Outcome none =
      RunTool({"bench", "--only", "core.nothing", "--scene", SourcePath("scenes/groove.yaml")});
  CHECK(none.exit_code == 2);
  CHECK_THAT(none.err, Catch::Contains("core.nothing") && Catch::Contains("core.free"));
}

TEST_CASE("stability: the fast passes hold, or say why the scene cannot", "[cli][stability]") {
  // A tube pushed at 2 m/s at a 1 mm wall in every variant of the sweep: none goes through,
  // except where the penalty cannot hold the device's force before the wall's middle, which is
  // named as outside the model's validity (K = 10 N/mm at eps = 10 um: 5.1 N < 8.5 N).
  const Outcome r = RunTool({"stability", "--quick", "--only", "fast pass", "--json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json doc = nlohmann::json::parse(r.out);
  REQUIRE(doc["cases"].size() >= 10);
  int outside = 0;
  for (const nlohmann::json& c : doc["cases"]) {
    INFO(c.dump());
    CHECK(c["pass"] == true);
    if (c["outside_validity"] == true) ++outside;
    if (c["name"] == "fast pass base") {
      CHECK(c["outside_validity"] == false);
      CHECK(c["warning"].is_null());
    }
    if (c["name"] == "fast pass eps=1e-05m")
      CHECK_THAT(c["warning"].get<std::string>(),
                 Catch::Contains("penalty too soft for a 0.001 m part") &&
                     Catch::Contains("no tunnelling"));
  }
  CHECK(outside < int(doc["cases"].size()) / 2);
}

TEST_CASE("usage: no subcommand and --version", "[cli]") {
  const std::string commands =
      "; the commands are check, beam, bench, simulate, graph, plans, evaluate, merge, live, "
      "accuracy, stability (tubeplan --help says what each does)\n";
  const Outcome none = RunTool({});
  CHECK(none.exit_code == 2);
  CHECK(none.err == "tubeplan: error: no command given" + commands);
  // A word where the command belongs is named, not "A subcommand is required".
  const Outcome unknown = RunTool({"frobnicate", "x.yaml"});
  CHECK(unknown.exit_code == 2);
  CHECK(unknown.err == "tubeplan: error: unknown command 'frobnicate'" + commands);
  const Outcome v = RunTool({"--version"});
  CHECK(v.exit_code == 0);
  CHECK_THAT(v.out, Catch::Contains("tubeplan"));
}

TEST_CASE("check: trajectories are checked by their .csv extension", "[cli]") {
  const std::string good = SourcePath("tests/data/trajectories/good.csv");
  const Outcome r = RunTool({"check", good});
  CHECK(r.exit_code == 0);
  // 3 samples 4 ms apart: 0.008 s at a mean rate of 250 Hz.
  CHECK_THAT(r.out, Catch::Contains("3 samples over 0.008 s (mean rate 250 Hz"));
  const Outcome missing = RunTool({"check", "no/such.csv"});
  CHECK(missing.exit_code == 2);
  CHECK(missing.err ==
        "no/such.csv: error: cannot read file (no such file), expected a readable CSV "
        "trajectory\n");
}

namespace {

// Fields of one CSV line (RFC 4180: a quoted field may hold commas; the series quotes only the CF).
std::vector<std::string> CsvFields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (const char c : line) {
    if (c == '"')
      quoted = !quoted;
    else if (c == ',' && !quoted)
      fields.emplace_back();
    else
      fields.back() += c;
  }
  return fields;
}

}  // namespace

TEST_CASE("simulate --out: every row has the header's columns; a PC's friction work is its slip's",
          "[cli]") {
  // The shipped insertion: its end face slides on the floor, its side lies down on it.
  const std::string csv = "cli_test_series.csv", jsonl = "cli_test_series.jsonl";
  for (const std::string& out : {csv, jsonl}) {
    const Outcome r = RunTool({"simulate", SourcePath("scenes/groove.yaml"),
                               SourcePath("plans/groove-insert.csv"), "--out", out});
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
  }
  std::istringstream text(tubeplan::testing::Slurp(csv));
  std::string line;
  REQUIRE(std::getline(text, line));
  const std::vector<std::string> header = CsvFields(line);
  std::map<std::string, std::size_t> column;
  for (std::size_t i = 0; i < header.size(); ++i) column[header[i]] = i;
  for (int k = 1; k <= 6; ++k) REQUIRE(column.contains("pc" + std::to_string(k) + "_work"));
  std::ifstream lines(jsonl);
  int rows = 0, sliding = 0;
  double total_J = 0.0;
  while (std::getline(text, line)) {
    const std::vector<std::string> f = CsvFields(line);
    REQUIRE(f.size() == header.size());
    std::string json_line;
    REQUIRE(std::getline(lines, json_line));
    const nlohmann::json j = nlohmann::json::parse(json_line);
    ++rows;
    const int n = std::stoi(f[column.at("n_pc")]);
    REQUIRE(int(j.at("contacts").size()) == n);
    for (int k = 1; k <= n; ++k) {
      const std::string p = "pc" + std::to_string(k);
      const double work = std::stod(f[column.at(p + "_work")]);
      INFO("t " << f[0] << " " << p << " " << f[column.at(p)] << ": " << work << " J");
      // Dissipated, never returned. A PC reads stuck while the points bearing most of its load
      // stick; a light point at the band's edge may slip meanwhile (measured up to 6e-10 J a
      // tick, against 3e-5 J over the run).
      CHECK(work >= 0.0);
      if (f[column.at(p + "_state")] == "stuck") CHECK(work <= 1e-8);
      sliding += f[column.at(p + "_state")] == "sliding";
      total_J += work;
      // The same number in both formats (CSV prints 17 significant digits: the same double).
      CHECK(j["contacts"][std::size_t(k - 1)].at("work").get<double>() == work);
    }
  }
  CHECK(rows == 5501);  // 5.5 s at 1 kHz, and the row at t = 0
  CHECK(sliding > 100);
  // The end face's slide on the floor and the lay-down: a few tens of microjoules (f_k ~ 5 mN
  // over millimetres), not the 2.86 mJ that counting a jump of the deepest point along the lying
  // side would give (docs/evaluate.md).
  CHECK(total_J > 1e-6);
  CHECK(total_J < 2e-4);
  std::filesystem::remove(csv);
  std::filesystem::remove(jsonl);
}
