// A sound mesh's named elements: faces grown across gentle edges, feature edges chained between
// two faces, feature vertices where three or more faces meet (docs/meshes.md, "Elements").
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <set>

#include <tubeplan/scene/mesh.hpp>

#include "scene/mesh_topology.hpp"

namespace tubeplan::scene {
namespace {

double CosDeg(double angle_deg) { return std::cos(angle_deg * std::numbers::pi / 180.0); }

int Find(std::vector<int>& root, int i) {
  while (root[std::size_t(i)] != i)
    i = root[std::size_t(i)] = root[std::size_t(root[std::size_t(i)])];
  return i;
}

void Join(std::vector<int>& root, int a, int b) {
  a = Find(root, a);
  b = Find(root, b);
  if (a != b) root[std::size_t(std::max(a, b))] = std::min(a, b);
}

// Names made unique in order: a name met before gets "_2", "_3"... (the first keeps its own).
void MakeUnique(std::vector<std::string*> names) {
  std::set<std::string> used;
  for (std::string* name : names) {
    std::string candidate = *name;
    for (int k = 2; used.count(candidate); ++k) candidate = *name + "_" + std::to_string(k);
    *name = candidate;
    used.insert(candidate);
  }
}

// Faces: triangles joined across edges whose normals differ by less than the feature angle,
// numbered in order of their first triangle.
void FindFaces(const TriangleMesh& mesh, const MeshTopology& topo,
               const std::vector<Eigen::Vector3d>& normals, MeshElements& out) {
  const int n = static_cast<int>(mesh.triangles.size());
  std::vector<int> root(static_cast<std::size_t>(n));
  std::iota(root.begin(), root.end(), 0);
  const double cos_feature = CosDeg(kFeatureAngle_deg);
  for (int t = 0; t < n; ++t)
    for (int u : topo.neighbour[std::size_t(t)])
      if (u > t && normals[std::size_t(t)].dot(normals[std::size_t(u)]) > cos_feature)
        Join(root, t, u);
  out.triangle_face.assign(std::size_t(n), -1);
  std::vector<int> face_of_root(std::size_t(n), -1);
  for (int t = 0; t < n; ++t) {
    int& face = face_of_root[std::size_t(Find(root, t))];
    if (face < 0) {
      face = static_cast<int>(out.faces.size());
      out.faces.emplace_back();
    }
    out.triangle_face[std::size_t(t)] = face;
    out.faces[std::size_t(face)].triangles.push_back(t);
  }
  // Planar or curved, by the area-weighted mean normal.
  const double cos_planar = CosDeg(kPlanarAngle_deg);
  for (MeshFace& face : out.faces) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int t : face.triangles) {
      const std::array<int, 3>& tri = mesh.triangles[std::size_t(t)];
      const Eigen::Vector3d& a = mesh.vertices_P_m[std::size_t(tri[0])];
      sum += (mesh.vertices_P_m[std::size_t(tri[1])] - a)
                 .cross(mesh.vertices_P_m[std::size_t(tri[2])] - a);
    }
    face.normal_P = sum.norm() > 0.0 ? Eigen::Vector3d(sum.normalized()) : sum;
    face.planar = std::all_of(face.triangles.begin(), face.triangles.end(), [&](int t) {
      return normals[std::size_t(t)].dot(face.normal_P) >= cos_planar;
    });
  }
  // Names: the first triangle's group ("_1", "_2"... when the group makes several faces), or
  // f0, f1... for faces without one.
  std::map<int, int> faces_of_group, seen_of_group;
  for (const MeshFace& face : out.faces)
    ++faces_of_group[mesh.triangle_names[std::size_t(face.triangles.front())]];
  int unnamed = 0;
  std::vector<std::string*> names;
  for (MeshFace& face : out.faces) {
    const int group = mesh.triangle_names[std::size_t(face.triangles.front())];
    if (group < 0) {
      face.name = "f" + std::to_string(unnamed++);
    } else {
      face.name = mesh.names[std::size_t(group)];
      if (faces_of_group[group] > 1) face.name += "_" + std::to_string(++seen_of_group[group]);
    }
    names.push_back(&face.name);
  }
  MakeUnique(names);
}

