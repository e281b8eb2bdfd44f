#include <filesystem>
#include <sstream>

#include <tubeplan/batch/check.hpp>
#include <tubeplan/core/core.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/trajectory_csv.hpp>

#include "io/text_file.hpp"

namespace tubeplan::batch {
namespace {

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

// Whether each element is a convex mesh edge, for a mesh edge: a mesh's elements are its faces,
// then its edges, then its vertices (scene::ElementsOf), counted from the part's first element.
std::vector<std::optional<bool>> MeshEdgeConvexity(
    const scene::Scene& s, const std::vector<scene::PartElement>& elements) {
  std::vector<std::optional<bool>> convex(elements.size());
  for (std::size_t e = 0, first = 0; e < elements.size(); ++e) {
    if (e > 0 && elements[e].part_index != elements[e - 1].part_index) first = e;
    const scene::Part& part = s.parts[elements[e].part_index];
    if (part.shape != scene::PartShape::kMesh || elements[e].kind != scene::ElementKind::kEdge)
      continue;
    const std::size_t edge = e - first - part.mesh->elements.faces.size();
    convex[e] = part.mesh->elements.edges[edge].convex;
  }
  return convex;
}

}  // namespace

CheckedFile CheckFile(const std::string& file) {
  if (std::filesystem::path(file).extension() == ".csv") {
    // Streamed: a recording of hours is checked in the memory of a few lines.
    io::TrajectoryScanResult scanned = io::ScanTrajectoryFile(file);
    CheckedFile c{"trajectory", std::move(scanned.diagnostics), std::nullopt, {}, {}};
    if (scanned.info) c.summary = Summary(*scanned.info);
    return c;
  }
  // A plan file names its plan at the top level ("plan: ..."); any other YAML is a scene.
  if (const std::optional<std::string> text = io::ReadTextFile(file);
      text && (text->rfind("plan:", 0) == 0 || text->find("\nplan:") != std::string::npos)) {
    io::PlanLoadResult plan = io::LoadPlanFile(file, {.trajectory_in_memory = false});
    CheckedFile c{"plan", std::move(plan.diagnostics), std::nullopt, {}, {}};
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
  CheckedFile c{"scene", std::move(loaded.diagnostics), std::nullopt, {}, {}};
  if (loaded.scene) {
    c.summary = Summary(*loaded.scene);
    c.elements = scene::EnumerateElements(*loaded.scene);
    c.convex = MeshEdgeConvexity(*loaded.scene, c.elements);
  }
  return c;
}

const char* ToString(scene::ElementKind kind) {
  return kind == scene::ElementKind::kFace   ? "face"
         : kind == scene::ElementKind::kEdge ? "edge"
                                             : "vertex";
}

}  // namespace tubeplan::batch
