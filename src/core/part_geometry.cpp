#include "core/part_geometry.hpp"

#include <cmath>
#include <limits>

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

BoxGeometry::BoxGeometry(const scene::BoxPart& box)
    : R_WP_(box.X_WP.linear()), p_WP_(box.X_WP.translation()), half_m_(0.5 * box.size_m) {
  min_W_.setConstant(std::numeric_limits<double>::infinity());
  max_W_ = -min_W_;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d sign(corner & 1 ? 1.0 : -1.0, corner & 2 ? 1.0 : -1.0,
                               corner & 4 ? 1.0 : -1.0);
    vertices_W_[std::size_t(corner)] = p_WP_ + R_WP_ * sign.cwiseProduct(half_m_);
    vertex_masks_[std::size_t(corner)] =
        FaceOn(0, sign.x()) | FaceOn(1, sign.y()) | FaceOn(2, sign.z());
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
      edge.a_mask = vertex_masks_[std::size_t(corner)];
      edge.b_mask = vertex_masks_[std::size_t(corner | bit)];
      edge.face_mask = edge.a_mask & edge.b_mask;
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

PartDistance BoxGeometry::Distance(const Eigen::Vector3d& p_W, std::uint8_t entry_mask) const {
  const Eigen::Vector3d p_P = R_WP_.transpose() * (p_W - p_WP_);
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
      r.face_mask |= FaceOn(a, sign);
    }
    r.distance_m = out_m;
    r.normal_W = R_WP_ * g_P;
    r.point_W = p_W - out_m * r.normal_W;
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
  r.point_W = p_W - r.distance_m * r.normal_W;
  r.face_mask = FaceOn(axis, sign);
  return r;
}

}  // namespace tubeplan::core
