// The accuracy study (issue 7) at quick sizes: its references reproduce the published values and
// converge at their order; the rows it reports are the ones the issue lists. Times are never
// asserted.
#include <cmath>
#include <map>
#include <string>

#include <catch2/catch.hpp>

#include <tubeplan/study/accuracy.hpp>

using namespace tubeplan;

TEST_CASE("Accuracy: the reference's convergence table shows second order", "[accuracy]") {
  const study::ConvergenceStudy c = study::TipLoadConvergence(5.0, 128);
  REQUIRE(c.order.size() == 3);
  // Halving h divides a second-order error by 4 (see tests/reference for the tolerance).
  for (const double order : c.order) CHECK(order == Approx(2.0).margin(0.15));
}

TEST_CASE("Accuracy: the linear model's error against the exact elastica", "[accuracy]") {
  scene::Scene s;
  s.name = "rubber";
  s.tube = {8e-3, 5e-3, 0.15, 3e6, 0.5};
  s.device.coupling_stiffness_N_per_m = 400.0;
  s.model.beam = model::BeamModel::kElastica;
  study::AccuracyOptions options;
  options.quick = true;
  const study::AccuracyReport r = study::RunAccuracy(s, options);
  bool linear_alpha1 = false, elastica_alpha100 = false;
  std::size_t contact_rows = 0;
  // Fig. 6's two PCs (the end on a wall, the side on an edge) by each rule and beam.
  std::map<std::string, const study::AccuracyRow*> two_pcs;
  for (const study::AccuracyRow& row : r.rows) {
    INFO(row.setting << " / " << row.scenario << ": " << row.error);
    if (row.scenario == "two PCs") two_pcs[row.setting] = &row;
    if (row.setting == "linear" && row.scenario == "tip load alpha=1") {
      linear_alpha1 = true;
      // physics.md: the linear tip deflection is 10 % too large at alpha = 1 (0.3333 against
      // 0.30172); the displacement error adds the missing shortening (0.0564): 21 %.
      CHECK(row.error ==
            Approx(std::hypot(1.0 / 3 - 0.30172, 0.05643) / std::hypot(0.30172, 0.05643))
                .epsilon(1e-3));
    }
    if (row.setting == "elastica" && row.scenario == "tip load alpha=100") {
      elastica_alpha100 = true;
      // Closed form against the reference rod at N = 32/64, Richardson: the rod's own error,
      // O(h^4) after extrapolation, is below 1e-4 there.
      CHECK(row.error < 1e-4);
    }
    if (row.scenario.rfind("tip load", 0) != 0) ++contact_rows;
    CHECK(std::isfinite(row.time_us));
  }
  CHECK(linear_alpha1);
  CHECK(elastica_alpha100);
  // The core flags the segmented rule out of its range there (core::kSegmentationOff: the end's
  // load moves the side contact, which the rule does not see), never the coupled rule; and the
  // reference agrees that the segmented rule is the one far off: measured 1.56 against 0.062
  // (linear) and 2.74 against 0.383 (elastica), so at least twice the coupled rule's error.
  for (const char* beam : {"linear", "elastica"}) {
    const std::string segmented = std::string(beam) + " segmented";
    const std::string coupled = std::string(beam) + " coupled";
    REQUIRE(two_pcs.count(segmented) == 1);
    REQUIRE(two_pcs.count(coupled) == 1);
    INFO(two_pcs[segmented]->detail << " | " << two_pcs[coupled]->detail);
    CHECK(two_pcs[segmented]->detail.find("SEGMENTED RULE OUT OF RANGE") != std::string::npos);
    CHECK(two_pcs[coupled]->detail.find("SEGMENTED RULE OUT OF RANGE") == std::string::npos);
    CHECK(two_pcs[segmented]->error > 2.0 * two_pcs[coupled]->error);
  }
  // Four contact scenarios x (4 beam/rule settings, 1 finer step, 6 contact K/eps settings, and
  // 8, 16 and 32 capsules: fewer than the 48 the core chooses for this soft tube).
  CHECK(r.capsules == 48);
  CHECK(contact_rows == 4 * 14);
  // The reference's contact solves converged (uncertainty 1 flags a failed solve) and N/2 and N
  // agree within 5 %. Known exception at this quick size (N = 32/64): the end face pressed flat
  // and sliding under the core's one-PC law (force at the nearer corner), where the corners trade
  // places and Newton may not settle; its rows then say "REFERENCE NOT CONVERGED" (the full run,
  // N = 64/128, converges).
  for (const study::ScenarioReference& ref : r.references) {
    INFO(ref.scenario << " (" << ref.contact << ")");
    if (ref.scenario == "sliding on a wall" && ref.contact == "same law") continue;
    CHECK(ref.uncertainty < 0.05);
  }
}
