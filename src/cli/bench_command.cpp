// `tubeplan bench`: speed figures of the core's building blocks. A benchmark is a command that
// prints numbers; nothing here passes or fails a build (tests never time anything).
//
// Method: each scenario runs a warm-up, then `samples` timed samples with
// std::chrono::steady_clock. Calls far shorter than the clock's overhead (~20 ns) are timed in
// batches and reported per call; the percentiles are then over batch means, which hides single slow
// calls inside a batch — the max column of the per-call scenarios is the honest worst case.
//
// The core's own cost against the machine's. On a shared machine the slowest ticks of a run are
// often not the core's: interruptions of ~20-80 us a few hundred times a second land on a tick
// with a probability proportional to its length and set the p99.9. Each core scenario therefore
// steps kReplicas cores in lockstep (the same scene and hand poses, hence the same state to the
// bit, checked by their outputs) and times each; a tick's own cost is the least of its kReplicas
// times. The wall-clock figures of the first core are reported beside it.
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iomanip>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/cli/app.hpp>
#include <tubeplan/core/core.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/model/elastica.hpp>
#include <tubeplan/model/linear_beam.hpp>

#include "commands.hpp"

namespace tubeplan::cli {
namespace {

struct BenchOptions {
  std::string scene_path = "scenes/groove.yaml";
  bool beam_only = false;
  std::vector<std::string> only;  // name prefixes; empty: every scenario
  int samples = 2000;
  bool json = false;
};

struct Scenario {
  std::string name;
  std::string what;
  int calls_per_sample = 1;
  double target_s = 0.0;  ///< the figure set for the median; 0 when none
  /// Runs calls_per_sample calls with inputs chosen by the sample index; returns a value that
  /// depends on every result so the compiler cannot drop the work.
  std::function<double(int sample)> run;
  double target_p999_s = 0.0;  ///< the figure set for p99.9; 0 when none
  /// For core scenarios: what the core was doing while timed (asked after the run).
  std::function<nlohmann::json()> state = nullptr;
  /// For core scenarios: the same call on replica r (1 .. replicas - 1), a core that has seen
  /// everything `run` has; it returns the same value as `run` did for this sample.
  std::function<double(int sample, int replica)> replica = nullptr;
  int replicas = 1;
};

struct Figures {
  double median_s = 0.0, p99_s = 0.0, p999_s = 0.0, max_s = 0.0;
  /// Over each sample's least time across the replicas (equal to the above without replicas).
  double own_median_s = 0.0, own_p99_s = 0.0, own_p999_s = 0.0, own_max_s = 0.0;
  int replica_mismatches = 0;  ///< samples where a replica's result differed (must stay 0)
};

double Percentile(const std::vector<double>& sorted, double q) {
  const auto index = static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1) + 0.5);
  return sorted[std::min(index, sorted.size() - 1)];
}

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

std::string Human(double seconds) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(seconds < 1e-6 ? 1 : 2);
  if (seconds < 1e-6) {
    s << seconds * 1e9 << " ns";
  } else if (seconds < 1e-3) {
    s << seconds * 1e6 << " us";
  } else {
    s << seconds * 1e3 << " ms";
  }
  return s.str();
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

