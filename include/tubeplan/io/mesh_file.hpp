#pragma once
// Triangle-mesh files of rigid parts (docs/meshes.md): Wavefront OBJ and STL (ASCII or binary),
// read, scaled to metres, welded, checked and cut into named faces, edges and vertices.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <tubeplan/io/diagnostics.hpp>
#include <tubeplan/scene/mesh.hpp>

namespace tubeplan::io {

/// The largest mesh file read: 200,000 triangles (scene::kMaxTriangles) of ASCII STL take about
/// 50 MB; four times that is a mistake, refused before it fills the memory.
inline constexpr std::uintmax_t kMaxMeshBytes = std::uintmax_t{256} << 20;

/// Where each triangle of a mesh file came from, for messages: the line and column of its OBJ
/// `f` statement or STL `facet`, or, in a binary STL, line 1 and the byte offset of its record
/// plus one.
struct MeshPlace {
  int line = 0;
  int column = 0;
};

struct MeshLoadResult {
  /// The welded, checked mesh in the file's frame scaled to metres; set only without errors.
  std::optional<scene::TriangleMesh> mesh;
  std::optional<scene::MeshElements> elements;  ///< set with mesh
  Diagnostics diagnostics;                      ///< every error and warning, all at once
};

/// Reads an OBJ or STL file (told by its extension, .obj or .stl in any case), multiplies its
/// numbers by `scale` (the file's unit in metres: 0.001 for millimetres; > 0), welds coincident
/// vertices (scene::kWeldRelativeTolerance), checks it (scene::CheckMesh) and finds its elements.
/// Problems are reported against `path` as given. Throws std::invalid_argument for a bad scale.
MeshLoadResult LoadMeshFile(const std::filesystem::path& path, double scale);

/// The same for bytes already in memory; `display_name` is the file name used in diagnostics,
/// and its extension tells the format.
MeshLoadResult LoadMeshBytes(std::string_view bytes, const std::string& display_name, double scale);

}  // namespace tubeplan::io
