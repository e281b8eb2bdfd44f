// The bench harness and its scenarios (tubeplan bench; bench/bench.hpp).
#include "bench.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <tubeplan/core/core.hpp>
#include <tubeplan/model/elastica.hpp>
#include <tubeplan/model/linear_beam.hpp>

#include "tessellated_box.hpp"

namespace tubeplan::bench {

namespace {
double Percentile(const std::vector<double>& sorted, double q) {
  const auto index = static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1) + 0.5);
  return sorted[std::min(index, sorted.size() - 1)];
}

}  // namespace

Figures Measure(const Scenario& scenario, int samples, double& sink) {
  using Clock = std::chrono::steady_clock;
  Figures f;
  // The same bits (a NaN equals itself, -0 differs from +0).
  const auto same = [](double a, double b) {
    return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
  };
  const auto call = [&](int i) {
    const double value = scenario.run(i);
    for (int r = 1; r < scenario.replicas; ++r)
      if (!same(scenario.replica(i, r), value)) ++f.replica_mismatches;
    return value;
  };
  for (int i = 0; i < std::max(10, samples / 10); ++i) sink += call(i);  // warm caches
  std::vector<double> per_call_s(static_cast<std::size_t>(samples));
  std::vector<double> own_s(static_cast<std::size_t>(samples));
  const auto timed = [&](auto&& work) {
    const Clock::time_point start = Clock::now();
    const double value = work();
    const Clock::time_point stop = Clock::now();
    sink += value;
    return std::pair{
        value, std::chrono::duration<double>(stop - start).count() / scenario.calls_per_sample};
  };
  for (int i = 0; i < samples; ++i) {
    const auto [value, first_s] = timed([&] { return scenario.run(i); });
    double least_s = first_s;
    for (int r = 1; r < scenario.replicas; ++r) {
      const auto [replica_value, replica_s] = timed([&] { return scenario.replica(i, r); });
      if (!same(replica_value, value)) ++f.replica_mismatches;
      least_s = std::min(least_s, replica_s);
    }
    per_call_s[static_cast<std::size_t>(i)] = first_s;
    own_s[static_cast<std::size_t>(i)] = least_s;
  }
  std::sort(per_call_s.begin(), per_call_s.end());
  std::sort(own_s.begin(), own_s.end());
  f.median_s = Percentile(per_call_s, 0.5);
  f.p99_s = Percentile(per_call_s, 0.99);
  f.p999_s = Percentile(per_call_s, 0.999);
  f.max_s = per_call_s.back();
  f.own_median_s = Percentile(own_s, 0.5);
  f.own_p99_s = Percentile(own_s, 0.99);
  f.own_p999_s = Percentile(own_s, 0.999);
  f.own_max_s = own_s.back();
  return f;
}

