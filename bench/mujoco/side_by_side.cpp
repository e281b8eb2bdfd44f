// A side-by-side of tubeplan's core and MuJoCo 2.2.2 on one contact case (docs/accuracy.md,
// "MuJoCo side by side"). The case is `tubeplan bench`'s core.end_stuck pose in a scene: the hand
// brought in 0.5 s from the scene's start to the bench's pose, the tube's end pressed on the floor,
// then held still; without friction unless --friction (core.end_pressed.frictionless,
// core.end_stuck). For each engine and element count it prints the settled vertical operator force,
// its error against the exact elastica of the same case (the shooting reference,
// reference/shooting_elastica.hpp, followed along the same hand path), and the wall time per
// 1 ms of simulated time, median over many ms after settling. Not part of the default build.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mujoco/mujoco.h>
#include <stdexcept>
#include <string>
#include <vector>

#include <tubeplan/core/core.hpp>
#include <tubeplan/core/coupling.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/model/tube.hpp>
#include <tubeplan/reference/shooting_elastica.hpp>

#include "bench/bench.hpp"
#include "mujoco_chain.hpp"

namespace tubeplan::bench::mujoco {
namespace {

namespace sh = reference::shooting;

// The hand's path of every core scenario of the bench: from the scene's start to `at`, then held.
struct HandPath {
  Eigen::Isometry3d start, at;
  Eigen::Isometry3d operator()(double t_s) const { return Approach(start, at, t_s); }
};

// The top of the part named "floor" (a box, level): z [m].
double FloorTop(const scene::Scene& scene) {
  for (const scene::Part& part : scene.parts)
    if (part.name == "floor" && part.shape == scene::PartShape::kBox &&
        part.X_WP.linear().isApprox(Eigen::Matrix3d::Identity()))
      return part.X_WP.translation().z() + 0.5 * part.size_m.z();
  throw std::invalid_argument("the scene has no level box named \"floor\"");
}

scene::Friction FloorFriction(const scene::Scene& scene) {
  for (const scene::Part& part : scene.parts)
    if (part.name == "floor" && part.friction) return *part.friction;
  return scene.friction;
}

// The exact elastica of the case: the shooting reference (an inextensible rod integrated along
// its arc, converged) with the core's contact and friction laws, the end's rim on the floor,
// followed quasi-statically along the hand's path in the plane the path keeps (world y, z; the
// tube's axis turns about world x), the held end on a spring of `coupling_N_per_m` to the hand
// (0: held at the hand).
struct Exact {
  double force_z_N = 0.0;  ///< on the operator
  double normal_N = 0.0, tangential_N = 0.0;
  bool stuck = false;
};

Exact ExactCase(const scene::Scene& scene, const HandPath& path, double coupling_N_per_m) {
  sh::Rod rod;
  rod.length_m = scene.tube.length_m;
  rod.bending_stiffness_Nm2 = model::ComputeSection(scene.tube).bending_stiffness_Nm2;
  rod.radius_m = scene.tube.outer_radius_m;
  sh::Setup setup;
  setup.coupling_N_per_m = coupling_N_per_m;
  setup.law = {scene.contact.stiffness_N_per_m, scene.contact.threshold_m};
  const scene::Friction f = FloorFriction(scene);
  sh::Obstacle floor;
  floor.kind = sh::ObstacleKind::kPlaneRim;
  floor.point_m = {0.0, FloorTop(scene)};
  floor.normal = {0.0, 1.0};
  floor.friction = {f.static_coefficient, f.kinetic_coefficient, f.exponent, f.reference_load_N,
                    true};
  setup.obstacles.push_back(floor);
  std::vector<sh::Hold> holds;
  constexpr int kHolds = 200;  // 2.5 ms apart on the approach
  for (int k = 0; k <= kHolds; ++k) {
    const Eigen::Isometry3d X = path(kApproach_s * k / kHolds);
    const Eigen::Vector3d axis = X.linear().col(2);
    if (std::abs(axis.x()) > 1e-12)
      throw std::invalid_argument("the case's hand path leaves the world's (y, z) plane");
    holds.push_back({{X.translation().y(), X.translation().z()}, std::atan2(axis.y(), axis.z())});
  }
  const sh::PathResult ref = sh::FollowPath(rod, setup, holds);
  if (!ref.ok) throw std::runtime_error("the shooting reference did not follow the hand's path");
  const sh::HoldResult& last = ref.holds.back();
  const sh::ContactResult& contact = last.solution.contacts.front();
  // The reference gives the force on the tube; the operator feels its opposite.
  return {-last.solution.operator_force_N.y(), contact.normal_N, contact.tangential_N,
          last.phase.front() == sh::ContactPhase::kStuck};
}

// One row of the table.
struct Row {
  std::string engine;
  int elements = 0;
  int steps_per_ms = 1;
  double force_z_N = 0.0, exact_z_N = 0.0;
  double still_us = 0.0, dithered_us = 0.0;
  double error() const { return std::abs(force_z_N - exact_z_N) / std::abs(exact_z_N); }
};

// tubeplan's core with `elements` rod elements: the bench's approach (0.5 s, then held 1.5 s),
// then one tick a sample, the hand held still and then dithered as the bench's.
Row RunTubeplan(const scene::Scene& base, const HandPath& path, int elements, int samples) {
  scene::Scene scene = base;
  scene.model.elements = elements;
  core::Core core(scene);
  const double T = scene.model.time_step_s;
  double t_s = 0.0;
  constexpr int kSettleTicks = 2000;
  for (int i = 0; i < kSettleTicks; ++i) core.Step(t_s += T, path(i * T));
  Row row{"tubeplan", core.element_count(), 1, core.last().force_W_N.z()};
  std::fprintf(stderr, "  tubeplan, %2d elements: force %.6g N, %s, %d iterations a tick\n",
               row.elements, row.force_z_N, core.FormationText().c_str(), core.last().iterations);
  const Eigen::Isometry3d X_held = path(t_s);
  const auto tick = [&](const Eigen::Isometry3d& X) {
    const core::StepOutput& out = core.Step(t_s += T, X);
    return out.force_W_N.z() + out.iterations;
  };
  double sink = 0.0;
  Scenario still{"tubeplan.still", "the hand held still", 1, 0.0,
                 [&](int) { return tick(X_held); }};
  row.still_us = 1e6 * Measure(still, samples, sink).median_s;
  long ms = 0;
  Scenario dithered{"tubeplan.dithered", "the hand dithered", 1, 0.0,
                    [&](int) { return tick(Dither(X_held, ms++)); }};
  row.dithered_us = 1e6 * Measure(dithered, samples, sink).median_s;
  if (!std::isfinite(sink)) throw std::runtime_error("the core's output went non-finite");
  return row;
}

void PrintTable(const std::vector<Row>& rows) {
  std::printf("%-9s %8s %9s %12s %8s %13s %13s\n", "engine", "elements", "steps/ms", "force [mN]",
              "error %", "us/ms still", "us/ms dither");
  for (const Row& r : rows)
    std::printf("%-9s %8d %9d %12.4f %8.2f %13.2f %13.2f\n", r.engine.c_str(), r.elements,
                r.steps_per_ms, 1e3 * r.force_z_N, 100.0 * r.error(), r.still_us, r.dithered_us);
  // At equal error: the MuJoCo chain whose error is nearest tubeplan's at its default count.
  const Row* ours = nullptr;
  const Row* nearest = nullptr;
  for (const Row& r : rows) {
    if (r.engine == "tubeplan") ours = &r;  // the last: the scene's default count
    if (ours && r.engine == "MuJoCo" &&
        (!nearest ||
         std::abs(r.error() - ours->error()) < std::abs(nearest->error() - ours->error())))
      nearest = &r;
  }
  if (ours && nearest)
    std::printf(
        "at equal error: tubeplan's default (%d elements) %.2f %% in %.2f us per ms; MuJoCo "
        "nearest, %d elements, %.2f %% in %.2f us per ms (%.1fx)\n",
        ours->elements, 100.0 * ours->error(), ours->still_us, nearest->elements,
        100.0 * nearest->error(), nearest->still_us, nearest->still_us / ours->still_us);
}

}  // namespace
}  // namespace tubeplan::bench::mujoco

