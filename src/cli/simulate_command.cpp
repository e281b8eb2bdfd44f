// `tubeplan simulate SCENE TRAJECTORY [--out FILE] [--json] [--mesh]`: runs the core over a
// recorded hand trajectory (resampled onto the core's step) and reports what happened. The
// per-tick series (columns in docs/simulate-output.md) goes to --out, CSV or JSON Lines by the
// file's extension, written to a temporary file and renamed.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/report/series_format.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

struct SimulateOptions {
  std::string scene_path;
  std::string trajectory_path;
  std::string out_path;
  bool json = false;
  bool mesh = false;
};

struct Visit {
  double t_s = 0.0;
  std::string cf;
  bool fault = false;  // entered on a tick the core flagged fault: {} there is not the tube's state
};

// What a replay saw, tick by tick, for the summary.
struct SimulateSummary {
  std::vector<Visit> visits;
  std::string cf_text;  // the last tick's contact formation
  double peak_force_N = 0.0, peak_force_t = 0.0, peak_strain = 0.0, peak_strain_t = 0.0;
  double peak_energy_J = 0.0, peak_torque_Nm = 0.0;
  std::array<long, core::kStepFlagCount> flag_ticks{};
  double core_s = 0.0, worst_tick_s = 0.0;
  std::size_t tick_count = 0;
  double duration_s = 0.0;
};

// The series' format from --out's extension (none without --out). False after saying why.
bool SeriesFormatOf(const std::string& out_path, report::SeriesFormat& format, std::ostream& err) {
  format = report::SeriesFormat::kNone;
  if (out_path.empty()) return true;
  const std::string ext = std::filesystem::path(out_path).extension().string();
  if (ext == ".csv") {
    format = report::SeriesFormat::kCsv;
  } else if (ext == ".jsonl") {
    format = report::SeriesFormat::kJsonLines;
  } else {
    err << out_path << ": error: unknown output format \"" << ext
        << "\", expected a file name ending in .csv or .jsonl\n";
    return false;
  }
  return true;
}

Eigen::Isometry3d HandPose(const plan::HandSample& sample) {
  Eigen::Isometry3d X_W_hand = Eigen::Isometry3d::Identity();
  X_W_hand.linear() = sample.q_WH.toRotationMatrix();
  X_W_hand.translation() = sample.p_WH_m;
  return X_W_hand;
}

// The core starts with the held end at the hand's first pose. A trajectory that starts away
// from the scene's start is allowed (a plan may begin mid-task) but said.
void ResetToFirstPose(const SimulateOptions& o, const scene::Scene& s,
                      const plan::HandSample& first, core::Core& core, std::ostream& err) {
  const Eigen::Isometry3d X_W_hand0 = HandPose(first);
  const double start_offset_m = (first.p_WH_m - s.X_WH_start.translation()).norm();
  const double start_turn_rad =
      Eigen::AngleAxisd(s.X_WH_start.linear().transpose() * X_W_hand0.linear()).angle();
  if (start_offset_m > 1e-3 || start_turn_rad > 1e-2) {
    err << o.trajectory_path << ": warning: the trajectory starts " << start_offset_m * 1e3
        << " mm and " << start_turn_rad * 180.0 / std::numbers::pi
        << " deg away from the scene's start pose; the held end starts at the trajectory's\n";
  }
  core.Reset(X_W_hand0);
}

