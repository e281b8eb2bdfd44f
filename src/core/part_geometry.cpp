#include "core/part_geometry.hpp"

#include <cmath>
#include <limits>

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

PartDistance PartGeometry::Distance(const Eigen::Vector3d& p_W, ElementIndex entry) const {
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
