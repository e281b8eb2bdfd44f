// The judge on synthetic ticks: each span's figures are those of its own ticks, a transition the
// replay never got to has no span, limits and the goal hold after the goal is reached, and ticks
// the core flags as faults neither count as a state nor pass without a warning.
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/batch/report.hpp>
#include <tubeplan/core/core.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/report/text_report.hpp>

namespace {

using namespace tubeplan;

// States by number: 0 is {} (no contact), i > 0 one PC on part element i, named kNames[i].
const std::vector<std::string> kNames = {"{}", "{Fe - floor.top}", "{Fs n floor.top}",
                                         "{Fs - floor.top}", "{Fs - right.top}"};

// One synthetic tick: the state, the operator force along x and the bending energy.
struct SyntheticTick {
  int state = 0;
  double force_N = 0.0;
  double energy_J = 0.0;
  std::uint32_t flags = 0;
  double friction_work_J = 0.0;
};

// Feeds ticks 1 ms apart (t = 1 ms for the first) and returns the judgement.
plan::Judgement Run(const std::vector<std::string>& states, const std::vector<SyntheticTick>& ticks,
                    plan::Limits limits = {}, const std::string& stopped_early = {}) {
  plan::Judging judging(states, limits, 1e-3);
  for (std::size_t k = 0; k < ticks.size(); ++k) {
    core::StepOutput out;
    const SyntheticTick& s = ticks[k];
    out.contact_count = s.state > 0 && (s.flags & core::kSolverFault) == 0 ? 1 : 0;
    out.contacts[0].part_element = s.state;
    out.contacts[0].friction_work_J = s.friction_work_J;
    out.force_W_N = Eigen::Vector3d(s.force_N, 0.0, 0.0);
    out.energy_J = s.energy_J;
    out.flags = s.flags;
    judging.Tick(1e-3 * double(k + 1), out,
                 [&] { return kNames[std::size_t(out.contact_count > 0 ? s.state : 0)]; });
  }
  return judging.Finish(stopped_early);
}

// `count` ticks in `state`, each with energy 1e-3 times its tick number (1-based, so the energy
// names the tick) and force 0.1 N.
void Add(std::vector<SyntheticTick>& ticks, int state, int count) {
  for (int i = 0; i < count; ++i) {
    const double k = double(ticks.size() + 1);
    ticks.push_back({state, 0.1, 1e-3 * k});
  }
}

std::string Text(const plan::Judgement& j, const std::vector<std::string>& states) {
  batch::Evaluated e;
  e.file = "synthetic.yaml";
  e.plan.name = "synthetic";
  e.plan.states = states;
  e.judgement = j;
  std::ostringstream text;
  report::PrintVerdicts(text, e, false);
  return text.str();
}

nlohmann::json Json(const plan::Judgement& j, const std::vector<std::string>& states) {
  batch::Evaluated e;
  e.file = "synthetic.yaml";
  e.plan.name = "synthetic";
  e.plan.states = states;
  e.judgement = j;
  return batch::ToJson({e}, {})["plans"][0];
}

}  // namespace

