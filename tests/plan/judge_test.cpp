// The batch evaluation: the shipped plans get their expected verdicts, a force limit is reported
// at the tick an independent replay finds, the report does not depend on --jobs, and bad plan
// files get exact messages.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/trajectories/perturb.hpp>

#include "cli/app.hpp"

namespace {

using namespace tubeplan;

std::string SourcePath(const std::string& relative) {
  return std::string(TUBEPLAN_SOURCE_DIR) + "/" + relative;
}

struct Outcome {
  int exit_code = -1;
  std::string out, err;
};

Outcome RunTool(std::vector<std::string> args) {
  std::ostringstream out, err;
  const int code = cli::Run(args, out, err);
  return {code, out.str(), err.str()};
}

nlohmann::json EvaluateShipped(const std::string& jobs) {
  const Outcome r = RunTool({"evaluate", SourcePath("plans"), "--json", "--jobs", jobs});
  INFO(r.err);
  REQUIRE(r.exit_code == 1);  // two shipped plans are infeasible by design
  return nlohmann::json::parse(r.out);
}

const nlohmann::json& PlanNamed(const nlohmann::json& report, const std::string& name) {
  for (const nlohmann::json& p : report["plans"])
    if (p["plan"] == name) return p;
  FAIL("no plan " << name);
  return report;
}

TEST_CASE("The shipped plans get their expected verdicts", "[plan]") {
  const nlohmann::json report = EvaluateShipped("2");
  CHECK(report["tubeplan_evaluate"] == 3);
  CHECK(report["summary"]["plans"] == 5);
  CHECK(report["summary"]["feasible"] == 3);

  // The side lands on the floor still bent for a moment (40 ms) before the tube straightens:
  // a detour the plan does not name.
  const nlohmann::json& insert = PlanNamed(report, "groove-insert");
  CHECK(insert["feasible"] == true);
  CHECK(insert["transitions"][0]["verdict"] == "feasible");
  CHECK(insert["transitions"][1]["verdict"] == "feasible");
  CHECK(insert["transitions"][2]["verdict"] == "feasible-with-detour");
  CHECK(insert["transitions"][2]["detour"] == nlohmann::json::array({"{Fs n floor.top}"}));

  const nlohmann::json& coarse = PlanNamed(report, "groove-insert-coarse");
  CHECK(coarse["feasible"] == true);
  CHECK(coarse["transitions"][1]["verdict"] == "feasible-with-detour");
  CHECK(coarse["transitions"][1]["detour"] ==
        nlohmann::json::array({"{Ee ~ floor.top}", "{Fs n floor.top}"}));

  CHECK(PlanNamed(report, "groove-lay-flat")["feasible"] == true);

  const nlohmann::json& wrong = PlanNamed(report, "groove-wrong-side");
  CHECK(wrong["feasible"] == false);
  CHECK(wrong["transitions"][0]["verdict"] == "infeasible");
  CHECK(wrong["transitions"][0]["reason"] ==
        "another state reached instead: {Fs - floor.top}, planned later, before "
        "{Fs - right.top}");
  CHECK(wrong["transitions"][1]["reason"] ==
        "not reached: the plan failed at an earlier transition");
}

TEST_CASE("A force limit is reported at the tick the force first exceeds it", "[plan]") {
  const nlohmann::json report = EvaluateShipped("1");
  const nlohmann::json& gentle = PlanNamed(report, "groove-gentle");
  CHECK(gentle["feasible"] == false);
  const nlohmann::json& last = gentle["transitions"][2];
  CHECK(last["verdict"] == "infeasible");
  const std::string reason = last["reason"];
  // An independent replay of the same trajectory through the core: the first tick after the
  // tube entered {Ee ~ floor.top} at which the operator force exceeds 0.05 N.
  const io::PlanLoadResult loaded = io::LoadPlanFile(SourcePath("plans/groove-gentle.yaml"));
  REQUIRE(loaded.plan);
  const std::vector<trajectories::HandSample> ticks =
      trajectories::Resample(*loaded.trajectory, loaded.scene->model.time_step_s);
  core::Core core(*loaded.scene);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = ticks.front().q_WH.toRotationMatrix();
  X.translation() = ticks.front().p_WH_m;
  core.Reset(X);
  double first_t = -1.0, force = 0.0;
  for (const trajectories::HandSample& s : ticks) {
    X.linear() = s.q_WH.toRotationMatrix();
    X.translation() = s.p_WH_m;
    const core::StepOutput& out = core.Step(s.t_s, X);
    if (s.t_s >= last["t_start_s"].get<double>() && out.force_W_N.norm() > 0.05) {
      first_t = s.t_s, force = out.force_W_N.norm();
      break;
    }
  }
  REQUIRE(first_t > 0.0);
  char expected[160];
  std::snprintf(expected, sizeof expected,
                "limit exceeded: operator force %.4g N > 0.05 N at t = %.3f s", force, first_t);
  CHECK(reason == expected);
  // Earlier transitions stay below the limit (their peaks are reported and below 0.05 N).
  for (int i = 0; i < 2; ++i) CHECK(gentle["transitions"][i]["peak_force_N"] < 0.05);
}

TEST_CASE("The report is the same for any --jobs and is written whole", "[plan]") {
  nlohmann::json one = EvaluateShipped("1");
  nlohmann::json two = EvaluateShipped("2");
  CHECK(one == two);
  const std::string report = "judge_test_report.json";
  std::filesystem::remove(report);
  const Outcome r = RunTool({"evaluate", SourcePath("plans"), "--jobs", "2", "--report", report});
  CHECK(r.exit_code == 1);
  std::ifstream in(report);
  REQUIRE(in);
  CHECK(nlohmann::json::parse(in) == two);
  for (const auto& e : std::filesystem::directory_iterator("."))
    CHECK(e.path().filename().string().find(report + ".tmp") == std::string::npos);
  std::filesystem::remove(report);
}

TEST_CASE("Bad plan files get every problem at once, and nothing is evaluated", "[plan]") {
  const std::filesystem::path dir = "judge_test_plans";
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir / "bad.yaml");
    f << "tubeplan: 1\n"
         "plan: bad\n"
         "scene: "
      << SourcePath("scenes/groove.yaml")
      << "\n"
         "trajectory: "
      << SourcePath("plans/groove-insert.csv")
      << "\n"
         "states: [\"{}\", \"{Fs - flor.top}\", \"{Fe u floor.top}\"]\n"
         "limits: {max_force: 5 mm, dwel: 20 ms}\n";
  }
  const Outcome r = RunTool({"evaluate", (dir / "bad.yaml").string()});
  CHECK(r.exit_code == 2);
  CHECK(r.out.empty());
  // Columns: the element's name inside the quoted CF (5:23), the marker that Fe cannot carry
  // (5:40), the unit of the quantity (6:23), the unknown key (6:27).
  const std::string file = (dir / "bad.yaml").string();
  CHECK(r.err ==
        file +
            ":5:23: error: states[1]: no element 'flor.top' in this scene, did you mean "
            "'floor.top'? (expected part.face, part.face_face or part.face_face_face)\n" +
            file + ":5:40: error: states[2]: " +
            states::ParseContactFormation("{Fe u floor.top}").error->message + "\n" + file +
            ":6:23: error: limits.max_force: has a unit of length (mm), expected a force such "
            "as \"2 N\"\n" +
            file +
            ":6:27: error: unknown key 'dwel' in 'limits', did you mean 'dwell'? "
            "(expected one of: max_force, max_strain, max_penetration, dwell, stall)\n");
  std::filesystem::remove_all(dir);
}

