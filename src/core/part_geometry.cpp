#include "core/part_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include <tubeplan/scene/elements.hpp>

namespace tubeplan::core {
namespace {

// The faces of BoxFace on each axis of the box frame (x, y, z): the positive one, the negative.
constexpr std::array<std::array<scene::BoxFace, 2>, 3> kAxisFaces = {{
    {scene::BoxFace::kXPos, scene::BoxFace::kXNeg},
    {scene::BoxFace::kYPos, scene::BoxFace::kYNeg},
    {scene::BoxFace::kTop, scene::BoxFace::kBottom},
}};

std::uint8_t FaceOn(int axis, double sign) {
  return FaceBit(kAxisFaces[std::size_t(axis)][sign >= 0.0 ? 0 : 1]);
}

}  // namespace

PartGeometry::PartGeometry(const scene::Part& part)
    : shape_(part.shape),
      R_WP_(part.X_WP.linear()),
      p_WP_(part.X_WP.translation()),
      half_m_(0.5 * part.size_m) {
  if (shape_ == scene::PartShape::kMesh) {
    mesh_ = part.mesh;
    BuildMesh();
  } else {
    // Element indices are positions among the part's elements, each named by its faces' bits.
    element_of_mask_.fill(kNoElement);
    for (const scene::PartElement& e : scene::ElementsOf(part, 0)) {
      element_of_mask_[e.face_mask] = ElementIndex(mask_of_element_.size());
      mask_of_element_.push_back(e.face_mask);
    }
    if (shape_ == scene::PartShape::kCylinder)
      BuildCylinder();
    else
      BuildBox();
  }
  thinnest_m_ = scene::ThinnestSize_m(part);
  std::vector<Eigen::Vector3d> lo, hi;
  for (const PartEdge& edge : edges_) {
    lo.push_back(edge.min_W);
    hi.push_back(edge.max_W);
  }
  edge_tree_ = scene::AabbTree(lo, hi);
}

bool PartGeometry::Bounds(ElementIndex a, ElementIndex b) const {
  if (mesh_ == nullptr) return (mask_of_element_[a] & mask_of_element_[b]) == mask_of_element_[b];
  const std::vector<ElementIndex>& on = bounded_[a];
  return a == b || std::binary_search(on.begin(), on.end(), b);
}

void PartGeometry::BuildBox() {
  vertices_W_.resize(8);
  vertex_elements_.resize(8);
  std::array<std::uint8_t, 8> vertex_masks{};
  edges_.resize(12);
  min_W_.setConstant(std::numeric_limits<double>::infinity());
  max_W_ = -min_W_;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d sign(corner & 1 ? 1.0 : -1.0, corner & 2 ? 1.0 : -1.0,
                               corner & 4 ? 1.0 : -1.0);
    vertices_W_[std::size_t(corner)] = p_WP_ + R_WP_ * sign.cwiseProduct(half_m_);
    vertex_masks[std::size_t(corner)] =
        FaceOn(0, sign.x()) | FaceOn(1, sign.y()) | FaceOn(2, sign.z());
    vertex_elements_[std::size_t(corner)] = ElementOfMask(vertex_masks[std::size_t(corner)]);
    min_W_ = min_W_.cwiseMin(vertices_W_[std::size_t(corner)]);
    max_W_ = max_W_.cwiseMax(vertices_W_[std::size_t(corner)]);
  }
  // An edge joins two corners that differ in one coordinate: along axis a, at the signs of the
  // two other axes.
  int e = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int bit = 1 << axis;
    for (int corner = 0; corner < 8; ++corner) {
      if (corner & bit) continue;
      PartEdge& edge = edges_[std::size_t(e++)];
      edge.a_W = vertices_W_[std::size_t(corner)];
      edge.b_W = vertices_W_[std::size_t(corner | bit)];
      const std::uint8_t a_mask = vertex_masks[std::size_t(corner)];
      const std::uint8_t b_mask = vertex_masks[std::size_t(corner | bit)];
      edge.a_element = ElementOfMask(a_mask);
      edge.b_element = ElementOfMask(b_mask);
      edge.element = ElementOfMask(a_mask & b_mask);
      edge.min_W = edge.a_W.cwiseMin(edge.b_W);
      edge.max_W = edge.a_W.cwiseMax(edge.b_W);
      for (int k = 1; k <= 2; ++k) {
        const int other = (axis + k) % 3;
        edge.face_normals_W[std::size_t(k - 1)] =
            (corner & (1 << other) ? 1.0 : -1.0) * R_WP_.col(other);
      }
    }
  }
}

