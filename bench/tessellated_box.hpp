#pragma once
// A box as a closed triangle mesh, each face cut into a grid: the mesh twin of a box part, for
// timing the core on a mesh part against the same box (tubeplan bench, docs/core.md).

#include <memory>

#include <Eigen/Core>

#include <tubeplan/scene/mesh.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::bench {

/// A box of full extents `size_m` [m] centred on its frame's origin, each of its six faces cut
/// into divisions x divisions cells of two triangles (12 divisions^2 triangles), welded, wound
/// outward. Its triangles are grouped by face in BoxFace order and named by the box's face ids
/// (top, bottom, xpos, xneg, ypos, yneg), so that its elements are named as a box part's faces.
/// Throws std::invalid_argument unless divisions >= 1 and every extent is positive.
scene::TriangleMesh TessellatedBox(const Eigen::Vector3d& size_m, int divisions);

/// TessellatedBox checked (scene::CheckMesh), cut into elements and with its distance queries
/// built: a part's mesh. Throws std::logic_error naming the first problem if CheckMesh finds one.
std::shared_ptr<const scene::PartMesh> TessellatedBoxMesh(const Eigen::Vector3d& size_m,
                                                          int divisions);

}  // namespace tubeplan::bench
