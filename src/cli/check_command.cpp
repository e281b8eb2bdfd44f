// `tubeplan check FILE...`: validates scene and trajectory files and prints a one-line summary of
// each valid one. Every problem in every file is reported before the exit code says so.
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/scene/elements.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

struct CheckOptions {
  std::vector<std::string> files;
  bool json = false;
  bool elements = false;
};

std::string Summary(const scene::Scene& s) {
  const auto& t = s.tube;
  std::ostringstream out;
  out << "scene \"" << s.name << "\": tube " << t.outer_radius_m * 2e3 << "/"
      << t.inner_radius_m * 2e3 << " mm x " << t.length_m * 1e3 << " mm, E "
      << (t.youngs_modulus_Pa >= 1e9 ? t.youngs_modulus_Pa / 1e9 : t.youngs_modulus_Pa / 1e6)
      << (t.youngs_modulus_Pa >= 1e9 ? " GPa; " : " MPa; ") << s.parts.size() << " parts, "
      << scene::EnumerateElements(s).size() << " elements";
  {
    // What the core keeps of it: parts beyond the tube's reach from the workspace are left out.
    const core::Core core(s);
    out << " (" << core.reachable_parts().size() << " parts, " << core.elements().size()
        << " elements within reach; the tube as " << core.element_count() << " rod elements)";
  }
  out << "; ";
  if (s.friction.IsFrictionless()) {
    out << "frictionless";
  } else {
    out << "friction " << s.friction.static_coefficient << "/" << s.friction.kinetic_coefficient;
  }
  out << "; " << scene::ToString(s.model.tube) << " model; goal " << states::ToString(s.goal)
      << "; alpha at 1 N: " << model::LoadParameter(t, 1.0);
  return out.str();
}

std::string Summary(const io::TrajectoryInfo& t) {
  const double duration_s = t.t_last_s - t.t_first_s;
  std::ostringstream out;
  out << "trajectory: " << t.sample_count << " samples over " << duration_s << " s (mean rate "
      << static_cast<double>(t.sample_count - 1) / duration_s << " Hz";
  if (t.nominal_rate_Hz > 0.0) out << ", nominal " << t.nominal_rate_Hz << " Hz";
  out << ")";
  if (!t.device.empty()) out << "; device " << t.device;
  if (!t.extra_columns.empty()) {
    out << "; extra columns";
    for (const std::string& c : t.extra_columns) out << " " << c;
  }
  return out.str();
}

// What a file is, by its extension: .csv is a trajectory, anything else a scene.
struct Checked {
  const char* kind;
  io::Diagnostics diagnostics;
  std::optional<std::string> summary;        // set when valid
  std::vector<scene::PartElement> elements;  // a valid scene's
};

const char* KindName(scene::ElementKind kind) {
  return kind == scene::ElementKind::kFace   ? "face"
         : kind == scene::ElementKind::kEdge ? "edge"
                                             : "vertex";
}

Checked CheckFile(const std::string& file) {
  if (std::filesystem::path(file).extension() == ".csv") {
    // Streamed: a recording of hours is checked in the memory of a few lines.
    io::TrajectoryScanResult scanned = io::ScanTrajectoryFile(file);
    Checked c{"trajectory", std::move(scanned.diagnostics), std::nullopt, {}};
    if (scanned.info) c.summary = Summary(*scanned.info);
    return c;
  }
  // A plan file names its plan at the top level ("plan: ..."); any other YAML is a scene.
  if (const std::optional<std::string> text = io::ReadTextFile(file);
      text && (text->rfind("plan:", 0) == 0 || text->find("\nplan:") != std::string::npos)) {
    io::PlanLoadResult plan = io::LoadPlanFile(file, {.trajectory_in_memory = false});
    Checked c{"plan", std::move(plan.diagnostics), std::nullopt, {}};
    if (plan.plan) {
      std::ostringstream out;
      out << "plan \"" << plan.plan->name << "\": " << plan.plan->states.size() << " states, "
          << plan.plan->states.front() << " to " << plan.plan->states.back() << "; scene \""
          << plan.scene->name << "\"; " << Summary(*plan.trajectory_file);
      c.summary = out.str();
    }
    return c;
  }
  io::SceneLoadResult loaded = io::LoadSceneFile(file);
  Checked c{"scene", std::move(loaded.diagnostics), std::nullopt, {}};
  if (loaded.scene) {
    c.summary = Summary(*loaded.scene);
    c.elements = scene::EnumerateElements(*loaded.scene);
  }
  return c;
}

int RunCheck(const CheckOptions& o, Streams io) {
  bool all_valid = true;
  nlohmann::json files = nlohmann::json::array();
  for (const std::string& file : o.files) {
    const Checked checked = CheckFile(file);
    io.err << checked.diagnostics.FormatAll();
    const bool valid = checked.summary.has_value();
    all_valid = all_valid && valid;
    if (o.json) {
      nlohmann::json diagnostics = nlohmann::json::array();
      for (const io::Diagnostic& d : checked.diagnostics.all())
        diagnostics.push_back(
            {{"line", d.line},
             {"column", d.column},
             {"severity", d.severity == io::Severity::kError ? "error" : "warning"},
             {"message", d.message}});
      nlohmann::json entry = {
          {"file", file}, {"kind", checked.kind}, {"valid", valid}, {"diagnostics", diagnostics}};
      if (valid) entry["summary"] = *checked.summary;
      if (o.elements) {
        entry["elements"] = nlohmann::json::array();
        for (const scene::PartElement& e : checked.elements)
          entry["elements"].push_back({{"name", e.name}, {"kind", KindName(e.kind)}});
      }
      files.push_back(entry);
    } else if (valid) {
      io.out << file << ": ok: " << *checked.summary << "\n";
      if (o.elements)
        for (const scene::PartElement& e : checked.elements)
          io.out << "  " << KindName(e.kind) << " " << e.name << "\n";
    }
  }
  if (o.json) io.out << nlohmann::json{{"files", files}}.dump(2) << "\n";
  return all_valid ? kExitOk : kExitBadInput;
}

}  // namespace

Command AddCheckCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<CheckOptions>();
  CLI::App* sub = app.add_subcommand(
      "check",
      "Validate scene and plan files (.yaml) and trajectories (.csv): every problem is reported as "
      "file:line:col (exit 2), and each valid file gets a one-line summary.");
  sub->add_option("files", options->files, "scene files (.yaml) and trajectory files (.csv)")
      ->required();
  sub->add_flag("--json", options->json, "print one JSON document");
  sub->add_flag("--elements", options->elements,
                "list each scene's part elements (faces, edges, vertices) by the names goals and "
                "plans use");
  return {sub, [options, streams] { return RunCheck(*options, streams); }};
}

}  // namespace tubeplan::cli