void PartGeometry::BuildCylinder() {
  const double radius_m = half_m_.x(), h = half_m_.z();
  const Eigen::Vector3d z_W = R_WP_.col(2);
  // The tight box of a turned cylinder: along world axis i its ends reach |z_i| h and its rims
  // r sqrt(1 - z_i^2) beyond.
  const Eigen::Vector3d reach =
      z_W.cwiseAbs() * h + radius_m * (1.0 - z_W.array().square()).max(0.0).sqrt().matrix();
  min_W_ = p_WP_ - reach;
  max_W_ = p_WP_ + reach;
  const auto side = FaceBit(scene::CylinderFace::kSide);
  for (const auto end : {scene::CylinderFace::kTop, scene::CylinderFace::kBottom}) {
    const double sz = end == scene::CylinderFace::kTop ? 1.0 : -1.0;
    const auto mask = static_cast<std::uint8_t>(FaceBit(end) | side);
    for (int k = 0; k < kRimSegments; ++k) {
      const auto corner_P = [&](int j) {
        const double phi = 2.0 * M_PI * double(j % kRimSegments) / kRimSegments;
        return Eigen::Vector3d(radius_m * std::cos(phi), radius_m * std::sin(phi), sz * h);
      };
      const Eigen::Vector3d a_P = corner_P(k), b_P = corner_P(k + 1);
      PartEdge edge;
      edge.a_W = p_WP_ + R_WP_ * a_P;
      edge.b_W = p_WP_ + R_WP_ * b_P;
      edge.min_W = edge.a_W.cwiseMin(edge.b_W);
      edge.max_W = edge.a_W.cwiseMax(edge.b_W);
      edge.element = edge.a_element = edge.b_element = ElementOfMask(mask);
      edge.a_bears = false;
      const Eigen::Vector3d mid_P = 0.5 * (a_P + b_P);
      edge.face_normals_W = {sz * z_W,
                             R_WP_ * Eigen::Vector3d(mid_P.x(), mid_P.y(), 0.0).normalized()};
      edges_.push_back(edge);
    }
  }
  // The round side: the axis, grown by the radius, bearing between the rims only.
  PartEdge axis;
  axis.a_W = p_WP_ - h * z_W;
  axis.b_W = p_WP_ + h * z_W;
  axis.radius_m = radius_m;
  axis.min_W = axis.a_W.cwiseMin(axis.b_W).array() - radius_m;
  axis.max_W = axis.a_W.cwiseMax(axis.b_W).array() + radius_m;
  axis.element = axis.a_element = axis.b_element = ElementOfMask(side);
  axis.a_bears = axis.b_bears = false;
  edges_.push_back(axis);
}