std::vector<Scenario> MakeScenarios(const model::TubeSpec& spec) {
  auto beam = std::make_shared<model::LinearBeam>(spec);
  const double l = spec.length_m;
  const double r = spec.outer_radius_m;
  constexpr int kBatch = 1000;  // linear calls take tens of ns: time them a thousand at a time
  std::vector<Scenario> scenarios;
  scenarios.push_back(
      {"beam.linear",
       "tip force from a tip deflection, then the displacement of one material point", kBatch,
       100e-9, [beam, l, r](int sample) {
         double acc = 0.0;
         for (int j = 0; j < kBatch; ++j) {
           // Inputs vary per call so nothing is hoisted out of the loop.
           const double phase = 1e-3 * (sample * kBatch + j);
           const double deflection_m = 1e-3 * (1.0 + 0.5 * std::sin(phase));
           const double force_N = deflection_m * beam->section().tip_stiffness_N_per_m;
           const Eigen::Vector2d f_O_N(force_N * std::cos(phase), force_N * std::sin(phase));
           const Eigen::Vector3d p_OP_O(0.7 * r * std::cos(3 * phase),
                                        0.7 * r * std::sin(3 * phase),
                                        l * (0.5 + 0.4 * std::sin(phase)));
           acc += beam->Displacement(p_OP_O, f_O_N).sum();
         }
         return acc;
       }});
  const double alpha_1N = model::LoadParameter(spec, 1.0);
  scenarios.push_back({"beam.elastica.solve", "elastica solve, 0.1-5 N at any angle to the tube", 1,
                       20e-6, [alpha_1N](int sample) {
                         // A golden-ratio sequence covers the hand-force range and the load angles
                         // evenly.
                         const double u = std::fmod(0.6180339887498949 * sample, 1.0);
                         const double v = std::fmod(0.7548776662466927 * sample, 1.0);
                         const double force_N =
                             0.1 * std::pow(50.0, u);  // 0.1 N .. 5 N, log-uniform
                         const double psi = (v - 0.5) * std::numbers::pi;
                         const model::ElasticaSolution s =
                             model::SolveElastica(alpha_1N * force_N, psi);
                         return s.tip.deflection + s.tip.shortening;
                       }});
  scenarios.push_back({"beam.elastica.small_alpha", "elastica solve by the series (alpha <= 1e-3)",
                       1, 20e-6, [](int sample) {
                         const double alpha = 1e-6 * (1.0 + (sample % 997));
                         return model::SolveElastica(alpha, 0.3).tip.deflection;
                       }});
  auto solved = std::make_shared<model::ElasticaSolution>(model::SolveElastica(alpha_1N, 0.0));
  constexpr int kPoints = 64;
  scenarios.push_back({"beam.elastica.centreline",
                       "centreline of a solved elastica, per point (64 per call)", kPoints, 0.0,
                       [solved](int sample) {
                         std::array<double, kPoints> s{};
                         std::array<Eigen::Vector2d, kPoints> xz{};
                         std::array<double, kPoints> theta{};
                         for (int j = 0; j < kPoints; ++j)
                           s[static_cast<std::size_t>(j)] = (j + 0.5 * (sample % 2)) / kPoints;
                         model::ElasticaCentreline(*solved, s, xz, theta);
                         return xz[kPoints - 1].x() + theta[kPoints / 2];
                       }});
  return scenarios;
}