// One core scenario: the hand moves from the scene's start to `at` in 0.5 s, stays 0.3 s, and is
// then timed tick by tick while `motion` (a function of the tick index) moves it about there.
// kReplicas cores take the same ticks (see the top of the file).
constexpr int kReplicas = 3;
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
  const Eigen::Isometry3d start = scene.X_WH_start;
  const double T = scene.model.time_step_s;
  for (CoreRun& run : *runs) {
    run.core = std::make_shared<core::Core>(scene);
    for (int i = 0; i <= 800; ++i) {
      const double u = std::min(1.0, i / 500.0);
      const double w = u * u * (3.0 - 2.0 * u);
      Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
      X.translation() = (1.0 - w) * start.translation() + w * at.translation();
      X.linear() = Eigen::Quaterniond(start.linear())
                       .slerp(w, Eigen::Quaterniond(at.linear()))
                       .toRotationMatrix();
      run.core->Step(run.t_s += T, X);
    }
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

// The hand's poses of the contact scenarios, for a groove along world y with its floor's top at
// z = 0 (the shipped scenes' layout), sized by the tube and by the gap between the tube and the
// wall named `left` (the groove taken as symmetric), so that each scenario reaches the same
// contact formation on a soft short tube and a stiff long one.
struct CorePoses {
  Eigen::Isometry3d end, two_pcs, three_pcs, side_on_floor;
};

CorePoses PosesFor(const scene::Scene& scene) {
  const double l = scene.tube.length_m, r1 = scene.tube.outer_radius_m;
  const double y = scene.X_WH_start.translation().y();
  // The gap between the tube and the left wall when the tube lies along the groove's middle.
  double gap_m = 0.25 * r1;
  for (const scene::BoxPart& part : scene.parts)
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

std::vector<Scenario> MakeCoreScenarios(const scene::Scene& scene) {
  std::vector<Scenario> out;
  // A small dither keeps every tick doing real work without changing the state.
  const auto dither = [](const Eigen::Isometry3d& X, long k) {
    Eigen::Isometry3d Y = X;
    Y.translation().z() += 20e-6 * std::sin(0.05 * double(k));
    return Y;
  };
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
                             end_pose, dither));
  out.push_back(
      CoreScenario(scene, "core.end_sliding", "the tip sliding along the floor", end_pose, slide));
  out.push_back(CoreScenario(scene, "core.two_pcs",
                             "the tip on the floor and the side along the left wall", poses.two_pcs,
                             dither));
  out.push_back(
      CoreScenario(scene, "core.three_pcs",
                   "lying in the groove, turned to touch both walls: floor, left wall, right wall",
                   poses.three_pcs, dither));
  // A line contact: the side lying along the floor, carried by every section on it.
  out.push_back(CoreScenario(scene, "core.side_on_floor",
                             "lying along the floor, pressed onto it (a line contact)",
                             poses.side_on_floor, dither));
  // The same stuck tip without friction, and with the shape asked for every tick.
  scene::Scene frictionless = scene;
  frictionless.friction = scene::Friction{};
  for (scene::BoxPart& part : frictionless.parts) part.friction.reset();
  out.push_back(CoreScenario(frictionless, "core.end_pressed.frictionless",
                             "core.end_stuck on the scene without friction", end_pose, dither));
  out.push_back(CoreScenario(scene, "core.end_stuck.mesh",
                             "core.end_stuck and the centreline (21 points) every tick", end_pose,
                             dither, true));
  scene::Scene linear = scene;
  linear.model.tube = scene::TubeModel::kLinear;
  out.push_back(CoreScenario(linear, "core.end_stuck.linear",
                             "core.end_stuck with the linear beam model", end_pose, dither));
  out.push_back(CoreScenario(linear, "core.three_pcs.linear",
                             "core.three_pcs with the linear beam model", poses.three_pcs, dither));
  return out;
}