void PartGeometry::BuildMesh() {
  const scene::MeshElements& el = mesh_->elements;
  const int faces = int(el.faces.size()), edges = int(el.edges.size());
  if (el.faces.size() + el.edges.size() + el.vertices.size() > scene::kMaxElements)
    throw std::invalid_argument("a mesh part has more elements than scene::kMaxElements");
  // What each element lies on: by the faces an edge joins and a vertex is on, and by the chains
  // that end in a vertex (two chains between the same faces are two edges).
  bounded_.assign(std::size_t(faces + edges) + el.vertices.size(), {});
  for (int e = 0; e < edges; ++e) {
    const scene::MeshEdge& edge = el.edges[std::size_t(e)];
    std::vector<ElementIndex>& on = bounded_[std::size_t(faces + e)];
    on = {ElementIndex(edge.face_a), ElementIndex(edge.face_b)};
    for (const auto& segment : edge.segments)
      for (const int v : segment)
        if (const int feature = el.vertex_element[std::size_t(v)]; feature >= 0)
          bounded_[std::size_t(faces + edges + feature)].push_back(ElementIndex(faces + e));
  }
  for (int v = 0; v < int(el.vertices.size()); ++v) {
    std::vector<ElementIndex>& on = bounded_[std::size_t(faces + edges + v)];
    for (const int f : el.vertices[std::size_t(v)].faces) on.push_back(ElementIndex(f));
  }
  for (std::vector<ElementIndex>& on : bounded_) {
    std::sort(on.begin(), on.end());
    on.erase(std::unique(on.begin(), on.end()), on.end());
  }
  min_W_.setConstant(std::numeric_limits<double>::infinity());
  max_W_ = -min_W_;
  for (const Eigen::Vector3d& v_P : mesh_->mesh.vertices_P_m) {
    const Eigen::Vector3d v_W = p_WP_ + R_WP_ * v_P;
    min_W_ = min_W_.cwiseMin(v_W);
    max_W_ = max_W_.cwiseMax(v_W);
  }
  AddMeshEdges();
  // The corners that poke: feature vertices none of whose feature edges is concave.
  std::vector<char> concave(mesh_->mesh.vertices_P_m.size(), 0);
  for (const scene::MeshEdge& edge : el.edges)
    if (!edge.convex)
      for (const auto& segment : edge.segments)
        concave[std::size_t(segment[0])] = concave[std::size_t(segment[1])] = 1;
  for (int v = 0; v < int(el.vertices.size()); ++v) {
    const scene::MeshVertex& vertex = el.vertices[std::size_t(v)];
    if (concave[std::size_t(vertex.mesh_vertex)]) continue;
    vertices_W_.push_back(p_WP_ + R_WP_ * vertex.position_P_m);
    vertex_elements_.push_back(ElementIndex(faces + edges + v));
  }
}

