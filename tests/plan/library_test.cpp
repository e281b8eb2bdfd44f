// tubeplan as a library: the one header a program includes is enough to do what the commands do.
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
  // Its scene explored within a budget of 6 motions, the first sweeps (the header is what is
  // tested; the exploration has tests of its own).
  graph::ExploreOptions o;
  o.max_motions = 6;
  o.jobs = 2;
  const graph::ContactGraph g = graph::Explore(*loaded.scene, o);
  CHECK(g.motions.size() == 6);
  CHECK(g.nodes.size() > 1);
  CHECK(g.start >= 0);
}
