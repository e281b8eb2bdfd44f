#include <cmath>
#include <limits>

#include <tubeplan/scene/mesh_distance.hpp>

#include "scene/mesh_topology.hpp"

namespace tubeplan::scene {
namespace {

// Where on a triangle its nearest point lies: a corner k, a side k (corner k to k+1), inside.
enum class Region : std::uint8_t { kCorner, kSide, kInside };

struct Nearest {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Region region = Region::kInside;
  int k = 0;
};

// The nearest point of triangle abc to p, by its Voronoi regions (Ericson, Real-Time Collision
// Detection, 5.1.5).
Nearest NearestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, Region::kCorner, 0};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, Region::kCorner, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return {a + (d1 / (d1 - d3)) * ab, Region::kSide, 0};
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, Region::kCorner, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return {a + (d2 / (d2 - d6)) * ac, Region::kSide, 2};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return {b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b), Region::kSide, 1};
  const double denom = 1.0 / (va + vb + vc);
  return {a + ab * (vb * denom) + ac * (vc * denom), Region::kInside, 0};
}

double BoxDistanceSquared(const AabbTree::Node& node, const Eigen::Vector3d& p) {
  return (node.lo - p).cwiseMax(p - node.hi).cwiseMax(0.0).squaredNorm();
}

// The angle at corner a of triangle abc [rad].
double CornerAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d u = b - a, v = c - a;
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

}  // namespace

