// Plan files in: YAML, validated like scenes (every problem at once, file:line:col), with the
// scene and trajectory they name loaded and the planned CFs checked against the scene.
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/trajectory_csv.hpp>

#include "text_file.hpp"
#include "yaml_reader.hpp"

namespace tubeplan::io {
namespace {

namespace dim_ = dim;

void ReadLimits(Reader& r, const YAML::Node& node, plan::Limits& l) {
  const std::string w = "limits";
  if (!r.ExpectMap(node, w, {"max_force", "max_strain", "max_penetration", "dwell", "stall"}))
    return;
  // Each range with both its bounds, the value as the file wrote it.
  auto check = [&](const char* key, Dimension dimension, const char* si_unit, double& target,
                   double lo, double hi, const char* expected) {
    if (r.Field(node, key, w, dimension, false, target) && !(target >= lo && target <= hi)) {
      const YAML::Node n = r.Get(node, key, w, false);
      r.Error(n, w + "." + key + " " + AsWritten(n, si_unit) + " is out of range, expected " +
                     expected);
    }
  };
  check("max_force", dim_::kForce, "N", l.max_force_N, 1e-6, 1e4,
        "a force from 1 uN to 10 kN, e.g. \"8.5 N\"");
  check("max_strain", dim_::kNone, "", l.max_strain, 1e-9, 1.0,
        "a strain from 1e-9 to 1, e.g. 0.2");
  check("max_penetration", dim_::kLength, "m", l.max_penetration_m, 0.0, 0.1,
        "a length from 0 to 100 mm, e.g. \"0.2 mm\"");
  check("dwell", dim_::kTime, "s", l.dwell_s, 0.0, 10.0, "a time from 0 to 10 s, e.g. \"20 ms\"");
  check("stall", dim_::kTime, "s", l.stall_s, 1e-3, 3600.0,
        "a time from 1 ms to 3600 s, e.g. \"1 s\"");
}

// The format version, the plan's name and its limits.
void ReadHeader(Reader& r, const YAML::Node& root, plan::Plan& p) {
  if (const YAML::Node n = r.Get(root, "tubeplan", "plan file", true); n.IsDefined()) {
    if (!n.IsScalar() || n.Scalar() != "1")
      r.Error(n, "unsupported format version " +
                     (n.IsScalar() ? Abbreviate(n.Scalar()) : std::string(KindName(n))) +
                     ", expected 1");
  }
  if (const YAML::Node n = r.Get(root, "plan", "plan file", true); n.IsDefined())
    if (auto name = r.String(n, "plan")) p.name = *name;
  if (const YAML::Node n = r.Get(root, "limits", "plan file", false); n.IsDefined())
    ReadLimits(r, n, p.limits);
}

// The planned states, start first and goal last, each checked against the scene's elements when
// the scene was read: their text into the plan, the formations into `formations`.
void ReadStates(Reader& r, const YAML::Node& n, const std::optional<scene::Scene>& scene,
                plan::Plan& p, std::vector<states::ContactFormation>& formations) {
  if (!n.IsSequence() || n.size() < 2) {
    r.Error(n,
            "states must be a sequence of at least two contact formations (start first, "
            "goal last), found " +
                (n.IsSequence() ? std::to_string(n.size()) + " items" : std::string(KindName(n))));
    return;
  }
  const std::vector<scene::PartElement> elements =
      scene ? scene::EnumerateElements(*scene) : std::vector<scene::PartElement>{};
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string what = "states[" + std::to_string(i) + "]";
    if (n[i].IsScalar() && n[i].Scalar() == "goal" && n[i].Tag() != "!") {
      if (scene) {
        formations.push_back(scene->goal);
        p.states.push_back(states::ToString(scene->goal));
      }
      continue;
    }
    if (auto cf = r.Formation(n[i], what, scene ? &elements : nullptr)) {
      p.states.push_back(states::ToString(*cf));
      formations.push_back(std::move(*cf));
    }
  }
  for (std::size_t i = 1; i < p.states.size(); ++i) {
    if (p.states[i] == p.states[i - 1] && i < n.size())
      r.Error(n[i], "states[" + std::to_string(i) +
                        "] repeats the state before it, expected "
                        "each planned state to differ from the one before");
  }
}

}  // namespace

