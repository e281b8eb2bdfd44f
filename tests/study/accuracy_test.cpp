// The accuracy study (issue 7) at quick sizes: its references reproduce the published values and
// converge at their order; the rows it reports are the ones the issue lists. Times are never
// asserted.
#include <cmath>
#include <map>
#include <string>

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/model/tube.hpp>
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
  // reference agrees that the segmented rule is the farther off: measured 1.56 against 0.062
  // (linear) and 0.576 against 0.380 (elastica; 2.74 until stop 42, when a load released in the
  // tick it closed still cut the elastica's chain).
  for (const char* beam : {"linear", "elastica"}) {
    const std::string segmented = std::string(beam) + " segmented";
    const std::string coupled = std::string(beam) + " coupled";
    REQUIRE(two_pcs.count(segmented) == 1);
    REQUIRE(two_pcs.count(coupled) == 1);
    INFO(two_pcs[segmented]->detail << " | " << two_pcs[coupled]->detail);
    CHECK(two_pcs[segmented]->detail.find("SEGMENTED RULE OUT OF RANGE") != std::string::npos);
    CHECK(two_pcs[coupled]->detail.find("SEGMENTED RULE OUT OF RANGE") == std::string::npos);
    CHECK(two_pcs[segmented]->error > two_pcs[coupled]->error);
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

TEST_CASE("Accuracy's soft two-PC run: the held end stays with the hand", "[accuracy][core]") {
  // The accuracy study's two PCs (Fig. 6) on the shipped rubber tube with a penalty ten times
  // softer (K = 1e3 N/m, eps = 0.1 mm), driven as `tubeplan accuracy` drives it: four load steps,
  // each a 0.2 s ramp and a 0.2 s hold. At tick 1329 of this run three PCs pinched the tube off
  // its contacts and the tick's system, near singular, carried the held end to 1.6e23 m (finite,
  // so no check caught it), where every later tick started. A solve that moves the held end
  // farther than the coupling alone would, plus the tube's length, is now treated as singular
  // (the tick holds still and sends nothing). The held end may trail the hand by the coupling's
  // stretch at the device's force (8.5 N / Kc, a few cm) and the tube's length; 1 m is far beyond
  // any of that and far below what the defect did.
  const io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/groove.yaml");
  REQUIRE(loaded.scene);
  scene::Scene s = *loaded.scene;
  s.parts.clear();
  s.X_WH_start = Eigen::Isometry3d::Identity();
  s.device.max_torque_Nm = 100.0;
  s.device.coupling_damping_Ns_per_m = 0.0;
  s.workspace.reset();
  s.contact.stiffness_N_per_m = 1e3;
  s.contact.threshold_m = 1e-4;
  s.friction = scene::Friction{};  // frictionless, as the study's two PCs
  const double Kc = core::Core(s).coupling_stiffness_N_per_m();
  s.device.coupling_stiffness_N_per_m = Kc;
  // Fig. 6 as src/study/accuracy.cpp builds it: 40 mm cubes turned 45 degrees, one edge at l / 2
  // on the -x side 1.1 eps from the surface, one at l - 1.5 r1 on the +x side 1.3 eps from it.
  const double l = s.tube.length_m, r1 = s.tube.outer_radius_m, eps = 1e-3;
  const double K = 1e4;  // the scene's law sizes the load steps, as in the study
  const double EI = model::ComputeSection(s.tube).bending_stiffness_Nm2;
  const double s1 = 0.5 * l, s2 = l - 1.5 * r1, d1 = 1.1 * eps, d2 = 1.3 * eps;
  const auto edge_block = [](const std::string& name, double x_m, double z_m) {
    scene::BoxPart b;
    b.name = name;
    b.size_m = Eigen::Vector3d::Constant(0.04);
    b.X_WP = Eigen::Isometry3d::Identity();
    b.X_WP.linear() = Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitY()).toRotationMatrix();
    b.X_WP.translation() =
        Eigen::Vector3d(x_m + (x_m > 0 ? 1.0 : -1.0) * 0.02 * std::sqrt(2.0), 0.0, z_m);
    return b;
  };
  s.parts.push_back(edge_block("under", -(r1 + d1), s1));
  s.parts.push_back(edge_block("over", r1 + d2, s2));
  const double reach = (d1 + d2 - 2 * eps) * s1 / (s2 - s1) + d1 - eps;
  const double compliance = 1.0 / Kc + 1.0 / K + std::pow(s2 - s1, 3) / (3.0 * EI);
  core::Core c(s);
  double t = 0.0, hand_x = 0.0, farthest_m = 0.0;
  int ticks = 0;
  for (const double F : {0.3, 0.7, 1.2, 2.0}) {
    const double target = -(reach + F * compliance), from = hand_x;
    for (int i = 1; i <= 400; ++i) {
      hand_x = from + (target - from) * std::min(1.0, i / 200.0);
      Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
      X.translation().x() = hand_x;
      const core::StepOutput& out = c.Step(t += 1e-3, X);
      ++ticks;
      farthest_m = std::max(farthest_m, (out.X_WH.translation() - X.translation()).norm());
    }
  }
  CHECK(ticks == 1600);
  CHECK(farthest_m < 1.0);
}