// Steps the core through every tick, keeping the summary's figures and writing the series to
// `series_file` in chunks as it grows. False after saying why the series was not written.
bool Replay(const SimulateOptions& o, plan::SampleTicks& ticks, core::Core& core,
            report::SeriesFormat format, std::optional<io::AtomicFile>& series_file,
            SimulateSummary& sum, std::ostream& err) {
  report::SeriesWriter writer(format, o.mesh);
  constexpr std::size_t kSeriesChunkBytes = std::size_t{1} << 20;
  for (std::size_t k = 0; k < ticks.count(); ++k) {
    const plan::HandSample sample = ticks.Tick(k);
    const Eigen::Isometry3d X_W_hand = HandPose(sample);
    const auto start = std::chrono::steady_clock::now();
    const core::StepOutput& out = core.Step(sample.t_s, X_W_hand);
    const double tick_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    sum.core_s += tick_s;
    sum.worst_tick_s = std::max(sum.worst_tick_s, tick_s);
    sum.cf_text = core.FormationText();
    const bool fault = (out.flags & core::kSolverFault) != 0;
    if (sum.visits.empty() || sum.visits.back().cf != sum.cf_text ||
        sum.visits.back().fault != fault)
      sum.visits.push_back({sample.t_s, sum.cf_text, fault});
    const double force_N = out.force_W_N.norm();
    if (force_N > sum.peak_force_N) sum.peak_force_N = force_N, sum.peak_force_t = sample.t_s;
    if (out.max_strain > sum.peak_strain)
      sum.peak_strain = out.max_strain, sum.peak_strain_t = sample.t_s;
    sum.peak_energy_J = std::max(sum.peak_energy_J, out.energy_J);
    sum.peak_torque_Nm = std::max(sum.peak_torque_Nm, out.torque_W_Nm.norm());
    for (int b = 0; b < core::kStepFlagCount; ++b)
      if (out.flags & (1u << b)) ++sum.flag_ticks[std::size_t(b)];
    writer.Add(core, out, sum.cf_text);
    if (series_file && writer.text().size() >= kSeriesChunkBytes) {
      series_file->Write(writer.text());
      writer.Clear();
    }
  }
  if (series_file) {
    series_file->Write(writer.text());
    if (const std::string error = series_file->Commit(); !error.empty()) {
      err << o.out_path << ": error: " << error << "\n";
      return false;
    }
  }
  sum.tick_count = ticks.count();
  sum.duration_s = ticks.TimeOf(sum.tick_count - 1) - ticks.TimeOf(0);
  return true;
}

void PrintJson(const SimulateOptions& o, const scene::Scene& s, const core::Core& core,
               const SimulateSummary& sum, const std::string& strain_warning, std::ostream& out) {
  nlohmann::json j;
  j["scene"] = o.scene_path;
  j["trajectory"] = o.trajectory_path;
  j["ticks"] = sum.tick_count;
  j["time_step_s"] = s.model.time_step_s;
  j["duration_s"] = sum.duration_s;
  j["elements"] = core.element_count();
  nlohmann::json v = nlohmann::json::array();
  for (const Visit& visit : sum.visits) {
    v.push_back({{"t", visit.t_s}, {"cf", visit.cf}});
    if (visit.fault) v.back()["fault"] = true;
  }
  j["visits"] = v;
  j["final_cf"] = sum.cf_text;
  j["goal"] = states::ToString(s.goal);
  j["goal_reached"] = sum.cf_text == states::ToString(s.goal);
  j["peak_force_N"] = sum.peak_force_N;
  j["peak_force_t"] = sum.peak_force_t;
  j["peak_torque_Nm"] = sum.peak_torque_Nm;
  j["peak_strain"] = sum.peak_strain;
  j["peak_strain_t"] = sum.peak_strain_t;
  j["peak_energy_J"] = sum.peak_energy_J;
  j["warnings"] =
      strain_warning.empty() ? nlohmann::json::array() : nlohmann::json::array({strain_warning});
  nlohmann::json flags;
  for (int b = 0; b < core::kStepFlagCount; ++b)
    flags[std::string(report::FlagName(1u << b))] = sum.flag_ticks[std::size_t(b)];
  j["flag_ticks"] = flags;
  j["run_time_s"] = sum.core_s;
  j["mean_tick_us"] = 1e6 * sum.core_s / static_cast<double>(sum.tick_count);
  j["worst_tick_us"] = 1e6 * sum.worst_tick_s;
  if (!o.out_path.empty()) j["out"] = o.out_path;
  out << j.dump(2) << "\n";
}