TEST_CASE("A plan replayed from its trajectory file row by row gets the same judgement",
          "[plan][stream]") {
  // evaluate without --monte-carlo streams the trajectory; with it, it loads it whole. Both must
  // give the same bits: the same ticks into the same core.
  for (const char* name : {"groove-insert", "groove-insert-coarse", "groove-gentle",
                           "groove-lay-flat", "groove-wrong-side"}) {
    CAPTURE(name);
    const std::string path = SourcePath(std::string("plans/") + name + ".yaml");
    const io::PlanLoadResult memory = io::LoadPlanFile(path);
    const io::PlanLoadResult streamed = io::LoadPlanFile(path, {.trajectory_in_memory = false});
    REQUIRE(memory.trajectory);
    REQUIRE(streamed.trajectory_file);
    CHECK_FALSE(streamed.trajectory);
    const plan::Judgement a =
        plan::Judge(*memory.scene, *memory.trajectory, memory.plan->states, memory.plan->limits);
    io::TrajectoryFileSamples samples(*streamed.trajectory_file);
    trajectories::SampleTicks ticks(samples, streamed.trajectory_file->t_first_s,
                                    streamed.trajectory_file->t_last_s,
                                    streamed.scene->model.time_step_s);
    const plan::Judgement b =
        plan::Judge(*streamed.scene, ticks, streamed.plan->states, streamed.plan->limits);
    CHECK(b.feasible == a.feasible);
    CHECK(b.ticks == a.ticks);
    CHECK(b.replayed_s == a.replayed_s);
    REQUIRE(b.observed.size() == a.observed.size());
    for (std::size_t i = 0; i < a.observed.size(); ++i) {
      CHECK(b.observed[i].cf == a.observed[i].cf);
      CHECK(b.observed[i].t_s == a.observed[i].t_s);
    }
    REQUIRE(b.transitions.size() == a.transitions.size());
    for (std::size_t i = 0; i < a.transitions.size(); ++i) {
      const plan::TransitionVerdict &x = a.transitions[i], &y = b.transitions[i];
      CHECK(y.verdict == x.verdict);
      CHECK(y.reason == x.reason);
      CHECK(y.detour == x.detour);
      CHECK(y.t_start_s == x.t_start_s);
      CHECK(y.t_end_s == x.t_end_s);
      CHECK(y.peak_force_N == x.peak_force_N);
      CHECK(y.friction_work_J == x.friction_work_J);
      CHECK(y.energy_entry_J == x.energy_entry_J);
      CHECK(y.energy_exit_J == x.energy_exit_J);
    }
  }
}

