#pragma once
// What `tubeplan check` says about one file: its kind (scene, plan or trajectory, told by its
// extension and first key), every problem in it, and for a valid file a one-line summary (and a
// scene's part elements).

#include <optional>
#include <string>
#include <vector>

#include <tubeplan/io/diagnostics.hpp>
#include <tubeplan/scene/elements.hpp>

namespace tubeplan::batch {

struct CheckedFile {
  const char* kind = "scene";  ///< "scene", "plan" or "trajectory"
  io::Diagnostics diagnostics;
  std::optional<std::string> summary;        ///< set when the file is valid
  std::vector<scene::PartElement> elements;  ///< a valid scene's, in EnumerateElements order
  /// Per element: a mesh edge's convexity (the material's angle there below 180 deg); unset for
  /// every other element (a box's and a cylinder's edges are all convex).
  std::vector<std::optional<bool>> convex;
};

/// Reads and checks `path`: a .csv is a trajectory (streamed: an hours-long recording is checked
/// in the memory of a few lines), a YAML file with a top-level `plan:` a plan, any other a scene.
CheckedFile CheckFile(const std::string& path);

/// "face", "edge" or "vertex".
const char* ToString(scene::ElementKind kind);

}  // namespace tubeplan::batch
