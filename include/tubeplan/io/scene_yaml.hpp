#pragma once
// Loading scene files (YAML, format version 1; the format is documented in docs/scene-format.md).

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <tubeplan/io/diagnostics.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::io {

struct SceneLoadResult {
  std::optional<scene::Scene> scene;  ///< set only when there is no error
  Diagnostics diagnostics;            ///< every error (and warning) found, all at once
};

/// Reads and validates a scene file; problems are reported against `path` as given. A mesh
/// part's file is read relative to the scene file's directory (docs/scene-format.md).
SceneLoadResult LoadSceneFile(const std::filesystem::path& path);

/// The same for text already in memory; `display_name` is the file name used in diagnostics, and
/// a mesh part's relative file is read relative to `base_dir` (empty: the current directory).
SceneLoadResult LoadSceneText(std::string_view yaml_text, const std::string& display_name,
                              const std::filesystem::path& base_dir = {});

}  // namespace tubeplan::io