void PartGeometry::AddMeshEdges() {
  const scene::TriangleMesh& mesh = mesh_->mesh;
  const scene::MeshElements& el = mesh_->elements;
  const int faces = int(el.faces.size()), edges = int(el.edges.size());
  // The triangles on either side of each mesh edge (the mesh is closed and manifold: two).
  std::map<std::pair<int, int>, std::vector<int>> sides;
  for (int t = 0; t < int(mesh.triangles.size()); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles[std::size_t(t)][std::size_t(k)];
      const int b = mesh.triangles[std::size_t(t)][std::size_t((k + 1) % 3)];
      sides[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  // A point where segments meet is borne once: at a feature vertex by every edge that ends
  // there (as a box's corner is), elsewhere by the first segment to reach it.
  std::vector<int> bearer(mesh.vertices_P_m.size(), -1);
  const auto add = [&](int va, int vb, ElementIndex element, bool ridge) {
    const std::vector<int>& ts = sides.at({std::min(va, vb), std::max(va, vb)});
    const int index = int(edges_.size());
    PartEdge edge;
    edge.a_W = p_WP_ + R_WP_ * mesh.vertices_P_m[std::size_t(va)];
    edge.b_W = p_WP_ + R_WP_ * mesh.vertices_P_m[std::size_t(vb)];
    edge.min_W = edge.a_W.cwiseMin(edge.b_W);
    edge.max_W = edge.a_W.cwiseMax(edge.b_W);
    edge.element = element;
    edge.ridge = ridge;
    for (const int v : {va, vb}) {
      const int feature = el.vertex_element[std::size_t(v)];
      const bool bears = feature >= 0 || bearer[std::size_t(v)] < 0;
      if (feature < 0 && bearer[std::size_t(v)] < 0) bearer[std::size_t(v)] = index;
      const ElementIndex at = feature >= 0 ? ElementIndex(faces + edges + feature) : element;
      (v == va ? edge.a_bears : edge.b_bears) = bears;
      (v == va ? edge.a_element : edge.b_element) = at;
    }
    edge.face_normals_W = {R_WP_ * scene::TriangleNormal(mesh, ts[0]),
                           R_WP_ * scene::TriangleNormal(mesh, ts[1])};
    edges_.push_back(edge);
  };
  for (int e = 0; e < edges; ++e) {
    const scene::MeshEdge& edge = el.edges[std::size_t(e)];
    if (!edge.convex) continue;
    for (const auto& segment : edge.segments)
      add(segment[0], segment[1], ElementIndex(faces + e), false);
  }
  // A curved face's ridges: its triangles' edges that turn convex by more than a flat face's
  // tolerance. They poke as the tessellated surface does, as part of the face.
  const double flat_cos = std::cos(scene::kPlanarAngle_deg * M_PI / 180.0);
  for (const auto& [key, ts] : sides) {
    if (ts.size() != 2) continue;
    const int t0 = ts[0], t1 = ts[1];
    const int face = el.triangle_face[std::size_t(t0)];
    if (face != el.triangle_face[std::size_t(t1)]) continue;
    const Eigen::Vector3d n0 = scene::TriangleNormal(mesh, t0);
    if (n0.dot(scene::TriangleNormal(mesh, t1)) > flat_cos) continue;
    // Convex: the far corner of the second triangle lies behind the first's plane.
    int far = 0;
    for (const int v : mesh.triangles[std::size_t(t1)])
      if (v != key.first && v != key.second) far = v;
    const Eigen::Vector3d& a = mesh.vertices_P_m[std::size_t(key.first)];
    if ((mesh.vertices_P_m[std::size_t(far)] - a).dot(n0) >= 0.0) continue;
    add(key.first, key.second, ElementIndex(face), true);
  }
}

PartDistance PartGeometry::MeshDistance(const Eigen::Vector3d& p_W) const {
  const scene::MeshDistance m = mesh_->distance_P.Distance(R_WP_.transpose() * (p_W - p_WP_));
  const scene::MeshElements& el = mesh_->elements;
  PartDistance r;
  r.distance_m = m.distance_m;
  r.normal_W = R_WP_ * m.normal_W;
  r.point_W = p_WP_ + R_WP_ * m.point_W;
  r.curvature_per_m = R_WP_ * m.curvature_per_m * R_WP_.transpose();
  const int base = m.feature.kind == scene::MeshFeatureKind::kFace ? 0
                   : m.feature.kind == scene::MeshFeatureKind::kEdge
                       ? int(el.faces.size())
                       : int(el.faces.size() + el.edges.size());
  r.element = ElementIndex(base + m.feature.index);
  return r;
}

PartDistance PartGeometry::Distance(const Eigen::Vector3d& p_W, ElementIndex entry) const {
  if (mesh_ != nullptr) return MeshDistance(p_W);
  const Eigen::Vector3d p_P = R_WP_.transpose() * (p_W - p_WP_);
  const std::uint8_t entry_mask = entry == kNoElement ? 0 : mask_of_element_[entry];
  std::uint8_t mask = 0;
  PartDistance r = shape_ == scene::PartShape::kCylinder ? CylinderDistance(p_P, entry_mask, mask)
                                                         : BoxDistance(p_P, entry_mask, mask);
  r.point_W = p_W - r.distance_m * r.normal_W;
  r.element = ElementOfMask(mask);
  return r;
}

PartDistance PartGeometry::CylinderDistance(const Eigen::Vector3d& p_P, std::uint8_t entry_mask,
                                            std::uint8_t& mask) const {
  using scene::CylinderFace;
  const double radius_m = half_m_.x(), h = half_m_.z();
  const double rho = std::hypot(p_P.x(), p_P.y());
  // The radial direction (any one on the axis) and the rims' direction there.
  const Eigen::Vector3d u_P =
      rho > 0.0 ? Eigen::Vector3d(p_P.x() / rho, p_P.y() / rho, 0.0) : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d a_P(-u_P.y(), u_P.x(), 0.0);
  const double sz = p_P.z() >= 0.0 ? 1.0 : -1.0;
  const CylinderFace end = sz > 0.0 ? CylinderFace::kTop : CylinderFace::kBottom;
  const double q_side = rho - radius_m, q_end = std::abs(p_P.z()) - h;
  PartDistance r;
  Eigen::Vector3d n_P;
  Eigen::Matrix3d c_P = Eigen::Matrix3d::Zero();
  if (q_side > 0.0 && q_end > 0.0) {
    // Beyond a rim: the distance to a circle, curving as a line's across it and with the circle
    // along it.
    r.distance_m = std::hypot(q_side, q_end);
    n_P = (q_side * u_P + q_end * sz * Eigen::Vector3d::UnitZ()) / r.distance_m;
    mask = FaceBit(end) | FaceBit(CylinderFace::kSide);
    c_P = (Eigen::Matrix3d::Identity() - n_P * n_P.transpose() - a_P * a_P.transpose()) /
              r.distance_m +
          a_P * a_P.transpose() * (q_side / (r.distance_m * rho));
  } else if (q_side > 0.0) {
    r.distance_m = q_side;
    n_P = u_P;
    mask = FaceBit(CylinderFace::kSide);
    c_P = a_P * a_P.transpose() / rho;
  } else if (q_end > 0.0) {
    r.distance_m = q_end;
    n_P = sz * Eigen::Vector3d::UnitZ();
    mask = FaceBit(end);
  } else {
    // Inside: out through the face the point came in by, if it is known, else the nearest.
    const std::array<double, 3> out = {p_P.z() - h, -p_P.z() - h, q_side};
    int face = -1;
    for (int f = 0; f < 3; ++f)
      if (entry_mask & (1u << f) && (face < 0 || out[std::size_t(f)] > out[std::size_t(face)]))
        face = f;
    if (face < 0) face = q_side > q_end ? int(CylinderFace::kSide) : int(end);
    r.distance_m = out[std::size_t(face)];
    mask = static_cast<std::uint8_t>(1u << face);
    n_P = face == int(CylinderFace::kSide)  ? u_P
          : face == int(CylinderFace::kTop) ? Eigen::Vector3d::UnitZ()
                                            : Eigen::Vector3d(-Eigen::Vector3d::UnitZ());
  }
  r.normal_W = R_WP_ * n_P;
  r.curvature_per_m = R_WP_ * c_P * R_WP_.transpose();
  return r;
}

PartDistance PartGeometry::BoxDistance(const Eigen::Vector3d& p_P, std::uint8_t entry_mask,
                                       std::uint8_t& mask) const {
  const Eigen::Vector3d q = p_P.cwiseAbs() - half_m_;
  PartDistance r;
  const Eigen::Vector3d outside = q.cwiseMax(0.0);
  const double out_m = outside.norm();
  if (out_m > 0.0) {
    // Beyond one face (a face is nearest), two (an edge) or three (a vertex).
    Eigen::Vector3d g_P = Eigen::Vector3d::Zero();
    for (int a = 0; a < 3; ++a) {
      if (q[a] <= 0.0) continue;
      const double sign = p_P[a] >= 0.0 ? 1.0 : -1.0;
      g_P[a] = sign * q[a] / out_m;
      mask |= FaceOn(a, sign);
    }
    r.distance_m = out_m;
    r.normal_W = R_WP_ * g_P;
    // Beyond an edge or a vertex the distance is to a line or a point: it curves.
    const int beyond = (q[0] > 0.0) + (q[1] > 0.0) + (q[2] > 0.0);
    if (beyond >= 2) {
      Eigen::Matrix3d c = Eigen::Matrix3d::Identity() - r.normal_W * r.normal_W.transpose();
      if (beyond == 2)
        for (int a = 0; a < 3; ++a)
          if (q[a] <= 0.0) c -= R_WP_.col(a) * R_WP_.col(a).transpose();
      r.curvature_per_m = c / out_m;
    }
    return r;
  }
  // Inside: out through the face the point came in by, if it is known, else the nearest face.
  int axis = -1;
  double sign = 1.0;
  for (int a = 0; a < 3; ++a)
    for (int s = 0; s < 2; ++s)
      if (entry_mask & FaceBit(kAxisFaces[std::size_t(a)][std::size_t(s)]) &&
          (axis < 0 || q[a] > q[axis])) {
        axis = a;
        sign = s == 0 ? 1.0 : -1.0;
      }
  if (axis < 0) {
    axis = 0;
    for (int a = 1; a < 3; ++a)
      if (q[a] > q[axis]) axis = a;
    sign = p_P[axis] >= 0.0 ? 1.0 : -1.0;
  }
  r.distance_m = sign * p_P[axis] - half_m_[axis];
  Eigen::Vector3d g_P = Eigen::Vector3d::Zero();
  g_P[axis] = sign;
  r.normal_W = R_WP_ * g_P;
  mask = FaceOn(axis, sign);
  return r;
}

}  // namespace tubeplan::core
