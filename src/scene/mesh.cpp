#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

#include <tubeplan/scene/mesh.hpp>

#include "scene/mesh_topology.hpp"

namespace tubeplan::scene {

double WeldTolerance_m(const TriangleMesh& mesh) {
  if (mesh.vertices_P_m.empty()) return 0.0;
  Eigen::Vector3d lo = mesh.vertices_P_m.front(), hi = lo;
  for (const Eigen::Vector3d& v : mesh.vertices_P_m) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  return kWeldRelativeTolerance * (hi - lo).norm();
}

TriangleMesh WeldVertices(const TriangleMesh& mesh, double tolerance_m,
                          std::vector<int>* source_triangle) {
  const std::vector<Eigen::Vector3d>& v = mesh.vertices_P_m;
  const int n = static_cast<int>(v.size());
  // Vertices sorted by a grid cell of twice the tolerance: a vertex's partners lie in the 27
  // cells around its own, found by binary search (n log n, whatever the mesh's shape).
  const double cell_m = tolerance_m > 0.0 ? 2.0 * tolerance_m : 1.0;
  // Cells counted from the mesh's low corner, capped far below the integers' range: a point far
  // from the origin, or beyond any cell worth telling apart, cannot overflow its key.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  for (const Eigen::Vector3d& p : v) lo = lo.cwiseMin(p);
  using Key = std::array<long long, 3>;
  auto cell_of = [&](double x, double x_lo) {
    return static_cast<long long>(std::min(std::floor((x - x_lo) / cell_m), 1e15));
  };
  auto key_of = [&](const Eigen::Vector3d& p) {
    return Key{cell_of(p.x(), lo.x()), cell_of(p.y(), lo.y()), cell_of(p.z(), lo.z())};
  };
  std::vector<std::pair<Key, int>> sorted(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) sorted[std::size_t(i)] = {key_of(v[std::size_t(i)]), i};
  std::sort(sorted.begin(), sorted.end());
  // Union-find whose root is the smallest index: the first occurrence keeps its position.
  std::vector<int> root(static_cast<std::size_t>(n));
  std::iota(root.begin(), root.end(), 0);
  auto find = [&](int i) {
    while (root[std::size_t(i)] != i)
      i = root[std::size_t(i)] = root[std::size_t(root[std::size_t(i)])];
    return i;
  };
  for (int i = 0; i < n; ++i) {
    const Key k = key_of(v[std::size_t(i)]);
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const Key near{k[0] + dx, k[1] + dy, k[2] + dz};
          auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(near, -1));
          for (; it != sorted.end() && it->first == near; ++it) {
            const int j = it->second;
            if (j <= i) continue;
            if ((v[std::size_t(i)] - v[std::size_t(j)]).cwiseAbs().maxCoeff() > tolerance_m)
              continue;
            const int a = find(i), b = find(j);
            if (a != b) root[std::size_t(std::max(a, b))] = std::min(a, b);
          }
        }
  }
  // Used vertices, renumbered in order of first use.
  TriangleMesh out;
  out.names = mesh.names;
  out.triangles.reserve(mesh.triangles.size());
  if (source_triangle) source_triangle->clear();
  std::vector<int> renumber(std::size_t(n), -1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const std::array<int, 3> r{find(mesh.triangles[t][0]), find(mesh.triangles[t][1]),
                               find(mesh.triangles[t][2])};
    if (r[0] == r[1] || r[1] == r[2] || r[2] == r[0]) continue;
    std::array<int, 3> w{};
    for (std::size_t k = 0; k < 3; ++k) {
      if (renumber[std::size_t(r[k])] < 0) {
        renumber[std::size_t(r[k])] = static_cast<int>(out.vertices_P_m.size());
        out.vertices_P_m.push_back(v[std::size_t(r[k])]);
      }
      w[k] = renumber[std::size_t(r[k])];
    }
    out.triangles.push_back(w);
    out.triangle_names.push_back(t < mesh.triangle_names.size() ? mesh.triangle_names[t] : -1);
    if (source_triangle) source_triangle->push_back(static_cast<int>(t));
  }
  return out;
}

Eigen::Vector3d TriangleNormal(const TriangleMesh& mesh, int t) {
  const std::array<int, 3>& tri = mesh.triangles[std::size_t(t)];
  const Eigen::Vector3d& a = mesh.vertices_P_m[std::size_t(tri[0])];
  const Eigen::Vector3d n = (mesh.vertices_P_m[std::size_t(tri[1])] - a)
                                .cross(mesh.vertices_P_m[std::size_t(tri[2])] - a);
  const double length = n.norm();
  return length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
}

MeshTopology BuildTopology(const TriangleMesh& mesh) {
  const std::size_t n = mesh.triangles.size();
  // Every triangle side as (low vertex, high vertex, triangle, side), sorted: one run per edge.
  std::vector<std::tuple<int, int, int, int>> sides;
  sides.reserve(3 * n);
  for (std::size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles[t][std::size_t(k)],
                b = mesh.triangles[t][std::size_t((k + 1) % 3)];
      sides.emplace_back(std::min(a, b), std::max(a, b), static_cast<int>(t), k);
    }
  std::sort(sides.begin(), sides.end());
  MeshTopology topo;
  topo.triangle_edge.assign(n, {-1, -1, -1});
  topo.neighbour.assign(n, {kOpen, kOpen, kOpen});
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    while (j < sides.size() && std::get<0>(sides[j]) == std::get<0>(sides[i]) &&
           std::get<1>(sides[j]) == std::get<1>(sides[i]))
      ++j;
    const int edge = static_cast<int>(topo.edge_vertices.size());
    topo.edge_vertices.push_back({std::get<0>(sides[i]), std::get<1>(sides[i])});
    std::vector<int>& tris = topo.edge_triangles.emplace_back();
    for (std::size_t s = i; s < j; ++s) {
      const auto [lo, hi, t, k] = sides[s];
      tris.push_back(t);
      topo.triangle_edge[std::size_t(t)][std::size_t(k)] = edge;
      int across = kOpen;
      if (j - i == 2) across = std::get<2>(sides[s == i ? i + 1 : i]);
      if (j - i > 2) across = kNonManifold;
      topo.neighbour[std::size_t(t)][std::size_t(k)] = across;
    }
    i = j;
  }
  return topo;
}

bool RunsFromTo(const TriangleMesh& mesh, int t, int a, int b) {
  const std::array<int, 3>& tri = mesh.triangles[std::size_t(t)];
  for (std::size_t k = 0; k < 3; ++k)
    if (tri[k] == a && tri[(k + 1) % 3] == b) return true;
  return false;
}

}  // namespace tubeplan::scene