void PrintText(const SimulateOptions& o, const scene::Scene& s, const core::Core& core,
               const SimulateSummary& sum, const std::string& strain_warning, std::ostream& out) {
  const std::vector<Visit>& visits = sum.visits;
  std::ostringstream text;
  text << std::setprecision(4);
  text << o.scene_path << " + " << o.trajectory_path << ": " << sum.tick_count << " ticks of "
       << s.model.time_step_s * 1e3 << " ms (" << sum.duration_s << " s), " << core.element_count()
       << " rod elements\n";
  text << "contact formations, in order (t = entry time):\n";
  const std::size_t shown = std::min<std::size_t>(visits.size(), 40);
  for (std::size_t i = 0; i < shown; ++i)
    text << "  t = " << std::setw(7) << visits[i].t_s << " s  " << visits[i].cf
         << (visits[i].fault ? "  (solver fault: the core held the tube still; not its state)" : "")
         << "\n";
  if (visits.size() > shown)
    text << "  ... " << visits.size() - shown << " more changes (the series in --out has all)\n";
  text << "final: " << sum.cf_text << (sum.cf_text == states::ToString(s.goal) ? " (the goal)" : "")
       << "\n";
  text << "peak force " << sum.peak_force_N << " N at t = " << sum.peak_force_t
       << " s; peak torque " << sum.peak_torque_Nm << " N m; peak strain " << sum.peak_strain
       << " at t = " << sum.peak_strain_t << " s; peak bending energy " << sum.peak_energy_J
       << " J\n";
  if (!strain_warning.empty()) text << "warning: " << strain_warning << "\n";
  text << "ticks flagged:";
  bool any = false;
  for (int b = 0; b < core::kStepFlagCount; ++b)
    if (sum.flag_ticks[std::size_t(b)] > 0) {
      text << " " << report::FlagName(1u << b) << " " << sum.flag_ticks[std::size_t(b)];
      any = true;
    }
  text << (any ? "" : " none") << "\n";
  text << "core run time " << sum.core_s * 1e3 << " ms: mean "
       << 1e6 * sum.core_s / static_cast<double>(sum.tick_count) << " us per tick, worst "
       << 1e6 * sum.worst_tick_s << " us\n";
  if (!o.out_path.empty()) text << "series written to " << o.out_path << "\n";
  out << text.str();
}

int RunSimulate(const SimulateOptions& o, Streams io) {
  if (!OutputsApart("simulate", {{"--out", o.out_path}},
                    {{"the scene", o.scene_path}, {"the trajectory", o.trajectory_path}}, io.err))
    return kExitBadInput;
  io::SceneLoadResult scene = io::LoadSceneFile(o.scene_path);
  // The trajectory is checked in a streamed pass and replayed in a second one, row by row: an
  // hour's recording is never held (docs/hardening.md).
  io::TrajectoryScanResult trajectory = io::ScanTrajectoryFile(o.trajectory_path);
  io.err << scene.diagnostics.FormatAll() << trajectory.diagnostics.FormatAll();
  report::SeriesFormat format = report::SeriesFormat::kNone;
  if (!SeriesFormatOf(o.out_path, format, io.err)) return kExitBadInput;
  if (!scene.scene || !trajectory.info) return kExitBadInput;

  const scene::Scene& s = *scene.scene;
  // The series goes to its file as it is made (an hour at 1 kHz is about 2 GB of CSV), into a
  // temporary file renamed at the end; a directory that cannot be written to is said before the
  // replay, not after it.
  std::optional<io::AtomicFile> series_file;
  if (format != report::SeriesFormat::kNone) {
    series_file.emplace(o.out_path);
    if (!series_file->error().empty()) {
      io.err << o.out_path << ": error: " << series_file->Commit() << "\n";
      return kExitBadInput;
    }
  }
  // Ticks one at a time from the file's rows: only the two samples around a tick are held.
  io::TrajectoryFileSamples samples(*trajectory.info);
  plan::SampleTicks ticks(samples, trajectory.info->t_first_s, trajectory.info->t_last_s,
                          s.model.time_step_s);
  core::Core core(s);
  ResetToFirstPose(o, s, ticks.Tick(0), core, io.err);
  SimulateSummary sum;
  if (!Replay(o, ticks, core, format, series_file, sum, io.err)) return kExitBadInput;
  // The same warning evaluate gives for a strain beyond the material's elastic range.
  const std::string strain_warning =
      plan::StrainWarning(s.tube, sum.peak_strain, sum.peak_strain_t);
  if (o.json)
    PrintJson(o, s, core, sum, strain_warning, io.out);
  else
    PrintText(o, s, core, sum, strain_warning, io.out);
  return kExitOk;
}

}  // namespace

Command AddSimulateCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* sub = app.add_subcommand(
      "simulate",
      "Run the core over a recorded hand trajectory: prints the contact formations visited, "
      "peaks and timing; --out writes the per-tick series (.csv or .jsonl).");
  sub->add_option("scene", options->scene_path, "scene file (.yaml)")->required();
  sub->add_option("trajectory", options->trajectory_path, "hand trajectory (.csv)")->required();
  sub->add_option(
      "--out", options->out_path,
      "write the per-tick series to FILE (.csv or .jsonl; see docs/simulate-output.md)");
  sub->add_flag("--json", options->json, "print the summary as one JSON document");
  sub->add_flag("--mesh", options->mesh,
                "add the deformed centreline (21 points) to every tick of the series");
  return {sub, [options, streams] { return RunSimulate(*options, streams); }};
}

}  // namespace tubeplan::cli
