// `tubeplan bench`: speed figures of the core's building blocks. A benchmark is a command that
// prints numbers; nothing here passes or fails a build (tests never time anything).
//
// Method: each scenario runs a warm-up, then `samples` timed samples with
// std::chrono::steady_clock. Calls far shorter than the clock's overhead (~20 ns) are timed in
// batches and reported per call; the percentiles are then over batch means, which hides single slow
// calls inside a batch — the max column of the per-call scenarios is the honest worst case.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <iomanip>
#include <memory>
#include <numbers>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/cli/app.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/model/elastica.hpp>
#include <tubeplan/model/linear_beam.hpp>

#include "commands.hpp"

namespace tubeplan::cli {
namespace {

struct BenchOptions {
  std::string scene_path;
  int samples = 2000;
  bool json = false;
};

struct Scenario {
  std::string name;
  std::string what;
  int calls_per_sample = 1;
  double target_s = 0.0;  ///< the figure the issue sets for the median; 0 when none
  /// Runs calls_per_sample calls with inputs chosen by the sample index; returns a value that
  /// depends on every result so the compiler cannot drop the work.
  std::function<double(int sample)> run;
};

struct Figures {
  double median_s = 0.0, p99_s = 0.0, p999_s = 0.0, max_s = 0.0;
};

double Percentile(const std::vector<double>& sorted, double q) {
  const auto index = static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1) + 0.5);
  return sorted[std::min(index, sorted.size() - 1)];
}

Figures Measure(const Scenario& scenario, int samples, double& sink) {
  using Clock = std::chrono::steady_clock;
  for (int i = 0; i < std::max(10, samples / 10); ++i) sink += scenario.run(i);  // warm caches
  std::vector<double> per_call_s(static_cast<std::size_t>(samples));
  double max_s = 0.0;
  for (int i = 0; i < samples; ++i) {
    const Clock::time_point start = Clock::now();
    sink += scenario.run(i);
    const Clock::time_point stop = Clock::now();
    per_call_s[static_cast<std::size_t>(i)] =
        std::chrono::duration<double>(stop - start).count() / scenario.calls_per_sample;
    max_s = std::max(max_s, per_call_s[static_cast<std::size_t>(i)]);
  }
  std::sort(per_call_s.begin(), per_call_s.end());
  return {Percentile(per_call_s, 0.5), Percentile(per_call_s, 0.99), Percentile(per_call_s, 0.999),
          max_s};
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

int RunBench(const BenchOptions& o, Streams io) {
  // The default tube is the shipped groove scene's (scenes/groove.yaml), so figures are comparable
  // without a file.
  model::TubeSpec spec{0.008, 0.005, 0.150, 3.0e6, 0.5};
  if (!o.scene_path.empty()) {
    const io::SceneLoadResult loaded = io::LoadSceneFile(o.scene_path);
    io.err << loaded.diagnostics.FormatAll();
    if (!loaded.scene) return kExitBadInput;
    spec = loaded.scene->tube;
  }
  double sink = 0.0;
  nlohmann::json results = nlohmann::json::array();
  if (!o.json) {
    io.out << std::left << std::setw(28) << "scenario" << std::right << std::setw(11) << "median"
           << std::setw(11) << "p99" << std::setw(11) << "p99.9" << std::setw(11) << "max"
           << "   target\n";
  }
  for (const Scenario& scenario : MakeScenarios(spec)) {
    const Figures f = Measure(scenario, o.samples, sink);
    if (o.json) {
      // Field names follow the core's benchmark schema (issue 3): microseconds, and ticks_per_s
      // meaning calls per second at the median.
      nlohmann::json entry = {{"name", scenario.name},
                              {"what", scenario.what},
                              {"calls_per_sample", scenario.calls_per_sample},
                              {"samples", o.samples},
                              {"median_us", f.median_s * 1e6},
                              {"p99_us", f.p99_s * 1e6},
                              {"p999_us", f.p999_s * 1e6},
                              {"max_us", f.max_s * 1e6},
                              {"ticks_per_s", 1.0 / f.median_s}};
      if (scenario.target_s > 0.0) {
        entry["target_median_us"] = scenario.target_s * 1e6;
        entry["target_met"] = f.median_s < scenario.target_s;
      }
      results.push_back(entry);
    } else {
      io.out << std::left << std::setw(28) << scenario.name << std::right << std::setw(11)
             << Human(f.median_s) << std::setw(11) << Human(f.p99_s) << std::setw(11)
             << Human(f.p999_s) << std::setw(11) << Human(f.max_s) << "   ";
      if (scenario.target_s > 0.0) {
        io.out << (f.median_s < scenario.target_s ? "< " : "MISSED < ") << Human(scenario.target_s);
      } else {
        io.out << "-";
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
    io.out << "(per call; " << o.samples
           << " samples each; tube alpha at 1 N = " << model::LoadParameter(spec, 1.0) << ")\n";
  }
  // The sink is never NaN for valid input; printing it only when it is keeps the work observable.
  if (std::isnan(sink)) io.err << "tubeplan bench: a scenario produced NaN\n";
  return kExitOk;
}

}  // namespace

Command AddBenchCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* sub = app.add_subcommand(
      "bench", "Measure the speed of the beam models (median, p99, p99.9, max per call).");
  sub->add_option("--scene", options->scene_path, "take the tube from this scene file");
  sub->add_option("--samples", options->samples, "timed samples per scenario")
      ->check(CLI::Range(10, 10000000));
  sub->add_flag("--json", options->json, "print one JSON document (times in microseconds)");
  return {sub, [options, streams] { return RunBench(*options, streams); }};
}

}  // namespace tubeplan::cli
