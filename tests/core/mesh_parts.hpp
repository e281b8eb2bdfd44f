#pragma once
// Mesh parts built in code for the core's tests: a box and a prism written as triangles, so that
// the core's answers for them can be set against the box and cylinder shapes it knows exactly.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <tubeplan/scene/mesh.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::testing {

// Adds the quad a b c d (counter-clockwise seen from outside) as two triangles of group `name`.
inline void AddQuad(scene::TriangleMesh& mesh, int a, int b, int c, int d, int name) {
  mesh.triangles.push_back({a, b, c});
  mesh.triangles.push_back({a, c, d});
  mesh.triangle_names.insert(mesh.triangle_names.end(), 2, name);
}

// A part from triangles: checked (a test fails on a problem), its elements found.
inline scene::Part MeshPart(const std::string& name, scene::TriangleMesh mesh,
                            const Eigen::Isometry3d& X_WP) {
  scene::MeshElements elements = scene::FindElements(mesh);
  return scene::MakeMeshPart(
      name, scene::MakePartMesh(name + ".obj", std::move(mesh), std::move(elements)), X_WP);
}

// A box of `size` centred on its frame, two triangles a face, its faces grouped and named as a
// box part's and written in the box's face order (top, bottom, xpos, xneg, ypos, yneg), so that
// its elements' names are the box part's.
inline scene::TriangleMesh BoxMesh(const Eigen::Vector3d& size) {
  scene::TriangleMesh mesh;
  for (int corner = 0; corner < 8; ++corner)
    mesh.vertices_P_m.push_back(0.5 * Eigen::Vector3d(corner & 1 ? size.x() : -size.x(),
                                                      corner & 2 ? size.y() : -size.y(),
                                                      corner & 4 ? size.z() : -size.z()));
  mesh.names = {"top", "bottom", "xpos", "xneg", "ypos", "yneg"};
  // Corner index bits: 1 x, 2 y, 4 z.
  AddQuad(mesh, 4, 5, 7, 6, 0);  // top, +z
  AddQuad(mesh, 0, 2, 3, 1, 1);  // bottom, -z
  AddQuad(mesh, 1, 3, 7, 5, 2);  // xpos
  AddQuad(mesh, 0, 4, 6, 2, 3);  // xneg
  AddQuad(mesh, 2, 6, 7, 3, 4);  // ypos
  AddQuad(mesh, 0, 1, 5, 4, 5);  // yneg
  return mesh;
}

// A prism of `sides` sides round z, its corners on a circle of `radius`, `length` long, centred
// on its frame: faces "top", "bottom" and, with sides >= 19 (turns below the feature angle),
// one curved face "side".
inline scene::TriangleMesh PrismMesh(double radius, double length, int sides) {
  scene::TriangleMesh mesh;
  mesh.names = {"top", "bottom", "side"};
  for (const double z : {0.5 * length, -0.5 * length})
    for (int k = 0; k < sides; ++k) {
      const double phi = 2.0 * M_PI * k / sides;
      mesh.vertices_P_m.emplace_back(radius * std::cos(phi), radius * std::sin(phi), z);
    }
  const int top_centre = int(mesh.vertices_P_m.size());
  mesh.vertices_P_m.emplace_back(0.0, 0.0, 0.5 * length);
  mesh.vertices_P_m.emplace_back(0.0, 0.0, -0.5 * length);
  for (int k = 0; k < sides; ++k) {
    const int next = (k + 1) % sides;
    mesh.triangles.push_back({top_centre, k, next});
    mesh.triangle_names.push_back(0);
    mesh.triangles.push_back({top_centre + 1, sides + next, sides + k});
    mesh.triangle_names.push_back(1);
    AddQuad(mesh, sides + k, sides + next, next, k, 2);
  }
  return mesh;
}

}  // namespace tubeplan::testing