int main(int argc, char** argv) {
  using namespace tubeplan;
  using namespace tubeplan::bench::mujoco;
  std::string scene_path = "scenes/groove.yaml";
  int samples = 2000;
  bool with_friction = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--friction") {
      with_friction = true;
    } else if (arg == "--samples" && i + 1 < argc) {
      const std::string n = argv[++i];
      if (n.empty() || n.size() > 7 || n.find_first_not_of("0123456789") != std::string::npos ||
          std::stoi(n) < 10) {
        std::fprintf(stderr,
                     "mujoco_side_by_side: error: --samples '%s', expected a whole number from 10 "
                     "to 9999999\n",
                     n.c_str());
        return 2;
      }
      samples = std::stoi(n);
    } else if (arg.starts_with("-")) {
      std::fprintf(stderr,
                   "usage: mujoco_side_by_side [SCENE] [--friction] [--samples N] (default %s, "
                   "%d)\n",
                   scene_path.c_str(), samples);
      return 2;
    } else {
      scene_path = arg;
    }
  }
  try {
    const io::SceneLoadResult loaded = io::LoadSceneFile(scene_path);
    if (!loaded.scene) {
      std::fprintf(stderr, "%s", loaded.diagnostics.FormatAll().c_str());
      return 2;
    }
    // The case is judged without friction by default (bench's core.end_pressed.frictionless):
    // its answer is the pose's alone. With friction (core.end_stuck) it depends on where the
    // end stuck on its way in, which a quasi-static reference, tubeplan's ticks and MuJoCo's
    // dynamics each decide their own way (docs/accuracy.md, "MuJoCo side by side").
    scene::Scene scene = *loaded.scene;
    if (!with_friction) {
      scene.friction = scene::Friction{};
      for (scene::Part& part : scene.parts) part.friction.reset();
    }
    const HandPath path{scene.X_WH_start, bench::PosesFor(scene).end};
    const core::Coupling coupling = core::ResolveCoupling(scene.device, scene.model.time_step_s);
    // tubeplan's held end is on the scene's coupling spring; MuJoCo's grip holds it rigidly.
    const Exact exact = ExactCase(scene, path, coupling.stiffness_N_per_m);
    const Exact rigid = ExactCase(scene, path, 0.0);
    if (with_friction)
      std::printf(
          "%s, core.end_stuck held still: the end %s on the floor, normal %.4f mN, "
          "tangential %.4f mN\n",
          scene_path.c_str(), exact.stuck ? "stuck" : "NOT stuck", 1e3 * exact.normal_N,
          1e3 * exact.tangential_N);
    else
      std::printf(
          "%s, core.end_stuck's pose without friction (core.end_pressed.frictionless), "
          "held still\n",
          scene_path.c_str());
    std::printf(
        "exact elastica (shooting reference): %.4f mN with the held end on the coupling "
        "(%.0f N/m, tubeplan's), %.4f mN held rigidly (MuJoCo's grip)\n",
        1e3 * exact.force_z_N, coupling.stiffness_N_per_m, 1e3 * rigid.force_z_N);

    const int most = core::ElementCount(scene);  // with model.elements unset: the default
    std::vector<Row> rows;
    std::vector<int> counts;
    for (const int n : {4, 6, 8, 12, 16, 24})
      if (n < most) counts.push_back(n);
    counts.push_back(most);
    for (const int n : counts) {
      scene::Scene s = scene;
      s.model.elements = n;
      if (core::ElementCount(s) != n) continue;
      Row row = RunTubeplan(scene, path, n, samples);
      row.exact_z_N = exact.force_z_N;
      rows.push_back(row);
    }

    ChainCase chain;
    chain.length_m = scene.tube.length_m;
    chain.outer_radius_m = scene.tube.outer_radius_m;
    chain.inner_radius_m = scene.tube.inner_radius_m;
    chain.bending_stiffness_Nm2 = model::ComputeSection(scene.tube).bending_stiffness_Nm2;
    chain.floor_z_m = FloorTop(scene);
    chain.contact_stiffness_N_per_m = scene.contact.stiffness_N_per_m;
    chain.threshold_m = scene.contact.threshold_m;
    // MuJoCo's friction is Coulomb's, mu N; the scene's limit is mu_s N0 (N / N0)^beta. Taken
    // at the exact case's normal force, they hold the same tangential force.
    const scene::Friction f = FloorFriction(scene);
    chain.friction = f.IsFrictionless()
                         ? 0.0
                         : f.static_coefficient *
                               std::pow(rigid.normal_N / f.reference_load_N, f.exponent - 1.0);
    chain.hand = path;
    std::fprintf(stderr, "MuJoCo %s: friction coefficient %.4g\n", mj_versionString(),
                 chain.friction);
    for (const int n : {4, 6, 8, 12, 16, 24}) {
      const ChainRun run = RunChain(chain, n, samples);
      std::fprintf(stderr,
                   "  MuJoCo, %2d elements: force at the grip %.6g N, on the floor %.6g N, %d "
                   "contact(s), K %.5g N/m, end moved %.3g um while timed\n",
                   n, run.force_z_N, run.contact_force_z_N, run.contacts,
                   run.contact_stiffness_N_per_m, 1e6 * run.tip_drift_m);
      rows.push_back({"MuJoCo", n, run.steps_per_ms, run.force_z_N, rigid.force_z_N, run.still_us,
                      run.dithered_us});
    }
    PrintTable(rows);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mujoco_side_by_side: error: %s\n", e.what());
    return 3;
  }
  return 0;
}