PlanLoadResult ReadPlanText(std::string_view yaml_text, const std::string& display_name,
                            const std::filesystem::path& directory,
                            const PlanLoadOptions& options) {
  PlanLoadResult result;
  Reader r(display_name, result.diagnostics);
  plan::Plan p;
  if (yaml_text.size() > kMaxYamlBytes) {
    result.diagnostics.Error(display_name, 0, 0,
                             "the file is " + std::to_string(yaml_text.size() >> 20) +
                                 " MiB, expected a YAML plan file of at most " +
                                 std::to_string(kMaxYamlBytes >> 20) + " MiB");
    return result;
  }
  if (!CheckInputText(yaml_text, display_name, "a YAML plan file", result.diagnostics))
    return result;
  YAML::Node root;
  try {
    root = LoadOneDocument(r, std::string(yaml_text), "a plan file");
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp's own guard of its recursive parser (500 levels); its message is "bad file".
    r.Error(e.mark, "nesting deeper than " + std::to_string(kMaxYamlDepth) +
                        " levels, expected a plan file (a few levels deep)");
    return result;
  } catch (const YAML::Exception& e) {
    r.Error(e.mark, e.msg + ", expected valid YAML");
    return result;
  }
  if (!CheckYamlShape(r, root, "a plan file")) return result;
  if (!root.IsMap()) {
    r.Error(root, std::string("a plan file must be a map, found ") + KindName(root) +
                      ", expected keys such as tubeplan, plan, scene, trajectory, states");
    return result;
  }
  r.ExpectMap(root, "plan file", {"tubeplan", "plan", "scene", "trajectory", "states", "limits"});
  ReadHeader(r, root, p);

  // A file the plan names, read once, relative to the plan's directory: (node, path, text), or
  // nothing after reporting why.
  struct Named {
    YAML::Node node;
    std::string full;
    std::string text;
  };
  // A path the plan names, relative to the plan's directory, or nothing (reported).
  auto named_path = [&](const char* key, std::string& target) {
    std::optional<std::pair<YAML::Node, std::filesystem::path>> named;
    const YAML::Node n = r.Get(root, key, "plan file", true);
    if (!n.IsDefined()) return named;
    const auto path = r.String(n, key);
    if (!path) return named;
    target = *path;
    named.emplace(n, directory / *path);
    return named;
  };
  auto cannot_read = [&](const YAML::Node& n, const char* key, const std::filesystem::path& full,
                         const std::string& why, const char* expected) {
    r.Error(n, std::string(key) + ": cannot read '" + full.string() + "' (" + why + "), expected " +
                   expected);
  };
  auto read_named = [&](const char* key, const char* expected, std::uintmax_t max_bytes,
                        std::string& target) {
    std::optional<Named> named;
    const auto path = named_path(key, target);
    if (!path) return named;
    const auto& [n, full] = *path;
    ReadResult read = ReadInputFile(full, max_bytes);
    if (read.text) {
      named = Named{n, full.string(), std::move(*read.text)};
    } else {
      cannot_read(n, key, full, read.error, expected);
    }
    return named;
  };
  // The scene first: the states are checked against its elements.
  std::optional<scene::Scene> scene;
  if (const auto named = read_named("scene", "a scene file path relative to the plan file",
                                    kMaxYamlBytes, p.scene)) {
    // A mesh the scene names lies relative to the scene file, not to the plan.
    SceneLoadResult loaded =
        LoadSceneText(named->text, named->full, std::filesystem::path(named->full).parent_path());
    result.diagnostics.Append(loaded.diagnostics);
    if (!loaded.scene) r.Error(named->node, "scene: '" + named->full + "' has errors (listed)");
    scene = std::move(loaded.scene);
  }
  constexpr const char* kTrajectoryPath = "a trajectory CSV path relative to the plan file";
  if (options.trajectory_in_memory) {
    if (const auto named =
            read_named("trajectory", kTrajectoryPath, kMaxInputBytes, p.trajectory)) {
      TrajectoryLoadResult loaded = LoadTrajectoryText(named->text, named->full);
      result.diagnostics.Append(loaded.diagnostics);
      if (!loaded.trajectory)
        r.Error(named->node, "trajectory: '" + named->full + "' has errors (listed)");
      result.trajectory = std::move(loaded.trajectory);
    }
  } else if (const auto named = named_path("trajectory", p.trajectory)) {
    const auto& [n, full] = *named;
    TrajectoryScanResult scanned = ScanTrajectoryFile(full);
    if (!scanned.read_error.empty()) {
      cannot_read(n, "trajectory", full, scanned.read_error, kTrajectoryPath);
    } else {
      result.diagnostics.Append(scanned.diagnostics);
      if (!scanned.info) r.Error(n, "trajectory: '" + full.string() + "' has errors (listed)");
      result.trajectory_file = std::move(scanned.info);
    }
  }
  if (const YAML::Node n = r.Get(root, "states", "plan file", true); n.IsDefined())
    ReadStates(r, n, scene, p, result.states);
  if (!result.diagnostics.HasErrors()) {
    result.plan = std::move(p);
    result.scene = std::move(scene);
  } else {
    result.trajectory.reset();
    result.trajectory_file.reset();
    result.states.clear();
  }
  return result;
}

PlanLoadResult LoadPlanText(std::string_view yaml_text, const std::string& display_name,
                            const std::filesystem::path& directory,
                            const PlanLoadOptions& options) {
  try {
    return ReadPlanText(yaml_text, display_name, directory, options);
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp's own guard of its recursive parser (500 levels); its message is "bad file".
    PlanLoadResult result;
    Reader r(display_name, result.diagnostics);
    r.Error(e.mark, "nesting deeper than " + std::to_string(kMaxYamlDepth) +
                        " levels, expected a plan file (a few levels deep)");
    return result;
  } catch (const YAML::Exception& e) {
    PlanLoadResult result;
    Reader r(display_name, result.diagnostics);
    r.Error(e.mark, e.msg + ", expected valid YAML");
    return result;
  } catch (const std::exception& e) {
    // Not expected: the reader checks every node's type before converting it. Still a file
    // problem for the user, never a crash.
    PlanLoadResult result;
    result.diagnostics.Error(display_name, 0, 0,
                             std::string("could not read the plan: ") + e.what());
    return result;
  }
}

PlanLoadResult LoadPlanFile(const std::filesystem::path& path, const PlanLoadOptions& options) {
  const ReadResult read = ReadInputFile(path, kMaxYamlBytes);
  if (!read.text) {
    PlanLoadResult result;
    result.diagnostics.Error(
        path.string(), 0, 0,
        "cannot read file (" + read.error + "), expected a readable YAML plan file");
    return result;
  }
  return LoadPlanText(*read.text, path.string(), path.parent_path(), options);
}

}  // namespace tubeplan::io