namespace {

Eigen::Isometry3d HandPose(double x_m, double y_m, double z_m, double tip_down_deg,
                           double yaw_deg) {
  // The groove scene's convention: roll -90 deg lays the tube's z along world +y; a further roll
  // tips the free end down, and yaw turns the tube about the vertical.
  constexpr double kDeg = std::numbers::pi / 180.0;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = (Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd((-90.0 - tip_down_deg) * kDeg, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  X.translation() = Eigen::Vector3d(x_m, y_m, z_m);
  return X;
}

// One core scenario: the hand moves from the scene's start to `at` (Approach), stays kSettle_s, and
// is then timed tick by tick while `motion` (a function of the tick index) moves it about there.
// kReplicas cores take the same ticks (see the top of the file).
constexpr double kSettle_s = 0.3;

struct CoreRun {
  std::shared_ptr<core::Core> core;
  double t_s = 0.0;
  long tick = 0;
};

Scenario CoreScenario(const scene::Scene& scene, std::string name, std::string what,
                      Eigen::Isometry3d at,
                      std::function<Eigen::Isometry3d(const Eigen::Isometry3d&, long)> motion,
                      bool mesh = false) {
  auto runs = std::make_shared<std::array<CoreRun, kReplicas>>();
  const double T = scene.model.time_step_s;
  const long ticks = std::lround((kApproach_s + kSettle_s) / T);
  for (CoreRun& run : *runs) {
    run.core = std::make_shared<core::Core>(scene);
    for (long i = 0; i <= ticks; ++i)
      run.core->Step(run.t_s += T, Approach(scene.X_WH_start, at, double(i) * T));
  }
  const auto step = [runs, at, motion, mesh, T](int replica) {
    CoreRun& run = (*runs)[std::size_t(replica)];
    const core::StepOutput& out = run.core->Step(run.t_s += T, motion(at, run.tick++));
    double acc = out.force_W_N.x() + out.energy_J + out.iterations;
    if (mesh) {
      std::array<Eigen::Vector3d, 21> centreline;
      run.core->Centreline(centreline);
      acc += centreline.back().z();
    }
    return acc;
  };
  // The targets: a median of 25 us and a p99.9 of 250 us, a fortieth and a quarter of the 1 ms
  // tick, leaving the servo thread room for the device's I/O on a loaded machine.
  Scenario s{std::move(name), std::move(what), 1, 25e-6, nullptr, 250e-6};
  s.run = [step](int) { return step(0); };
  s.replica = [step](int, int replica) { return step(replica); };
  s.replicas = kReplicas;
  s.state = [runs] {
    const core::Core& core = *(*runs)[0].core;
    return nlohmann::json{{"cf", core.FormationText()},
                          {"pcs", core.last().contact_count},
                          {"iterations", core.last().iterations},
                          {"model", scene::ToString(core.scene().model.tube)},
                          {"elements", core.element_count()}};
  };
  return s;
}

}  // namespace

CorePoses PosesFor(const scene::Scene& scene) {
  const double l = scene.tube.length_m, r1 = scene.tube.outer_radius_m;
  const double y = scene.X_WH_start.translation().y();
  // The gap between the tube and the left wall when the tube lies along the groove's middle.
  double gap_m = 0.25 * r1;
  for (const scene::Part& part : scene.parts)
    if (part.name == "left") gap_m = -(part.X_WP.translation().x() + 0.5 * part.size_m.x()) - r1;
  constexpr double kTipDownDeg = 15.0;
  const double tip_down = kTipDownDeg * std::numbers::pi / 180.0;
  // Tipped down 15 deg, the rim's lowest point 0.13 r1 below the floor's top.
  const double z_end = l * std::sin(tip_down) + r1 * std::cos(tip_down) - 0.1313 * r1;
  CorePoses p;
  p.end = HandPose(0.0, y, z_end, kTipDownDeg, 0.0);
  // As the end, 1/16 r1 past touching the left wall.
  p.two_pcs = HandPose(-(gap_m + r1 / 16.0), y, z_end, kTipDownDeg, 0.0);
  // Lying on the floor, the held end 0.15 of the gap from the left wall, turned so that the free
  // end, were the tube straight, would come within half the contact band of the right wall.
  const double eps = scene.contact.threshold_m;
  const double turn = std::atan((0.85 * gap_m + gap_m - 0.5 * eps) / l) * 180.0 / std::numbers::pi;
  p.three_pcs = HandPose(-0.85 * gap_m, y, 1.025 * r1, 0.0, -turn);
  p.side_on_floor = HandPose(0.0, y, 0.95 * r1, 0.0, 0.0);
  return p;
}

Eigen::Isometry3d Approach(const Eigen::Isometry3d& start, const Eigen::Isometry3d& at,
                           double t_s) {
  const double u = std::clamp(t_s / kApproach_s, 0.0, 1.0);
  const double w = u * u * (3.0 - 2.0 * u);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = (1.0 - w) * start.translation() + w * at.translation();
  X.linear() = Eigen::Quaterniond(start.linear())
                   .slerp(w, Eigen::Quaterniond(at.linear()))
                   .toRotationMatrix();
  return X;
}

Eigen::Isometry3d Dither(const Eigen::Isometry3d& X, long tick) {
  Eigen::Isometry3d Y = X;
  Y.translation().z() += 20e-6 * std::sin(0.05 * double(tick));
  return Y;
}

namespace {

// Cells along each edge of a face of the mesh floor: 12 * 29^2 = 10,092 triangles, the size of
// part a tick on a mesh is compared with its box twin at.
constexpr int kMeshFloorDivisions = 29;

// The scene with its part named "floor" (a box) made a tessellated mesh of the same size, centred
// on the same frame, its faces named as the box's; nothing when the scene has no such part.
std::optional<scene::Scene> WithMeshFloor(const scene::Scene& scene) {
  for (std::size_t i = 0; i < scene.parts.size(); ++i) {
    const scene::Part& box = scene.parts[i];
    if (box.name != "floor" || box.shape != scene::PartShape::kBox) continue;
    scene::Scene meshed = scene;
    scene::Part& part = meshed.parts[i];
    part = scene::MakeMeshPart(box.name, TessellatedBoxMesh(box.size_m, kMeshFloorDivisions),
                               box.X_WP);
    part.friction = box.friction;
    return meshed;
  }
  return std::nullopt;
}
}  // namespace

std::vector<Scenario> MakeCoreScenarios(const scene::Scene& scene) {
  std::vector<Scenario> out;
  const auto slide = [](const Eigen::Isometry3d& X, long k) {
    // Back and forth along the groove, +-10 mm at 20 mm/s: the tip slides except at the turns.
    const double phase = std::fmod(double(k) * 1e-3 * 20e-3, 40e-3);
    Eigen::Isometry3d Y = X;
    Y.translation().y() += phase < 20e-3 ? phase - 10e-3 : 30e-3 - phase;
    return Y;
  };
  const CorePoses poses = PosesFor(scene);
  const Eigen::Isometry3d free_pose = scene.X_WH_start;
  const Eigen::Isometry3d& end_pose = poses.end;
  out.push_back(CoreScenario(scene, "core.free", "free motion above the groove", free_pose,
                             [](const Eigen::Isometry3d& X, long k) {
                               Eigen::Isometry3d Y = X;
                               Y.translation().x() += 5e-3 * std::sin(2e-3 * double(k));
                               return Y;
                             }));
  out.push_back(CoreScenario(scene, "core.end_stuck", "the tip pressed on the floor, stuck",
                             end_pose, Dither));
  out.push_back(
      CoreScenario(scene, "core.end_sliding", "the tip sliding along the floor", end_pose, slide));
  out.push_back(CoreScenario(scene, "core.two_pcs",
                             "the tip on the floor and the side along the left wall", poses.two_pcs,
                             Dither));
  out.push_back(
      CoreScenario(scene, "core.three_pcs",
                   "lying in the groove, turned to touch both walls: floor, left wall, right wall",
                   poses.three_pcs, Dither));
  // A line contact: the side lying along the floor, carried by every section on it.
  out.push_back(CoreScenario(scene, "core.side_on_floor",
                             "lying along the floor, pressed onto it (a line contact)",
                             poses.side_on_floor, Dither));
  // The floor a mesh of 10,092 triangles in place of its box: what a mesh part costs a tick.
  if (const std::optional<scene::Scene> meshed = WithMeshFloor(scene)) {
    out.push_back(CoreScenario(*meshed, "core.end_stuck.mesh10k",
                               "core.end_stuck on the floor as a 10,092-triangle mesh", end_pose,
                               Dither));
    out.push_back(CoreScenario(*meshed, "core.side_on_floor.mesh10k",
                               "core.side_on_floor on the floor as a 10,092-triangle mesh",
                               poses.side_on_floor, Dither));
  }
  // The same stuck tip without friction, and with the shape asked for every tick.
  scene::Scene frictionless = scene;
  frictionless.friction = scene::Friction{};
  for (scene::Part& part : frictionless.parts) part.friction.reset();
  out.push_back(CoreScenario(frictionless, "core.end_pressed.frictionless",
                             "core.end_stuck on the scene without friction", end_pose, Dither));
  out.push_back(CoreScenario(scene, "core.end_stuck.mesh",
                             "core.end_stuck and the centreline (21 points) every tick", end_pose,
                             Dither, true));
  scene::Scene linear = scene;
  linear.model.tube = scene::TubeModel::kLinear;
  out.push_back(CoreScenario(linear, "core.end_stuck.linear",
                             "core.end_stuck with the linear beam model", end_pose, Dither));
  out.push_back(CoreScenario(linear, "core.three_pcs.linear",
                             "core.three_pcs with the linear beam model", poses.three_pcs, Dither));
  return out;
}

}  // namespace tubeplan::bench