// The segments of one chain in order along it where it is a path or a loop (as found otherwise).
std::vector<std::array<int, 2>> Ordered(std::vector<std::array<int, 2>> segments) {
  std::map<int, std::vector<std::size_t>> at;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    at[segments[s][0]].push_back(s);
    at[segments[s][1]].push_back(s);
  }
  int start = segments.front()[0];
  for (const auto& [v, list] : at)
    if (list.size() == 1) {
      start = v;
      break;
    }
  std::vector<bool> used(segments.size(), false);
  std::vector<std::array<int, 2>> path;
  for (int v = start;;) {
    std::size_t next = segments.size();
    for (std::size_t s : at[v])
      if (!used[s]) next = s;
    if (next == segments.size()) break;
    used[next] = true;
    const int w = segments[next][0] == v ? segments[next][1] : segments[next][0];
    path.push_back({v, w});
    v = w;
  }
  if (path.size() != segments.size()) return segments;
  return path;
}

// Feature edges: mesh edges between triangles that are not joined, grouped by their two faces
// and chained through shared vertices; convex or concave by the larger length.
void FindEdges(const TriangleMesh& mesh, const MeshTopology& topo,
               const std::vector<Eigen::Vector3d>& normals, MeshElements& out) {
  const double cos_feature = CosDeg(kFeatureAngle_deg);
  const std::size_t n = mesh.triangles.size();
  // Per face pair, its feature mesh edges (undirected edge ids), in edge order.
  std::map<std::pair<int, int>, std::vector<int>> by_pair;
  std::vector<double> convex_length(topo.edge_vertices.size(), 0.0);
  for (std::size_t e = 0; e < topo.edge_vertices.size(); ++e) {
    const int t = topo.edge_triangles[e][0], u = topo.edge_triangles[e][1];
    if (normals[std::size_t(t)].dot(normals[std::size_t(u)]) > cos_feature) continue;
    const int fa = out.triangle_face[std::size_t(t)], fb = out.triangle_face[std::size_t(u)];
    // A crease that fades out inside one face (its sides joined round its end) bounds nothing.
    if (fa == fb) continue;
    by_pair[{std::min(fa, fb), std::max(fa, fb)}].push_back(static_cast<int>(e));
    // Convex when the neighbour's far corner lies below this triangle's plane.
    const std::array<int, 3>& tu = mesh.triangles[std::size_t(u)];
    int far = tu[0];
    for (int v : tu)
      if (v != topo.edge_vertices[e][0] && v != topo.edge_vertices[e][1]) far = v;
    const Eigen::Vector3d& a = mesh.vertices_P_m[std::size_t(topo.edge_vertices[e][0])];
    const double length = (mesh.vertices_P_m[std::size_t(topo.edge_vertices[e][1])] - a).norm();
    convex_length[e] = normals[std::size_t(t)].dot(mesh.vertices_P_m[std::size_t(far)] - a) < 0.0
                           ? length
                           : -length;
  }
  std::vector<int> edge_element(topo.edge_vertices.size(), -1);
  std::vector<int> root(mesh.vertices_P_m.size());
  std::iota(root.begin(), root.end(), 0);
  for (const auto& [pair, edges] : by_pair) {
    // Chains: the pair's edges joined through shared vertices, in order of their first edge.
    for (int e : edges)
      Join(root, topo.edge_vertices[std::size_t(e)][0], topo.edge_vertices[std::size_t(e)][1]);
    std::map<int, std::size_t> chain_of_root;
    const std::size_t first_element = out.edges.size();
    std::vector<double> balance;
    for (int e : edges) {
      const int r = Find(root, topo.edge_vertices[std::size_t(e)][0]);
      auto [it, added] = chain_of_root.emplace(r, out.edges.size());
      if (added) {
        MeshEdge edge;
        edge.face_a = pair.first;
        edge.face_b = pair.second;
        edge.name = out.faces[std::size_t(pair.first)].name + "_" +
                    out.faces[std::size_t(pair.second)].name;
        out.edges.push_back(edge);
        balance.push_back(0.0);
      }
      out.edges[it->second].segments.push_back(topo.edge_vertices[std::size_t(e)]);
      balance[it->second - first_element] += convex_length[std::size_t(e)];
      edge_element[std::size_t(e)] = static_cast<int>(it->second);
    }
    // Undo the joins so that the next pair starts apart.
    for (int e : edges)
      for (int v : topo.edge_vertices[std::size_t(e)]) root[std::size_t(v)] = v;
    const std::size_t chains = out.edges.size() - first_element;
    for (std::size_t c = 0; c < chains; ++c) {
      MeshEdge& edge = out.edges[first_element + c];
      edge.convex = balance[c] >= 0.0;
      edge.segments = Ordered(edge.segments);
      if (chains > 1) edge.name += "_" + std::to_string(c + 1);
    }
  }
  out.triangle_edge.assign(n, {-1, -1, -1});
  for (std::size_t t = 0; t < n; ++t)
    for (std::size_t k = 0; k < 3; ++k)
      out.triangle_edge[t][k] = edge_element[std::size_t(topo.triangle_edge[t][k])];
}

