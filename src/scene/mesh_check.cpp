// The checks that make a welded triangle mesh a solid the contact model can use: each edge of
// exactly two triangles that run it opposite ways, every body facing outwards, no two triangles
// crossing. Why each is an error: docs/meshes.md, "What is checked".
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include <tubeplan/scene/aabb_tree.hpp>
#include <tubeplan/scene/mesh.hpp>

#include "scene/mesh_topology.hpp"

namespace tubeplan::scene {
namespace {

std::string Millimetres(double length_m) {
  std::ostringstream text;
  text.precision(6);
  text << length_m * 1e3 << " mm";
  return text.str();
}

std::string Point(const Eigen::Vector3d& p_m) {
  std::ostringstream text;
  text.precision(6);
  text << "(" << p_m.x() * 1e3 << ", " << p_m.y() * 1e3 << ", " << p_m.z() * 1e3 << ") mm";
  return text.str();
}

const Eigen::Vector3d& Corner(const TriangleMesh& mesh, int t, int k) {
  return mesh.vertices_P_m[std::size_t(mesh.triangles[std::size_t(t)][std::size_t(k)])];
}

// Whether segment pq passes through the inside of triangle abc (unit normal n): its ends
// strictly on either side of the plane and the crossing point strictly inside, by more than
// `tolerance_m`. Touching is no crossing.
bool SegmentCrosses(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                    const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& n,
                    double tolerance_m) {
  const double dp = n.dot(p - a), dq = n.dot(q - a);
  if (!((dp > tolerance_m && dq < -tolerance_m) || (dp < -tolerance_m && dq > tolerance_m)))
    return false;
  const Eigen::Vector3d x = p + (q - p) * (dp / (dp - dq));
  const std::array<const Eigen::Vector3d*, 3> v = {&a, &b, &c};
  for (std::size_t k = 0; k < 3; ++k) {
    const Eigen::Vector3d edge = *v[(k + 1) % 3] - *v[k];
    if (n.dot(edge.cross(x - *v[k])) <= tolerance_m * edge.norm()) return false;
  }
  return true;
}

// Coplanar triangles that overlap by more than the tolerance: an edge of one crossing an edge of
// the other, or a corner of one inside the other, in the plane (2-D, along n's largest axis).
bool CoplanarOverlap(const std::array<Eigen::Vector3d, 3>& A,
                     const std::array<Eigen::Vector3d, 3>& B, const Eigen::Vector3d& n,
                     double tolerance_m) {
  Eigen::Index drop = 0;
  n.cwiseAbs().maxCoeff(&drop);
  const Eigen::Index u = (drop + 1) % 3, w = (drop + 2) % 3;
  auto flat = [&](const Eigen::Vector3d& p) { return Eigen::Vector2d(p[u], p[w]); };
  auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
  };
  auto inside = [&](const std::array<Eigen::Vector3d, 3>& T, const Eigen::Vector2d& p) {
    const double sign = cross(flat(T[1]) - flat(T[0]), flat(T[2]) - flat(T[0])) > 0 ? 1.0 : -1.0;
    for (std::size_t k = 0; k < 3; ++k) {
      const Eigen::Vector2d e = flat(T[(k + 1) % 3]) - flat(T[k]);
      if (sign * cross(e, p - flat(T[k])) <= tolerance_m * e.norm()) return false;
    }
    return true;
  };
  for (std::size_t i = 0; i < 3; ++i) {
    if (inside(B, flat(A[i])) || inside(A, flat(B[i]))) return true;
    for (std::size_t j = 0; j < 3; ++j) {
      const Eigen::Vector2d p = flat(A[i]), q = flat(A[(i + 1) % 3]);
      const Eigen::Vector2d r = flat(B[j]), s = flat(B[(j + 1) % 3]);
      const double d1 = cross(q - p, r - p), d2 = cross(q - p, s - p);
      const double d3 = cross(s - r, p - r), d4 = cross(s - r, q - r);
      const double e1 = tolerance_m * (q - p).norm(), e2 = tolerance_m * (s - r).norm();
      if (((d1 > e1 && d2 < -e1) || (d1 < -e1 && d2 > e1)) &&
          ((d3 > e2 && d4 < -e2) || (d3 < -e2 && d4 > e2)))
        return true;
    }
  }
  return false;
}

bool TrianglesCross(const TriangleMesh& mesh, int t, int u, double tolerance_m) {
  const std::array<Eigen::Vector3d, 3> A = {Corner(mesh, t, 0), Corner(mesh, t, 1),
                                            Corner(mesh, t, 2)};
  const std::array<Eigen::Vector3d, 3> B = {Corner(mesh, u, 0), Corner(mesh, u, 1),
                                            Corner(mesh, u, 2)};
  const Eigen::Vector3d na = TriangleNormal(mesh, t), nb = TriangleNormal(mesh, u);
  const bool coplanar = std::all_of(B.begin(), B.end(), [&](const Eigen::Vector3d& p) {
    return std::abs(na.dot(p - A[0])) <= tolerance_m;
  });
  if (coplanar) return CoplanarOverlap(A, B, na, tolerance_m);
  for (std::size_t k = 0; k < 3; ++k) {
    if (SegmentCrosses(A[k], A[(k + 1) % 3], B[0], B[1], B[2], nb, tolerance_m)) return true;
    if (SegmentCrosses(B[k], B[(k + 1) % 3], A[0], A[1], A[2], na, tolerance_m)) return true;
  }
  return false;
}

void CheckSelfIntersections(const TriangleMesh& mesh, double tolerance_m,
                            std::vector<MeshProblem>& problems) {
  const std::size_t n = mesh.triangles.size();
  std::vector<Eigen::Vector3d> lo(n), hi(n);
  for (std::size_t t = 0; t < n; ++t) {
    lo[t] =
        Corner(mesh, int(t), 0).cwiseMin(Corner(mesh, int(t), 1)).cwiseMin(Corner(mesh, int(t), 2));
    hi[t] =
        Corner(mesh, int(t), 0).cwiseMax(Corner(mesh, int(t), 1)).cwiseMax(Corner(mesh, int(t), 2));
  }
  const AabbTree tree(lo, hi);
  std::vector<int> candidates;
  for (std::size_t t = 0; t < n; ++t) {
    candidates.clear();
    tree.Overlapping(lo[t], hi[t], [&](int u) {
      if (u > static_cast<int>(t)) candidates.push_back(u);
    });
    std::sort(candidates.begin(), candidates.end());
    for (int u : candidates) {
      // Neighbours (a shared corner) meet by construction; only the others may not.
      const std::array<int, 3>& a = mesh.triangles[t];
      const std::array<int, 3>& b = mesh.triangles[std::size_t(u)];
      bool shared = false;
      for (int i : a)
        for (int j : b) shared = shared || i == j;
      if (shared || !TrianglesCross(mesh, static_cast<int>(t), u, tolerance_m)) continue;
      problems.push_back({MeshProblemKind::kSelfIntersection, u, static_cast<int>(t),
                          "this triangle crosses another one that shares no corner with it, "
                          "expected a surface that does not pass through itself"});
    }
  }
}

// Closed bodies (sets of triangles joined across edges) of negative volume, or of none. A body
// inside the bounding box of one of positive volume is taken for a cavity, which faces inwards
// rightly. Volumes are summed about a corner of the body, not the origin: a part far from the
// origin keeps its digits.
void CheckOrientation(const TriangleMesh& mesh, const MeshTopology& topo,
                      std::vector<MeshProblem>& problems) {
  const std::size_t n = mesh.triangles.size();
  std::vector<int> body(n, -1);
  struct Body {
    int first = 0;
    double volume_m3 = 0.0;
    Eigen::Vector3d lo, hi;
  };
  std::vector<Body> bodies;
  std::vector<int> stack;
  for (std::size_t start = 0; start < n; ++start) {
    if (body[start] >= 0) continue;
    Body b{static_cast<int>(start), 0.0, Corner(mesh, int(start), 0), Corner(mesh, int(start), 0)};
    const Eigen::Vector3d o = Corner(mesh, int(start), 0);
    body[start] = static_cast<int>(bodies.size());
    stack.assign(1, static_cast<int>(start));
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      const Eigen::Vector3d &p = Corner(mesh, t, 0), &q = Corner(mesh, t, 1),
                            &r = Corner(mesh, t, 2);
      b.volume_m3 += (p - o).dot((q - o).cross(r - o)) / 6.0;
      b.lo = b.lo.cwiseMin(p).cwiseMin(q).cwiseMin(r);
      b.hi = b.hi.cwiseMax(p).cwiseMax(q).cwiseMax(r);
      for (int u : topo.neighbour[std::size_t(t)])
        if (u >= 0 && body[std::size_t(u)] < 0) {
          body[std::size_t(u)] = body[start];
          stack.push_back(u);
        }
    }
    bodies.push_back(b);
  }
  for (const Body& b : bodies) {
    // No volume to speak of: a billionth of its box's diagonal cubed, far below any real part's
    // (a plate 0.1 mm thick and 100 mm square has 3.5e-4 of it).
    const double diagonal_m = (b.hi - b.lo).norm();
    if (std::abs(b.volume_m3) <= 1e-9 * diagonal_m * diagonal_m * diagonal_m) {
      std::ostringstream m;
      m.precision(6);
      m << "the closed body of this triangle encloses no volume (" << b.volume_m3 * 1e9
        << " mm^3): it is a sheet seen from both sides, expected a solid";
      problems.push_back({MeshProblemKind::kFlat, b.first, -1, m.str()});
      continue;
    }
    if (b.volume_m3 >= 0.0) continue;
    const bool cavity = std::any_of(bodies.begin(), bodies.end(), [&](const Body& outer) {
      return outer.volume_m3 > 0.0 && (outer.lo.array() < b.lo.array()).all() &&
             (outer.hi.array() > b.hi.array()).all();
    });
    if (cavity) continue;
    std::ostringstream m;
    m.precision(6);
    m << "the closed body of this triangle has a negative volume (" << b.volume_m3 * 1e9
      << " mm^3): its normals point inwards, expected corners counter-clockwise seen from "
         "outside (reverse each face's corners, or export with outward normals)";
    problems.push_back({MeshProblemKind::kInverted, b.first, -1, m.str()});
  }
}

}  // namespace

