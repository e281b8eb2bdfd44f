// A box as a tessellated triangle mesh (bench/tessellated_box.hpp).
#include "tessellated_box.hpp"

#include <array>
#include <stdexcept>
#include <string>

namespace tubeplan::bench {

scene::TriangleMesh TessellatedBox(const Eigen::Vector3d& size_m, int divisions) {
  if (divisions < 1 || !(size_m.minCoeff() > 0.0))
    throw std::invalid_argument("TessellatedBox: divisions " + std::to_string(divisions) +
                                " and size [" + std::to_string(size_m.x()) + ", " +
                                std::to_string(size_m.y()) + ", " + std::to_string(size_m.z()) +
                                "] m, expected divisions >= 1 and every extent > 0");
  // Each face's axis and outward sign, in BoxFace order (top, bottom, xpos, xneg, ypos, yneg).
  constexpr std::array<std::array<int, 2>, 6> kFaces = {
      {{2, 1}, {2, -1}, {0, 1}, {0, -1}, {1, 1}, {1, -1}}};
  const Eigen::Vector3d half_m = 0.5 * size_m;
  const int n = divisions;
  scene::TriangleMesh soup;
  for (const char* id : scene::kBoxFaceIds) soup.names.emplace_back(id);
  for (std::size_t f = 0; f < kFaces.size(); ++f) {
    const int axis = kFaces[f][0];
    const double sign = kFaces[f][1];
    // e_u x e_v = e_axis (cyclic order): counter-clockwise in (u, v) faces +axis.
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    // The face's grid of (n + 1)^2 points; neighbouring faces repeat their shared rows, which
    // the weld below merges.
    const int first = int(soup.vertices_P_m.size());
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        Eigen::Vector3d p;
        p[axis] = sign * half_m[axis];
        p[u] = -half_m[u] + size_m[u] * i / n;
        p[v] = -half_m[v] + size_m[v] * j / n;
        soup.vertices_P_m.push_back(p);
      }
    }
    const auto at = [&](int i, int j) { return first + j * (n + 1) + i; };
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const int c00 = at(i, j), c10 = at(i + 1, j), c11 = at(i + 1, j + 1), c01 = at(i, j + 1);
        if (sign > 0.0) {
          soup.triangles.push_back({c00, c10, c11});
          soup.triangles.push_back({c00, c11, c01});
        } else {
          soup.triangles.push_back({c00, c11, c10});
          soup.triangles.push_back({c00, c01, c11});
        }
        soup.triangle_names.push_back(int(f));
        soup.triangle_names.push_back(int(f));
      }
    }
  }
  return scene::WeldVertices(soup, scene::WeldTolerance_m(soup));
}

std::shared_ptr<const scene::PartMesh> TessellatedBoxMesh(const Eigen::Vector3d& size_m,
                                                          int divisions) {
  scene::TriangleMesh mesh = TessellatedBox(size_m, divisions);
  const std::vector<scene::MeshProblem> problems = scene::CheckMesh(mesh);
  if (!problems.empty())
    throw std::logic_error("TessellatedBoxMesh: " + std::to_string(problems.size()) +
                           " problem(s), the first at triangle " +
                           std::to_string(problems.front().triangle) + ": " +
                           problems.front().message + "; a closed box was expected");
  scene::MeshElements elements = FindElements(mesh);
  return scene::MakePartMesh("tessellated box", std::move(mesh), std::move(elements));
}

}  // namespace tubeplan::bench