// Feature vertices: mesh vertices whose triangles lie on three or more faces.
void FindVertices(const TriangleMesh& mesh, MeshElements& out) {
  const std::size_t nv = mesh.vertices_P_m.size();
  std::vector<std::vector<int>> faces_at(nv);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int v : mesh.triangles[t]) faces_at[std::size_t(v)].push_back(out.triangle_face[t]);
  std::vector<std::pair<std::vector<int>, int>> found;
  for (std::size_t v = 0; v < nv; ++v) {
    std::vector<int>& faces = faces_at[v];
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    if (faces.size() >= 3) found.emplace_back(faces, static_cast<int>(v));
  }
  // In order of their faces, as a box's vertices are.
  std::sort(found.begin(), found.end());
  out.vertex_element.assign(nv, -1);
  for (const auto& [faces, v] : found) {
    MeshVertex vertex;
    vertex.faces = faces;
    vertex.mesh_vertex = v;
    vertex.position_P_m = mesh.vertices_P_m[std::size_t(v)];
    for (int f : faces)
      vertex.name += (vertex.name.empty() ? "" : "_") + out.faces[std::size_t(f)].name;
    out.vertex_element[std::size_t(v)] = static_cast<int>(out.vertices.size());
    out.vertices.push_back(vertex);
  }
  out.vertex_edge.assign(nv, -1);
  for (std::size_t e = 0; e < out.edges.size(); ++e)
    for (const std::array<int, 2>& s : out.edges[e].segments)
      for (int v : s)
        if (out.vertex_element[std::size_t(v)] < 0 && out.vertex_edge[std::size_t(v)] < 0)
          out.vertex_edge[std::size_t(v)] = static_cast<int>(e);
}

}  // namespace

MeshElements FindElements(const TriangleMesh& mesh) {
  const MeshTopology topo = BuildTopology(mesh);
  std::vector<Eigen::Vector3d> normals(mesh.triangles.size());
  for (std::size_t t = 0; t < normals.size(); ++t)
    normals[t] = TriangleNormal(mesh, static_cast<int>(t));
  MeshElements out;
  FindFaces(mesh, topo, normals, out);
  FindEdges(mesh, topo, normals, out);
  FindVertices(mesh, out);
  // Every element's name once: a later one that repeats an earlier one gets "_2", "_3"...
  std::vector<std::string*> names;
  for (MeshFace& f : out.faces) names.push_back(&f.name);
  for (MeshEdge& e : out.edges) names.push_back(&e.name);
  for (MeshVertex& v : out.vertices) names.push_back(&v.name);
  MakeUnique(names);
  return out;
}

}  // namespace tubeplan::scene