TEST_CASE("A transition's figures are those of its span: entering a .. entering b", "[plan]") {
  // {} for 50 ticks, {Fe} for 50, then the goal {Fs -} for 50. States count after 20 ticks but
  // are entered at their first tick: the spans are 1..51 ms and 51..101 ms.
  const std::vector<std::string> states = {kNames[0], kNames[1], kNames[3]};
  std::vector<SyntheticTick> ticks;
  Add(ticks, 0, 50);
  Add(ticks, 1, 50);
  Add(ticks, 3, 50);
  // A 2 N spike at the goal's first tick (101) and 1 J of friction work at {Fe}'s first tick (51):
  // each belongs to the span the state opens, not to the one it ends.
  ticks[100].force_N = 2.0;
  ticks[50].friction_work_J = 1.0;
  const plan::Judgement j = Run(states, ticks);
  REQUIRE(j.feasible);
  const plan::TransitionVerdict& a = j.transitions[0];
  const plan::TransitionVerdict& b = j.transitions[1];
  CHECK(a.t_start_s == Approx(0.001));
  CHECK(a.t_end_s == Approx(0.051));
  CHECK(a.friction_work_J == 0.0);
  CHECK(b.t_start_s == Approx(0.051));
  CHECK(b.t_end_s == Approx(0.101));
  CHECK(b.friction_work_J == 1.0);
  CHECK(b.peak_force_N == 0.1);
  // The energies at the span's ends are those of the ticks there.
  CHECK(a.energy_entry_J == Approx(0.001));
  CHECK(a.energy_exit_J == Approx(0.051));
  CHECK(b.energy_entry_J == Approx(0.051));
  CHECK(b.energy_exit_J == Approx(0.101));
  // The stretch after the goal: from the goal's entry to the last tick, with the spike.
  CHECK(j.after_goal.started);
  CHECK(j.after_goal.t_start_s == Approx(0.101));
  CHECK(j.after_goal.t_end_s == Approx(0.150));
  CHECK(j.after_goal.peak_force_N == 2.0);
  CHECK(j.after_goal.energy_exit_J == Approx(0.150));
}

TEST_CASE("A transition never reached has no span and no figures", "[plan]") {
  const std::vector<std::string> states = {kNames[0], kNames[1], kNames[2], kNames[3]};
  SECTION("after a limit exceeded on the way") {
    // 10 N at tick 60 (in {Fe}, transition 2 under way), then {Fs n} is reached at tick 101:
    // transition 2 is infeasible there and transition 3 never starts.
    std::vector<SyntheticTick> ticks;
    Add(ticks, 0, 50);
    Add(ticks, 1, 50);
    Add(ticks, 2, 50);
    Add(ticks, 3, 50);
    ticks[59].force_N = 10.0;
    const plan::Judgement j = Run(states, ticks);
    CHECK_FALSE(j.feasible);
    CHECK(j.transitions[1].reason == "limit exceeded: operator force 10 N > 8.5 N at t = 0.060 s");
    CHECK(j.transitions[1].t_end_s == Approx(0.101));
    const plan::TransitionVerdict& last = j.transitions[2];
    CHECK_FALSE(last.started);
    CHECK(last.reason == "not reached: the plan failed at an earlier transition");
    CHECK(last.friction_work_J == 0.0);
    CHECK(last.peak_force_N == 0.0);
    CHECK_FALSE(j.after_goal.started);
    const nlohmann::json json = Json(j, states);
    CHECK(json["transitions"][2]["t_start_s"].is_null());
    CHECK(json["transitions"][2]["t_end_s"].is_null());
    CHECK(json["transitions"][2]["friction_work_J"].is_null());
    CHECK(json["after_goal"].is_null());
    // The text gives the not-reached transition no time span.
    const std::string text = Text(j, states);
    CHECK(text.find("{Fs n floor.top} -> {Fs - floor.top}: infeasible (not reached: the plan "
                    "failed at an earlier transition)\n") != std::string::npos);
    CHECK(text.find(" .. 0 s") == std::string::npos);
  }
  SECTION("when the replay starts elsewhere") {
    // It starts in {Fe} with 2 J of friction work on its first tick: the first transition is
    // infeasible and none has a span or figures.
    std::vector<SyntheticTick> ticks;
    Add(ticks, 1, 50);
    ticks[0].friction_work_J = 2.0;
    const plan::Judgement j = Run(states, ticks);
    CHECK(j.transitions[0].reason ==
          "the replay starts in {Fe - floor.top}, not in the planned {}");
    for (const plan::TransitionVerdict& v : j.transitions) {
      CHECK_FALSE(v.started);
      CHECK(v.friction_work_J == 0.0);
    }
    CHECK(Text(j, states).find("friction work") == std::string::npos);
  }
  SECTION("when another planned state comes first") {
    // {} then straight to {Fs n} (planned after {Fe}): the exit energy is the one at its entry.
    std::vector<SyntheticTick> ticks;
    Add(ticks, 0, 50);
    Add(ticks, 2, 50);
    const plan::Judgement j = Run(states, ticks);
    const plan::TransitionVerdict& v = j.transitions[0];
    CHECK(v.verdict == plan::Verdict::kInfeasible);
    CHECK(v.t_end_s == Approx(0.051));
    CHECK(v.energy_exit_J == Approx(0.051));
  }
}