std::vector<MeshProblem> CheckMesh(const TriangleMesh& mesh) {
  std::vector<MeshProblem> problems;
  const std::size_t n = mesh.triangles.size();
  if (n > kMaxTriangles) {
    problems.push_back({MeshProblemKind::kTooManyTriangles, -1, -1,
                        "the mesh has " + std::to_string(n) + " triangles, expected at most " +
                            std::to_string(kMaxTriangles) + " (simplify the mesh in its export)"});
    return problems;
  }
  const double tolerance_m = WeldTolerance_m(mesh);
  // A triangle is degenerate when its smallest height is within the weld tolerance.
  bool degenerate = false;
  for (std::size_t t = 0; t < n; ++t) {
    const Eigen::Vector3d &a = Corner(mesh, int(t), 0), &b = Corner(mesh, int(t), 1),
                          &c = Corner(mesh, int(t), 2);
    const double longest_m = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const double height_m = longest_m > 0.0 ? (b - a).cross(c - a).norm() / longest_m : 0.0;
    if (height_m > tolerance_m) continue;
    degenerate = true;
    problems.push_back({MeshProblemKind::kDegenerate, static_cast<int>(t), -1,
                        "this triangle has (nearly) no area: its height is " +
                            Millimetres(height_m) + ", expected more than the weld tolerance (" +
                            Millimetres(tolerance_m) + ")"});
  }
  const MeshTopology topo = BuildTopology(mesh);
  bool sound = !degenerate;
  for (std::size_t e = 0; e < topo.edge_vertices.size(); ++e) {
    const std::vector<int>& tris = topo.edge_triangles[e];
    const int a = topo.edge_vertices[e][0], b = topo.edge_vertices[e][1];
    const std::string where = "the edge from " + Point(mesh.vertices_P_m[std::size_t(a)]) + " to " +
                              Point(mesh.vertices_P_m[std::size_t(b)]);
    if (tris.size() == 1) {
      problems.push_back({MeshProblemKind::kOpenEdge, tris[0], -1,
                          where + " borders this triangle only: the mesh has a hole, expected "
                                  "a closed surface (each edge shared by two triangles)"});
      sound = false;
    } else if (tris.size() > 2) {
      problems.push_back({MeshProblemKind::kNonManifoldEdge, tris[2], tris[0],
                          where + " borders " + std::to_string(tris.size()) +
                              " triangles, expected two (a surface that does not branch)"});
      sound = false;
    } else if (RunsFromTo(mesh, tris[0], a, b) == RunsFromTo(mesh, tris[1], a, b)) {
      problems.push_back({MeshProblemKind::kInconsistentWinding, tris[1], tris[0],
                          "this triangle and its neighbour run " + where +
                              " the same way, expected opposite ways (both counter-clockwise "
                              "seen from outside)"});
      sound = false;
    }
  }
  // Volume and crossings mean something only for a closed, consistently wound surface.
  if (!sound) return problems;
  CheckOrientation(mesh, topo, problems);
  CheckSelfIntersections(mesh, tolerance_m, problems);
  return problems;
}

}  // namespace tubeplan::scene
