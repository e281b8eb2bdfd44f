// tubeplan as a library: the one header a program includes is enough to do what the commands do.
#include <sstream>
#include <string>

#include <catch2/catch.hpp>

#include <tubeplan/tubeplan.hpp>

TEST_CASE("The library header alone loads a plan, judges it and explores its scene", "[plan]") {
  using namespace tubeplan;
  const io::PlanLoadResult loaded =
      io::LoadPlanFile(std::string(TUBEPLAN_SOURCE_DIR) + "/plans/groove-insert.yaml",
                       {.trajectory_in_memory = true});
  REQUIRE(loaded.diagnostics.FormatAll() == "");
  REQUIRE(loaded.trajectory);
  // The shipped insertion is feasible, as `evaluate` says.
  const plan::Judgement j =
      plan::Judge(*loaded.scene, *loaded.trajectory, loaded.plan->states, loaded.plan->limits);
  CHECK(j.feasible);
  CHECK(plan::Overall(j) == plan::Verdict::kFeasible);
  // Its scene explored within a budget of 2 motions, the first sweeps (the header is what is
  // tested; the exploration has tests of its own).
  graph::ExploreOptions o;
  o.max_motions = 2;
  o.jobs = 2;
  const graph::ContactGraph g = graph::Explore(*loaded.scene, o);
  CHECK(g.motions.size() == 2);
  CHECK(g.nodes.size() > 1);
  CHECK(g.start >= 0);
}

TEST_CASE("The library header alone replays a trajectory file as simulate does", "[plan]") {
  using namespace tubeplan;
  const std::string source = TUBEPLAN_SOURCE_DIR;
  batch::SimulationInput input;
  std::ostringstream err;
  REQUIRE(batch::LoadSimulation(source + "/scenes/groove.yaml", source + "/plans/groove-insert.csv",
                                input, err));
  std::size_t watched = 0;
  const batch::Simulated simulated = batch::RunSimulation(
      input, err,
      [&](const core::Core&, const core::StepOutput&, const std::string&) { ++watched; });
  CHECK(err.str() == "");
  CHECK(watched == simulated.run.tick_count);
  // The shipped insertion ends in its scene's goal, the last state it entered.
  CHECK(simulated.run.final_cf == states::ToString(input.scene->goal));
  REQUIRE(!simulated.run.visits.empty());
  CHECK(simulated.run.visits.back().cf == simulated.run.final_cf);
  // The file read row by row gives the ticks of the trajectory in memory bit for bit, so the
  // same visits at the same times and the same peaks.
  const io::TrajectoryLoadResult loaded =
      io::LoadTrajectoryFile(source + "/plans/groove-insert.csv");
  REQUIRE(loaded.trajectory);
  trajectories::TickStream ticks(*loaded.trajectory, input.scene->model.time_step_s);
  core::Core core(*input.scene);
  const plan::Simulation in_memory = plan::Simulate(ticks, core);
  REQUIRE(in_memory.visits.size() == simulated.run.visits.size());
  for (std::size_t i = 0; i < in_memory.visits.size(); ++i) {
    CHECK(in_memory.visits[i].t_s == simulated.run.visits[i].t_s);
    CHECK(in_memory.visits[i].cf == simulated.run.visits[i].cf);
  }
  CHECK(in_memory.peak_force_N == simulated.run.peak_force_N);
  CHECK(in_memory.peak_strain == simulated.run.peak_strain);
}