TEST_CASE("Limits and the goal hold after the goal is reached", "[plan]") {
  const std::vector<std::string> states = {kNames[0], kNames[1], kNames[3]};
  std::vector<SyntheticTick> ticks;
  Add(ticks, 0, 50);
  Add(ticks, 1, 50);
  SECTION("a limit exceeded after the goal") {
    Add(ticks, 3, 100);
    ticks[149].force_N = 9.0;  // t = 0.150 s, 49 ms after the goal was entered
    const plan::Judgement j = Run(states, ticks);
    for (const plan::TransitionVerdict& v : j.transitions)
      CHECK(v.verdict == plan::Verdict::kFeasible);
    CHECK_FALSE(j.feasible);
    CHECK(j.after_goal.verdict == plan::Verdict::kInfeasible);
    CHECK(j.after_goal.reason ==
          "after the goal: limit exceeded: operator force 9 N > 8.5 N at t = 0.150 s");
    CHECK(Text(j, states).find("INFEASIBLE") != std::string::npos);
    CHECK(Json(j, states)["after_goal"]["verdict"] == "infeasible");
  }
  SECTION("leaving the goal, and ending outside it") {
    Add(ticks, 3, 50);
    Add(ticks, 2, 50);  // {Fs n} from t = 0.151 s to the end
    const plan::Judgement j = Run(states, ticks);
    CHECK_FALSE(j.feasible);
    CHECK(j.after_goal.reason ==
          "after the goal: left the goal for {Fs n floor.top} at t = 0.151 s; the trajectory "
          "ended in {Fs n floor.top}, not in the goal");
  }
  SECTION("leaving the goal and coming back") {
    Add(ticks, 3, 50);
    Add(ticks, 2, 30);
    Add(ticks, 3, 30);
    const plan::Judgement j = Run(states, ticks);
    CHECK_FALSE(j.feasible);
    CHECK(j.after_goal.reason ==
          "after the goal: left the goal for {Fs n floor.top} at t = 0.151 s; it was back in the "
          "goal at the end");
  }
  SECTION("a flicker shorter than the dwell is not leaving") {
    Add(ticks, 3, 50);
    Add(ticks, 2, 10);
    Add(ticks, 3, 30);
    const plan::Judgement j = Run(states, ticks);
    CHECK(j.feasible);
    CHECK(j.after_goal.verdict == plan::Verdict::kFeasible);
    CHECK(j.after_goal.reason.empty());
  }
}

TEST_CASE("Fault ticks are not a state of the tube and are warned about", "[plan]") {
  // {} -> {Fe} -> goal; in {Fe} 30 ticks the core flags fault (with penetration and separated,
  // as it does): their formation reads {}, which the judge must not take for a state.
  const std::vector<std::string> states = {kNames[0], kNames[1], kNames[3]};
  std::vector<SyntheticTick> ticks;
  Add(ticks, 0, 50);
  Add(ticks, 1, 20);
  for (int i = 0; i < 30; ++i)
    ticks.push_back({1, 0.0, 0.0, core::kSolverFault | core::kPenetration | core::kProxySeparated});
  Add(ticks, 1, 20);
  Add(ticks, 3, 50);
  const plan::Judgement j = Run(states, ticks);
  CHECK(j.feasible);
  REQUIRE(j.observed.size() == 3);
  CHECK(j.observed[1].cf == kNames[1]);
  CHECK(j.observed[2].cf == kNames[3]);
  CHECK(j.transitions[1].FlaggedSeconds(core::kSolverFault) == Approx(0.030).margin(1e-12));
  CHECK(j.transitions[0].FlaggedSeconds(core::kSolverFault) == 0.0);
  CHECK(Json(j, states)["transitions"][1]["fault_s"] == Approx(0.030).margin(1e-12));
  const std::string text = Text(j, states);
  CHECK(text.find("      warning: for 0.03 s the core could not solve the tick (flag fault") !=
        std::string::npos);
}