TEST_CASE("A plan's bad trajectory gets the same messages streamed and in memory",
          "[plan][stream]") {
  const std::filesystem::path dir = "judge_test_stream_plans";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bad.csv")
      << "t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.001,0,x,0,1,0,0,0\n";
  for (const std::string trajectory :
       {"bad.csv", "missing.csv", ".", "/dev/zero", "../judge_test_stream_plans/bad.csv"}) {
    CAPTURE(trajectory);
    std::ofstream(dir / "p.yaml")
        << "tubeplan: 1\nplan: p\nscene: "
        << std::filesystem::absolute(SourcePath("scenes/groove.yaml")).string()
        << "\ntrajectory: " << trajectory << "\nstates: [\"{}\", goal]\n";
    const io::PlanLoadResult memory = io::LoadPlanFile(dir / "p.yaml");
    const io::PlanLoadResult streamed =
        io::LoadPlanFile(dir / "p.yaml", {.trajectory_in_memory = false});
    CHECK_FALSE(streamed.plan);
    CHECK_FALSE(streamed.trajectory_file);
    CHECK(memory.diagnostics.HasErrors());
    CHECK(streamed.diagnostics.FormatAll() == memory.diagnostics.FormatAll());
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("Shards merged give the unsharded report", "[plan]") {
  const nlohmann::json whole = EvaluateShipped("2");
  std::vector<std::string> merge = {"merge", "--json"};
  for (const char* shard : {"1/3", "2/3", "3/3"}) {
    const std::string file = std::string("judge_test_shard_") + shard[0] + ".json";
    const Outcome r =
        RunTool({"evaluate", SourcePath("plans"), "--shard", shard, "--report", file, "--json"});
    CHECK((r.exit_code == 0 || r.exit_code == 1));
    // Five plans in three shards: 2, 2 and 1 of them.
    CHECK(nlohmann::json::parse(r.out)["summary"]["plans"] == (shard[0] == '3' ? 1 : 2));
    merge.push_back(file);
  }
  const Outcome merged = RunTool(merge);
  CHECK(merged.exit_code == 1);
  CHECK(nlohmann::json::parse(merged.out) == whole);
  // The same shard twice is an error, not a double count.
  const Outcome twice = RunTool({"merge", merge[2], merge[2]});
  CHECK(twice.exit_code == 2);
  for (std::size_t i = 2; i < merge.size(); ++i) std::filesystem::remove(merge[i]);
  CHECK(RunTool({"evaluate", SourcePath("plans"), "--shard", "4/3"}).exit_code == 2);
}

TEST_CASE("Wilson intervals and perturbed trajectories", "[plan]") {
  // Known values of the 95 % Wilson score interval (e.g. Newcombe 1998, Table I: 8/10 gives
  // 0.490 .. 0.943; 0/10 gives 0 .. 0.278).
  const trajectories::Interval a = trajectories::WilsonInterval(8, 10);
  CHECK(a.low == Approx(0.4902).margin(5e-5));
  CHECK(a.high == Approx(0.9433).margin(5e-5));
  const trajectories::Interval b = trajectories::WilsonInterval(0, 10);
  CHECK(b.low == 0.0);
  CHECK(b.high == Approx(0.2775).margin(5e-5));
  CHECK(trajectories::WilsonInterval(10, 10).low == Approx(1.0 - 0.2775).margin(5e-5));

  const io::PlanLoadResult loaded = io::LoadPlanFile(SourcePath("plans/groove-insert.yaml"));
  REQUIRE(loaded.trajectory);
  const trajectories::Trajectory& nominal = *loaded.trajectory;
  // No perturbation: the same samples, bit for bit.
  const trajectories::Trajectory same = trajectories::Perturb(nominal, {0.0, 0.0, 1.0, 1.0}, 7, 3);
  REQUIRE(same.samples.size() == nominal.samples.size());
  for (std::size_t i = 0; i < same.samples.size(); i += 251) {
    CHECK(same.samples[i].t_s == nominal.samples[i].t_s);
    CHECK(same.samples[i].p_WH_m == nominal.samples[i].p_WH_m);
  }
  // The defaults: the offset stays within 1 mm plus the tremor's reach, the duration within the
  // speed range, and another replicate differs.
  const trajectories::Perturbation p;
  for (int r = 0; r < 20; ++r) {
    const trajectories::Trajectory t = trajectories::Perturb(nominal, p, 7, r);
    const double duration = t.samples.back().t_s - t.samples.front().t_s;
    const double nominal_duration = nominal.samples.back().t_s - nominal.samples.front().t_s;
    CHECK(duration >= nominal_duration / p.speed_max - 1e-12);
    CHECK(duration <= nominal_duration / p.speed_min + 1e-12);
    CHECK((t.samples.front().p_WH_m - nominal.samples.front().p_WH_m).norm() <=
          p.offset_m + std::sqrt(3.0) * p.tremor_m + 1e-12);
  }
  CHECK(trajectories::Perturb(nominal, p, 7, 0).samples[100].p_WH_m !=
        trajectories::Perturb(nominal, p, 7, 1).samples[100].p_WH_m);
}

TEST_CASE("Monte-Carlo robustness is the same for any --jobs", "[plan]") {
  auto run = [](const char* jobs) {
    const Outcome r = RunTool({"evaluate", SourcePath("plans/groove-lay-flat.yaml"),
                               SourcePath("plans/groove-insert.yaml"), "--monte-carlo", "2",
                               "--json", "--jobs", jobs});
    REQUIRE(r.exit_code == 0);
    return nlohmann::json::parse(r.out);
  };
  const nlohmann::json one = run("1");
  CHECK(one == run("2"));
  for (const nlohmann::json& p : one["plans"]) {
    for (const nlohmann::json& t : p["transitions"]) {
      const nlohmann::json& mc = t["monte_carlo"];
      CHECK(mc["runs"] == 2);
      CHECK(mc["feasible"] >= 0);
      CHECK(mc["feasible"] <= 2);
      CHECK(mc["ci95"][0] <= mc["fraction"]);
      CHECK(mc["fraction"] <= mc["ci95"][1]);
    }
  }
}

}  // namespace

TEST_CASE("Ticks beyond the linear range or whose solve stopped short are timed", "[plan]") {
  // Synthetic ticks with no contact (the CF stays {}, the first planned state): 50 plain, 30
  // flagged beyond_linear, 20 plain. The transition {} -> {Fe - wall.xneg} is under way all along
  // and gets the 30 flagged ticks' time, 30 steps of 1 ms (summed: rounding only, 1e-12).
  plan::Judging judging({"{}", "{Fe - wall.xneg}"}, plan::Limits{}, 1e-3);
  core::StepOutput out;
  const auto text = [] { return std::string("{}"); };
  for (int k = 0; k < 100; ++k) {
    out.flags = (k >= 50 && k < 80) ? core::kBeyondLinearRange : 0u;
    // And 12 whose solve stopped short (core::kNotConverged), 5 of them among those 30: each
    // flag is timed alone.
    if (k >= 75 && k < 87) out.flags |= core::kNotConverged;
    judging.Tick(1e-3 * (k + 1), out, text);
  }
  const plan::Judgement j = judging.Finish();
  REQUIRE(j.transitions.size() == 1);
  CHECK(j.transitions[0].FlaggedSeconds(core::kBeyondLinearRange) == Approx(0.030).margin(1e-12));
  CHECK(j.transitions[0].FlaggedSeconds(core::kNotConverged) == Approx(0.012).margin(1e-12));
  CHECK(j.transitions[0].FlaggedSeconds(core::kSolverFault) == 0.0);
  CHECK(j.transitions[0].verdict == plan::Verdict::kInfeasible);
}

TEST_CASE("A detour lists every state passed, returns to the span's start too", "[plan]") {
  // Synthetic ticks, 30 of each state in turn (the dwell is 20): the planned start {}, an
  // unplanned X, back to {}, X again, then the planned goal. The span {} -> goal passed X, {}, X.
  plan::Judging judging({"{}", "{Fe - wall.xneg}"}, plan::Limits{}, 1e-3);
  const std::vector<std::string> texts = {"{}", "{Ee - wall.xneg}", "{Fe - wall.xneg}"};
  const std::vector<int> sequence = {0, 1, 0, 1, 2};
  core::StepOutput out;
  int state = 0, tick = 0;
  const auto text = [&] { return texts[std::size_t(state)]; };
  for (const int s : sequence) {
    state = s;
    out.contact_count = s == 0 ? 0 : 1;
    // Another tube element on the same part element: another state's key.
    out.contacts[0].part_element = 3;
    out.contacts[0].tube = s == 1 ? states::TubeElement::kEndRim : states::TubeElement::kEndFace;
    for (int k = 0; k < 30; ++k) judging.Tick(1e-3 * ++tick, out, text);
  }
  const plan::Judgement j = judging.Finish();
  REQUIRE(j.transitions.size() == 1);
  CHECK(j.transitions[0].verdict == plan::Verdict::kFeasibleWithDetour);
  CHECK(j.transitions[0].detour ==
        std::vector<std::string>{"{Ee - wall.xneg}", "{}", "{Ee - wall.xneg}"});
}

TEST_CASE("A limit's message reads right: one space a word, the device's clamp said", "[plan]") {
  const auto reason = [](const std::function<void(core::StepOutput&)>& set) {
    plan::Limits limits;
    limits.max_force_N = 8.5;
    limits.max_strain = 0.2;
    plan::Judging judging({"{}", "{Fe - wall.xneg}"}, limits, 1e-3);
    core::StepOutput out;
    judging.Tick(1e-3, out, [] { return std::string("{}"); });
    set(out);
    judging.Tick(2e-3, out, [] { return std::string("{}"); });
    return judging.Finish().transitions[0].reason;
  };
  // A strain has no unit: no doubled spaces around the missing one.
  CHECK(reason([](core::StepOutput& o) { o.max_strain = 0.9263; }) ==
        "limit exceeded: strain 0.9263 > 0.2 at t = 0.002 s");
  // The force held at the device's clamp with a limit set to it: the motion asks more, so the
  // limit is exceeded whether the clamped force rounds a little over the limit, to it, or a
  // little under it; and said so.
  for (const double clamped_N : {std::nextafter(8.5, 9.0), 8.5, std::nextafter(8.5, 8.0)}) {
    CHECK(reason([&](core::StepOutput& o) {
            o.force_W_N = Eigen::Vector3d(0.0, 0.0, clamped_N);
            o.flags = core::kForceClamped;
          }) ==
          "limit exceeded: operator force 8.5 N at the device's clamp (the motion asks more than "
          "it renders), limit 8.5 N at t = 0.002 s");
  }
  // Clamped below a plan's higher limit (a device weaker than the plan allows): within it.
  CHECK(reason([](core::StepOutput& o) {
          o.force_W_N = Eigen::Vector3d(0.0, 0.0, 8.0);
          o.flags = core::kForceClamped;
        }).find("limit exceeded") == std::string::npos);
  // The torque clamped (the same flag) with the force over a lower plan limit: the force's
  // own message.
  CHECK(reason([](core::StepOutput& o) {
          o.force_W_N = Eigen::Vector3d(0.0, 0.0, 9.0);
          o.flags = core::kForceClamped;
        }) == "limit exceeded: operator force 9 N > 8.5 N at t = 0.002 s");
  // Unclamped, a force at the limit is within it.
  CHECK(reason([](core::StepOutput& o) {
          o.force_W_N = Eigen::Vector3d(0.0, 0.0, 8.5);
        }).find("limit exceeded") == std::string::npos);
  CHECK(reason([](core::StepOutput& o) { o.force_W_N = Eigen::Vector3d(9.0, 0.0, 0.0); }) ==
        "limit exceeded: operator force 9 N > 8.5 N at t = 0.002 s");
}

TEST_CASE("A plan's limit out of range is said with its value as written and both bounds",
          "[plan]") {
  const std::filesystem::path dir = "judge_test_ranges";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "p.yaml") << "tubeplan: 1\nplan: p\nscene: "
                                << SourcePath("scenes/groove.yaml")
                                << "\ntrajectory: " << SourcePath("plans/groove-insert.csv")
                                << "\nstates: [\"{}\", goal]\n"
                                   "limits: {max_force: 1e300 N, stall: 0}\n";
  const io::PlanLoadResult loaded = io::LoadPlanFile(dir / "p.yaml");
  const std::string file = (dir / "p.yaml").string();
  CHECK(loaded.diagnostics.FormatAll() ==
        file +
            ":6:21: error: limits.max_force 1e300 N is out of range, expected a force from 1 uN "
            "to 10 kN, e.g. \"8.5 N\"\n" +
            file +
            ":6:37: error: limits.stall 0 s is out of range, expected a time from 1 ms to 3600 "
            "s, e.g. \"1 s\"\n");
  std::filesystem::remove_all(dir);
}