MeshGeometry::MeshGeometry(const TriangleMesh& mesh, const MeshElements& elements,
                           const Eigen::Isometry3d& X_WP) {
  const MeshTopology topo = BuildTopology(mesh);
  std::vector<Eigen::Vector3d> v_W(mesh.vertices_P_m.size());
  for (std::size_t v = 0; v < v_W.size(); ++v) v_W[v] = X_WP * mesh.vertices_P_m[v];
  const std::size_t n = mesh.triangles.size();
  triangles_.resize(n);
  edge_normals_W_.assign(topo.edge_vertices.size(), Eigen::Vector3d::Zero());
  vertex_normals_W_.assign(v_W.size(), Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> lo(n), hi(n);
  for (std::size_t t = 0; t < n; ++t) {
    Triangle& tri = triangles_[t];
    const std::array<int, 3>& idx = mesh.triangles[t];
    tri.a = v_W[std::size_t(idx[0])];
    tri.b = v_W[std::size_t(idx[1])];
    tri.c = v_W[std::size_t(idx[2])];
    tri.normal = (tri.b - tri.a).cross(tri.c - tri.a).normalized();
    tri.edge = topo.triangle_edge[t];
    tri.vertex = idx;
    tri.face = elements.triangle_face[t];
    lo[t] = tri.a.cwiseMin(tri.b).cwiseMin(tri.c);
    hi[t] = tri.a.cwiseMax(tri.b).cwiseMax(tri.c);
    // Pseudo-normals: a side's is the sum of its two triangles' normals, a corner's the sum of
    // its triangles' normals weighted by their angles at it.
    const std::array<const Eigen::Vector3d*, 3> corner = {&tri.a, &tri.b, &tri.c};
    for (std::size_t k = 0; k < 3; ++k) {
      edge_normals_W_[std::size_t(tri.edge[k])] += tri.normal;
      vertex_normals_W_[std::size_t(idx[k])] +=
          CornerAngle(*corner[k], *corner[(k + 1) % 3], *corner[(k + 2) % 3]) * tri.normal;
    }
  }
  for (Eigen::Vector3d& v : edge_normals_W_) v.normalize();
  for (Eigen::Vector3d& v : vertex_normals_W_) v.normalize();
  tree_ = AabbTree(lo, hi);
  min_W_ = tree_.nodes().front().lo;
  max_W_ = tree_.nodes().front().hi;
  // Features of the mesh's edges and vertices.
  edge_feature_.assign(topo.edge_vertices.size(), -1);
  for (std::size_t t = 0; t < n; ++t)
    for (std::size_t k = 0; k < 3; ++k)
      edge_feature_[std::size_t(topo.triangle_edge[t][k])] = elements.triangle_edge[t][k];
  vertex_feature_ = elements.vertex_element;
  vertex_edge_ = elements.vertex_edge;
  for (std::size_t e = 0; e < elements.edges.size(); ++e)
    for (const std::array<int, 2>& s : elements.edges[e].segments)
      edge_segments_.push_back(
          {v_W[std::size_t(s[0])], v_W[std::size_t(s[1])], static_cast<int>(e)});
  for (const MeshVertex& vertex : elements.vertices)
    feature_vertices_W_.push_back(v_W[std::size_t(vertex.mesh_vertex)]);
}

MeshDistance MeshGeometry::Distance(const Eigen::Vector3d& p_W) const {
  // The nearest triangle: nearer child first, and a box skipped when it is farther than the best
  // triangle so far, both when it is pushed and when it is popped (the best has improved since).
  const std::vector<AabbTree::Node>& nodes = tree_.nodes();
  const std::vector<int>& items = tree_.items();
  double best_sq = std::numeric_limits<double>::infinity();
  int best = 0;
  Nearest nearest;
  struct Entry {
    int node;
    double distance_sq;
  };
  Entry stack[AabbTree::kMaxDepth];
  int top = 0;
  if (!nodes.empty()) stack[top++] = {0, 0.0};
  while (top > 0) {
    const Entry entry = stack[--top];
    if (entry.distance_sq > best_sq) continue;
    const AabbTree::Node& node = nodes[std::size_t(entry.node)];
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const int t = items[std::size_t(i)];
        const Triangle& tri = triangles_[std::size_t(t)];
        const Nearest q = NearestOnTriangle(p_W, tri.a, tri.b, tri.c);
        const double d_sq = (p_W - q.point).squaredNorm();
        if (d_sq < best_sq || (d_sq == best_sq && t < best)) {
          best_sq = d_sq;
          best = t;
          nearest = q;
        }
      }
      continue;
    }
    const Entry left{node.first, BoxDistanceSquared(nodes[std::size_t(node.first)], p_W)};
    const Entry right{node.first + 1, BoxDistanceSquared(nodes[std::size_t(node.first + 1)], p_W)};
    // Pushed far first, so that the near one is walked first; ties are walked (an equally near
    // triangle of lower index wins, as in a loop over all).
    const bool left_near = left.distance_sq <= right.distance_sq;
    const Entry& far = left_near ? right : left;
    const Entry& near = left_near ? left : right;
    if (far.distance_sq <= best_sq) stack[top++] = far;
    if (near.distance_sq <= best_sq) stack[top++] = near;
  }
  const Triangle& tri = triangles_[std::size_t(best)];
  MeshDistance r;
  r.triangle = best;
  r.point_W = nearest.point;
  // The pseudo-normal of the piece the nearest point lies on, and the element it belongs to.
  Eigen::Vector3d pseudo = tri.normal;
  r.feature = {MeshFeatureKind::kFace, tri.face};
  Eigen::Vector3d edge_direction = Eigen::Vector3d::Zero();
  bool on_corner = false;
  if (nearest.region == Region::kSide) {
    const int e = tri.edge[std::size_t(nearest.k)];
    pseudo = edge_normals_W_[std::size_t(e)];
    if (edge_feature_[std::size_t(e)] >= 0) {
      r.feature = {MeshFeatureKind::kEdge, edge_feature_[std::size_t(e)]};
      const std::array<const Eigen::Vector3d*, 3> corner = {&tri.a, &tri.b, &tri.c};
      edge_direction =
          (*corner[std::size_t(nearest.k + 1) % 3] - *corner[std::size_t(nearest.k)]).normalized();
    }
  } else if (nearest.region == Region::kCorner) {
    const int v = tri.vertex[std::size_t(nearest.k)];
    pseudo = vertex_normals_W_[std::size_t(v)];
    if (vertex_feature_[std::size_t(v)] >= 0) {
      r.feature = {MeshFeatureKind::kVertex, vertex_feature_[std::size_t(v)]};
      on_corner = true;
    } else if (vertex_edge_[std::size_t(v)] >= 0) {
      r.feature = {MeshFeatureKind::kEdge, vertex_edge_[std::size_t(v)]};
      on_corner = true;
    }
  }
  const Eigen::Vector3d away = p_W - nearest.point;
  const double unsigned_m = std::sqrt(best_sq);
  const bool inside = away.dot(pseudo) < 0.0;
  r.distance_m = inside ? -unsigned_m : unsigned_m;
  r.normal_W = unsigned_m > 0.0 ? Eigen::Vector3d((inside ? -away : away) / unsigned_m) : pseudo;
  // A line's or a point's distance curves across it; a plane's does not.
  if (r.distance_m != 0.0 && r.feature.kind != MeshFeatureKind::kFace) {
    Eigen::Matrix3d c = Eigen::Matrix3d::Identity() - r.normal_W * r.normal_W.transpose();
    if (!on_corner) c -= edge_direction * edge_direction.transpose();
    r.curvature_per_m = c / r.distance_m;
  }
  return r;
}

}  // namespace tubeplan::scene