TEST_CASE("A run that stopped early judges only what it finished", "[plan]") {
  const std::vector<std::string> states = {kNames[0], kNames[1], kNames[2], kNames[3]};
  const std::string stop = "interrupted at t = 0.110 s";
  std::vector<SyntheticTick> ticks;
  Add(ticks, 0, 50);
  Add(ticks, 1, 50);
  Add(ticks, 2, 10);  // {Fs n} entered at 101 ms, not yet counted (dwell 20 ms)
  SECTION("the span under way and those after it are not judged") {
    const plan::Judgement j = Run(states, ticks, {}, stop);
    CHECK_FALSE(j.feasible);
    CHECK(plan::Overall(j) == plan::Verdict::kNotJudged);
    CHECK(j.stopped_early == stop);
    CHECK(j.transitions[0].verdict == plan::Verdict::kFeasible);
    const plan::TransitionVerdict& cut = j.transitions[1];
    CHECK(cut.verdict == plan::Verdict::kNotJudged);
    CHECK(cut.reason == "the run stopped: " + stop);
    CHECK(cut.started);
    CHECK(cut.t_start_s == Approx(0.051));
    CHECK(cut.t_end_s == Approx(0.110));
    CHECK(cut.detour.empty());  // {Fs n} entered, never counted: not a detour
    CHECK(j.transitions[2].verdict == plan::Verdict::kNotJudged);
    CHECK_FALSE(j.transitions[2].started);
    CHECK_THAT(Text(j, states), Catch::Contains("NOT JUDGED, 3 transitions, 0.109 s replayed; "
                                                "the run stopped early: " +
                                                stop));
    const nlohmann::json json = Json(j, states);
    CHECK(json["outcome"] == "not judged");
    CHECK(json["stopped_early"] == stop);
    CHECK(json["transitions"][1]["verdict"] == "not judged");
    batch::Evaluated e;
    e.judgement = j;
    const nlohmann::json summary = batch::ToJson({e}, {})["summary"];
    CHECK(summary["not_judged"] == 1);
    CHECK(summary["infeasible"] == 0);
  }
  SECTION("a limit exceeded before the stop is a verdict") {
    ticks[59].force_N = 10.0;
    const plan::Judgement j = Run(states, ticks, {}, stop);
    CHECK(plan::Overall(j) == plan::Verdict::kInfeasible);
    CHECK(j.transitions[1].verdict == plan::Verdict::kInfeasible);
    CHECK(j.transitions[1].reason == "limit exceeded: operator force 10 N > 8.5 N at t = 0.060 s");
    CHECK(j.transitions[2].reason == "not reached: the plan failed at an earlier transition");
    CHECK(Json(j, states)["outcome"] == "infeasible");
  }
  SECTION("the goal reached, the stretch after it cut short") {
    Add(ticks, 2, 40);
    Add(ticks, 3, 50);
    const plan::Judgement j = Run(states, ticks, {}, stop);
    for (const plan::TransitionVerdict& v : j.transitions)
      CHECK(v.verdict == plan::Verdict::kFeasible);
    CHECK(j.after_goal.started);
    CHECK(j.after_goal.verdict == plan::Verdict::kNotJudged);
    CHECK_FALSE(j.feasible);
    CHECK(plan::Overall(j) == plan::Verdict::kNotJudged);
  }
  SECTION("a trajectory that ended there is judged: the next state was never reached") {
    const plan::Judgement j = Run(states, ticks);
    CHECK(plan::Overall(j) == plan::Verdict::kInfeasible);
    CHECK(j.transitions[1].verdict == plan::Verdict::kInfeasible);
    CHECK_THAT(j.transitions[1].reason, Catch::StartsWith(kNames[2] + " never reached"));
    CHECK(Json(j, states)["stopped_early"].is_null());
  }
}