int RunBench(const BenchOptions& o, Streams io) {
  // The default tube is the shipped groove scene's (scenes/groove.yaml), so figures are comparable
  // without a file.
  const io::SceneLoadResult loaded = io::LoadSceneFile(o.scene_path);
  io.err << loaded.diagnostics.FormatAll();
  if (!loaded.scene) return kExitBadInput;
  const model::TubeSpec spec = loaded.scene->tube;
  std::vector<Scenario> scenarios = MakeScenarios(spec);
  if (!o.beam_only) {
    std::vector<Scenario> core_scenarios = MakeCoreScenarios(*loaded.scene);
    scenarios.insert(scenarios.end(), core_scenarios.begin(), core_scenarios.end());
  }
  if (!o.only.empty()) {
    const auto wanted = [&](const Scenario& s) {
      return std::any_of(o.only.begin(), o.only.end(),
                         [&](const std::string& p) { return s.name.starts_with(p); });
    };
    std::vector<Scenario> kept;
    for (Scenario& s : scenarios)
      if (wanted(s)) kept.push_back(std::move(s));
    if (kept.empty()) {
      io.err << "tubeplan bench: error: no scenario's name starts with";
      for (const std::string& p : o.only) io.err << " '" << p << "'";
      io.err << ", and one was expected; the scenarios are:";
      for (const Scenario& s : scenarios) io.err << " " << s.name;
      io.err << "\n";
      return kExitBadInput;
    }
    scenarios = std::move(kept);
  }
  double sink = 0.0;
  nlohmann::json results = nlohmann::json::array();
  if (!o.json) {
    io.out << std::left << std::setw(28) << "scenario" << std::right << std::setw(11) << "median"
           << std::setw(11) << "p99" << std::setw(11) << "p99.9" << std::setw(11) << "max"
           << std::setw(11) << "own p99.9" << std::setw(11) << "own max"
           << "   target\n";
  }
  int mismatched = 0;
  for (const Scenario& scenario : scenarios) {
    const Figures f = Measure(scenario, o.samples, sink);
    if (f.replica_mismatches > 0) {
      io.err << "tubeplan bench: error: " << scenario.name << ": " << f.replica_mismatches
             << " ticks gave another result on a replica core with the same history, where the "
                "same bits were expected (the core is not deterministic)\n";
      ++mismatched;
    }
    // The median is judged on the first core's wall clock; the p99.9 on the tick's own cost
    // (the least of the replicas' times), the machine's interruptions being no part of the core.
    const bool median_met = f.median_s < scenario.target_s;
    const bool p999_met = f.own_p999_s < scenario.target_p999_s;
    if (o.json) {
      // Times in microseconds; ticks_per_s means calls per second at the median.
      nlohmann::json entry = {{"name", scenario.name},
                              {"what", scenario.what},
                              {"calls_per_sample", scenario.calls_per_sample},
                              {"samples", o.samples},
                              {"median_us", f.median_s * 1e6},
                              {"p99_us", f.p99_s * 1e6},
                              {"p999_us", f.p999_s * 1e6},
                              {"max_us", f.max_s * 1e6},
                              {"ticks_per_s", 1.0 / f.median_s}};
      if (scenario.replicas > 1) {
        entry["replicas"] = scenario.replicas;
        entry["own"] = {{"median_us", f.own_median_s * 1e6},
                        {"p99_us", f.own_p99_s * 1e6},
                        {"p999_us", f.own_p999_s * 1e6},
                        {"max_us", f.own_max_s * 1e6}};
      }
      if (scenario.target_s > 0.0) {
        entry["target_median_us"] = scenario.target_s * 1e6;
        entry["target_met"] = median_met;
      }
      if (scenario.target_p999_s > 0.0) {
        entry["target_p999_us"] = scenario.target_p999_s * 1e6;
        entry["target_p999_judged_on"] = "own.p999_us";
        entry["target_met"] = median_met && p999_met;
      }
      if (scenario.state) entry["state"] = scenario.state();
      results.push_back(entry);
    } else {
      io.out << std::left << std::setw(28) << scenario.name << std::right << std::setw(11)
             << Human(f.median_s) << std::setw(11) << Human(f.p99_s) << std::setw(11)
             << Human(f.p999_s) << std::setw(11) << Human(f.max_s);
      if (scenario.replicas > 1) {
        io.out << std::setw(11) << Human(f.own_p999_s) << std::setw(11) << Human(f.own_max_s);
      } else {
        io.out << std::setw(11) << "-" << std::setw(11) << "-";
      }
      io.out << "   ";
      if (scenario.target_s > 0.0) {
        io.out << (median_met ? "< " : "MISSED < ") << Human(scenario.target_s);
      } else {
        io.out << "-";
      }
      if (scenario.target_p999_s > 0.0) {
        io.out << (p999_met ? ", own p99.9 < " : ", own p99.9 MISSED < ")
               << Human(scenario.target_p999_s);
      }
      if (scenario.state) {
        const nlohmann::json state = scenario.state();
        io.out << "   " << state["cf"].get<std::string>() << " (" << state["elements"].get<int>()
               << " elements, " << state["iterations"].get<int>() << " iterations)";
      }
      io.out << "\n";
    }
  }
  if (o.json) {
    io.out << nlohmann::json{{"tube_alpha_at_1N", model::LoadParameter(spec, 1.0)},
                             {"scenarios", results}}
                  .dump(2)
           << "\n";
  } else {
    io.out << "(per call; " << o.samples << " samples each; ";
    if (!o.beam_only)
      io.out << "own: the least of " << kReplicas
             << " cores' times for the same tick, without the machine's interruptions; ";
    io.out << "tube alpha at 1 N = " << model::LoadParameter(spec, 1.0) << ")\n";
  }
  // The sink is never NaN for valid input; printing it only when it is keeps the work observable.
  if (std::isnan(sink)) io.err << "tubeplan bench: a scenario produced NaN\n";
  return mismatched > 0 ? kExitInternal : kExitOk;
}

}  // namespace

Command AddBenchCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* sub = app.add_subcommand(
      "bench",
      "Measure the speed of the beam models and of the core's tick in free motion, one end "
      "contact stuck and sliding, two and three PCs (median, p99, p99.9, max).");
  sub->add_option("--scene", options->scene_path,
                  "the scene of the core scenarios and the tube of the beam ones (default "
                  "scenes/groove.yaml, relative to the working directory)");
  sub->add_flag("--beam-only", options->beam_only, "only the beam models' scenarios");
  sub->add_option("--only", options->only,
                  "only the scenarios whose names start with this (repeatable), e.g. "
                  "--only core.end_stuck");
  sub->add_option("--samples", options->samples, "timed samples per scenario")
      ->check(CLI::Range(10, 10000000));
  sub->add_flag("--json", options->json, "print one JSON document (times in microseconds)");
  return {sub, [options, streams] { return RunBench(*options, streams); }};
}

}  // namespace tubeplan::cli
