#include <bit>
#include <iterator>

#include <tubeplan/scene/elements.hpp>

namespace tubeplan::scene {
namespace {

// Faces on the same axis (top/bottom, xpos/xneg, ypos/yneg) are parallel and never meet.
constexpr int AxisOf(int face) { return face / 2; }

std::string JoinFaceNames(const Part& part, std::uint8_t mask) {
  std::string name = part.name + ".";
  bool first = true;
  for (int face = 0; face < int(FaceIds(part.shape).size()); ++face) {
    if ((mask & (1u << face)) == 0) continue;
    if (!first) name += '_';
    name += part.face_names[static_cast<std::size_t>(face)];
    first = false;
  }
  return name;
}

// A box's elements: faces, then edges (two faces on different axes), then vertices (one face
// per axis): every subset of faces with at most one face per axis is an element.
void AddBoxElements(const Part& part, std::uint32_t p, std::vector<PartElement>& elements) {
  for (int count = 1; count <= 3; ++count) {
    for (unsigned mask = 1; mask < 64; ++mask) {
      if (std::popcount(mask) != count) continue;
      bool one_per_axis = true;
      for (int a = 0; a < 6 && one_per_axis; ++a)
        for (int b = a + 1; b < 6; ++b)
          if ((mask & (1u << a)) && (mask & (1u << b)) && AxisOf(a) == AxisOf(b))
            one_per_axis = false;
      if (!one_per_axis) continue;
      const auto kind = static_cast<ElementKind>(count - 1);
      const auto face_mask = static_cast<std::uint8_t>(mask);
      elements.push_back({p, kind, face_mask, JoinFaceNames(part, face_mask)});
    }
  }
}

// A cylinder's elements: its three faces, then the two rims where the side meets an end.
void AddCylinderElements(const Part& part, std::uint32_t p, std::vector<PartElement>& elements) {
  const auto bit = [](CylinderFace f) { return std::uint8_t(1u << int(f)); };
  for (CylinderFace f : {CylinderFace::kTop, CylinderFace::kBottom, CylinderFace::kSide})
    elements.push_back({p, ElementKind::kFace, bit(f), JoinFaceNames(part, bit(f))});
  for (CylinderFace end : {CylinderFace::kTop, CylinderFace::kBottom}) {
    const auto mask = std::uint8_t(bit(end) | bit(CylinderFace::kSide));
    elements.push_back({p, ElementKind::kEdge, mask, JoinFaceNames(part, mask)});
  }
}

// A mesh's elements, as its file cut them (scene::FindElements): faces, edges, vertices.
void AddMeshElements(const Part& part, std::uint32_t p, std::vector<PartElement>& elements) {
  const MeshElements& m = part.mesh->elements;
  const std::string prefix = part.name + ".";
  for (const MeshFace& f : m.faces) elements.push_back({p, ElementKind::kFace, 0, prefix + f.name});
  for (const MeshEdge& e : m.edges) elements.push_back({p, ElementKind::kEdge, 0, prefix + e.name});
  for (const MeshVertex& v : m.vertices)
    elements.push_back({p, ElementKind::kVertex, 0, prefix + v.name});
}

}  // namespace

std::vector<PartElement> ElementsOf(const Part& part, std::uint32_t part_index) {
  std::vector<PartElement> elements;
  if (part.shape == PartShape::kMesh)
    AddMeshElements(part, part_index, elements);
  else if (part.shape == PartShape::kCylinder)
    AddCylinderElements(part, part_index, elements);
  else
    AddBoxElements(part, part_index, elements);
  return elements;
}

std::vector<PartElement> EnumerateElements(const Scene& scene) {
  std::vector<PartElement> elements;
  elements.reserve(scene.parts.size() * 26);
  for (std::uint32_t p = 0; p < scene.parts.size(); ++p) {
    std::vector<PartElement> of_part = ElementsOf(scene.parts[p], p);
    elements.insert(elements.end(), std::make_move_iterator(of_part.begin()),
                    std::make_move_iterator(of_part.end()));
  }
  return elements;
}

int FindElement(const std::vector<PartElement>& elements, std::string_view name) {
  for (std::size_t i = 0; i < elements.size(); ++i)
    if (elements[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace tubeplan::scene
