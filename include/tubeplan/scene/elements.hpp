#pragma once
// Named surface elements of the rigid parts: a box has 6 faces, 12 edges and 8 vertices. A face
// is "part.face"; an edge joins its two faces' names with '_' and a vertex its three, in the
// order of BoxFace (top/bottom, then x faces, then y faces): "left.top", "left.top_xpos",
// "left.top_xpos_ypos" — or, with the scene's face names, "left.top_inner". A cylinder has 3
// faces (top, bottom, side) and 2 edges, its rims: "post.top_side", "post.bottom_side". A mesh
// has the faces, edges and vertices its file cuts it into (docs/meshes.md): "clip.floor".

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <tubeplan/scene/scene.hpp>

namespace tubeplan::scene {

enum class ElementKind : unsigned char { kFace, kEdge, kVertex };

struct PartElement {
  std::uint32_t part_index = 0;
  ElementKind kind = ElementKind::kFace;
  /// Bit i set: the element lies on face i (BoxFace, CylinderFace); 0 on a mesh.
  std::uint8_t face_mask = 0;
  std::string name;  ///< "part.element"
};

/// Every element of every part, in part order, then faces, edges, vertices.
std::vector<PartElement> EnumerateElements(const Scene& scene);

/// The elements of one part, `part_index` its index in the scene, in the order of
/// EnumerateElements: an element's position here is its index within the part.
std::vector<PartElement> ElementsOf(const Part& part, std::uint32_t part_index);

/// Index into `elements` of the element named `name`, or -1.
int FindElement(const std::vector<PartElement>& elements, std::string_view name);

}  // namespace tubeplan::scene
