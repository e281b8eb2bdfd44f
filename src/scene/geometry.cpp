#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>

#include <tubeplan/scene/geometry.hpp>

namespace tubeplan::scene {

bool BoxesOverlap(const Part& a, const Part& b, double tolerance_m) {
  const Eigen::Matrix3d& Ra = a.X_WP.linear();
  const Eigen::Matrix3d& Rb = b.X_WP.linear();
  const Eigen::Vector3d ha = a.size_m / 2.0;
  const Eigen::Vector3d hb = b.size_m / 2.0;
  const Eigen::Vector3d d_W = b.X_WP.translation() - a.X_WP.translation();
  // The boxes' six face normals and the nine cross products of their edges.
  std::array<Eigen::Vector3d, 15> axes;
  std::size_t count = 0;
  for (int i = 0; i < 3; ++i) {
    axes[count++] = Ra.col(i);
    axes[count++] = Rb.col(i);
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d c = Ra.col(i).cross(Rb.col(j));
      if (c.norm() > 1e-9) axes[count++] = c.normalized();  // parallel edges give no new axis
    }
  }
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3d& n = axes[k];
    const double ra = (Ra.transpose() * n).cwiseAbs().dot(ha);
    const double rb = (Rb.transpose() * n).cwiseAbs().dot(hb);
    if (std::abs(d_W.dot(n)) >= ra + rb - tolerance_m) return false;  // a separating axis
  }
  return true;
}

namespace {

// The part as FCL's shape, centred in its frame as the part is.
std::shared_ptr<fcl::CollisionGeometryd> ShapeOf(const Part& part) {
  if (part.shape == PartShape::kCylinder)
    return std::make_shared<fcl::Cylinderd>(0.5 * part.size_m.x(), part.size_m.z());
  return std::make_shared<fcl::Boxd>(part.size_m);
}

}  // namespace

bool PartsOverlap(const Part& a, const Part& b, double tolerance_m) {
  if (a.shape == PartShape::kBox && b.shape == PartShape::kBox)
    return BoxesOverlap(a, b, tolerance_m);
  // Other shapes: FCL's penetration depth (GJK and EPA) against the same tolerance.
  const fcl::CollisionObjectd oa(ShapeOf(a), a.X_WP), ob(ShapeOf(b), b.X_WP);
  fcl::CollisionRequestd request(1, true);
  fcl::CollisionResultd result;
  if (fcl::collide(&oa, &ob, request, result) == 0) return false;
  return result.getContact(0).penetration_depth > tolerance_m;
}

std::vector<std::pair<std::size_t, std::size_t>> OverlappingParts(std::span<const Part> parts,
                                                                  double tolerance_m) {
  // Each part's box in FCL's tree, its index as the object's user data.
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::vector<fcl::CollisionObjectd*> registered;
  objects.reserve(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(ShapeOf(parts[i]), parts[i].X_WP));
    objects.back()->setUserData(reinterpret_cast<void*>(i));
    objects.back()->computeAABB();
    registered.push_back(objects.back().get());
  }
  fcl::DynamicAABBTreeCollisionManagerd manager;
  manager.registerObjects(registered);
  manager.setup();
  // The tree hands over the pairs whose bounding boxes meet; the exact test decides.
  struct Search {
    std::span<const Part> parts;
    double tolerance_m;
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
  } search{parts, tolerance_m, {}};
  manager.collide(&search, [](fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
    auto& s = *static_cast<Search*>(data);
    auto i = reinterpret_cast<std::size_t>(a->getUserData());
    auto j = reinterpret_cast<std::size_t>(b->getUserData());
    if (i < j) std::swap(i, j);
    if (PartsOverlap(s.parts[j], s.parts[i], s.tolerance_m)) s.pairs.emplace_back(i, j);
    return false;  // on to the next pair
  });
  std::sort(search.pairs.begin(), search.pairs.end());
  return search.pairs;
}

namespace {

using Point2 = Eigen::Vector2d;

double Cross(const Point2& o, const Point2& a, const Point2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// The convex hull, counter-clockwise (Andrew's monotone chain); fewer than three points when
// the points are one or on one line.
std::vector<Point2> ConvexHull(std::vector<Point2> points) {
  std::sort(points.begin(), points.end(), [](const Point2& a, const Point2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  std::vector<Point2> hull(2 * points.size());
  std::size_t k = 0;
  for (const Point2& p : points) {
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], p) <= 0.0) --k;
    hull[k++] = p;
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

double DistanceToSegment(const Point2& p, const Point2& a, const Point2& b) {
  const Point2 ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// Distance from the origin to the convex polygon `hull` (counter-clockwise), 0 inside it.
double DistanceFromOrigin(const std::vector<Point2>& hull) {
  const Point2 origin = Point2::Zero();
  if (hull.size() == 1) return hull[0].norm();
  bool inside = hull.size() >= 3;
  double distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Point2& a = hull[i];
    const Point2& b = hull[(i + 1) % hull.size()];
    if (Cross(a, b, origin) < 0.0) inside = false;
    distance = std::min(distance, DistanceToSegment(origin, a, b));
  }
  return inside ? 0.0 : distance;
}

}  // namespace

namespace {

// A part as a convex polyhedron in its own frame: its corners and its edges (pairs of corners).
// A cylinder is a prism of 64 sides, within R (1 - cos(pi / 64)), 0.12 % of its radius.
struct Polyhedron {
  std::vector<Eigen::Vector3d> corners_P;
  std::vector<std::pair<std::size_t, std::size_t>> edges;
};

Polyhedron PolyhedronOf(const Part& part) {
  Polyhedron poly;
  const Eigen::Vector3d half = 0.5 * part.size_m;
  if (part.shape == PartShape::kCylinder) {
    constexpr std::size_t kSides = 64;
    for (std::size_t k = 0; k < kSides; ++k) {
      const double phi = 2.0 * M_PI * double(k) / double(kSides);
      for (const double sz : {-1.0, 1.0})
        poly.corners_P.emplace_back(half.x() * std::cos(phi), half.y() * std::sin(phi),
                                    sz * half.z());
      const std::size_t next = (k + 1) % kSides;
      poly.edges.emplace_back(2 * k, 2 * k + 1);         // along the side
      poly.edges.emplace_back(2 * k, 2 * next);          // the bottom rim
      poly.edges.emplace_back(2 * k + 1, 2 * next + 1);  // the top rim
    }
    return poly;
  }
  for (int c = 0; c < 8; ++c) {
    poly.corners_P.emplace_back((c & 1 ? 1.0 : -1.0) * half.x(), (c & 2 ? 1.0 : -1.0) * half.y(),
                                (c & 4 ? 1.0 : -1.0) * half.z());
    for (const int axis : {1, 2, 4})
      if ((c & axis) == 0) poly.edges.emplace_back(c, c | axis);  // each edge from its low corner
  }
  return poly;
}

}  // namespace

std::optional<double> StraightTubeOverlap(const Eigen::Isometry3d& X_WH, double radius_m,
                                          double length_m, const Part& part, double tolerance_m) {
  // The part's corners in the held frame: the tube is the cylinder x^2 + y^2 <= r^2, 0 <= z <= l.
  const Eigen::Isometry3d X_HP = X_WH.inverse() * part.X_WP;
  const Polyhedron poly = PolyhedronOf(part);
  std::vector<Eigen::Vector3d> corners_H;
  corners_H.reserve(poly.corners_P.size());
  for (const Eigen::Vector3d& c_P : poly.corners_P) corners_H.push_back(X_HP * c_P);
  // The vertices of the part's piece between the planes z = 0 and z = l, each moved in by the
  // tolerance (a part touching an end's face, to rounding, is not in the tube): its corners
  // there and where its edges cross the planes, seen along the axis.
  const double z_low = tolerance_m, z_high = length_m - tolerance_m;
  std::vector<Point2> piece;
  for (const Eigen::Vector3d& c : corners_H)
    if (c.z() >= z_low && c.z() <= z_high) piece.emplace_back(c.x(), c.y());
  for (const auto& [a, b] : poly.edges) {
    const Eigen::Vector3d& p = corners_H[a];
    const Eigen::Vector3d& q = corners_H[b];
    for (const double plane : {z_low, z_high}) {
      if ((p.z() - plane) * (q.z() - plane) >= 0.0) continue;
      const double t = (plane - p.z()) / (q.z() - p.z());
      const Eigen::Vector3d x = p + t * (q - p);
      piece.emplace_back(x.x(), x.y());
    }
  }
  if (piece.empty()) return std::nullopt;
  const double depth_m = radius_m - DistanceFromOrigin(ConvexHull(std::move(piece)));
  if (!(depth_m > tolerance_m)) return std::nullopt;
  return depth_m;
}

bool Contains(const Part& part, const Eigen::Vector3d& p_W, double margin_m) {
  const Eigen::Vector3d p_P = part.X_WP.inverse() * p_W;
  const Eigen::Vector3d half = 0.5 * part.size_m;
  if (part.shape == PartShape::kCylinder)
    return half.x() - p_P.head<2>().norm() > margin_m && half.z() - std::abs(p_P.z()) > margin_m;
  return (half.array() - p_P.cwiseAbs().array() > margin_m).all();
}

ElementPoint PointOnElement(const Part& part, std::uint8_t face_mask,
                            const Eigen::Vector3d& toward_W) {
  const Eigen::Vector3d half = 0.5 * part.size_m;
  Eigen::Vector3d c_P = Eigen::Vector3d::Zero(), n_P = Eigen::Vector3d::Zero();
  if (part.shape == PartShape::kCylinder) {
    // The side's radial direction that faces `toward_W` most (any one along the axis).
    Eigen::Vector3d u_P = part.X_WP.linear().transpose() * toward_W;
    u_P.z() = 0.0;
    u_P = u_P.norm() > 1e-9 ? u_P.normalized() : Eigen::Vector3d::UnitX();
    if (face_mask & (1u << int(CylinderFace::kSide))) {
      c_P += half.x() * u_P;
      n_P += u_P;
    }
    for (const auto& [face, sz] :
         {std::pair{CylinderFace::kTop, 1.0}, std::pair{CylinderFace::kBottom, -1.0}})
      if (face_mask & (1u << int(face))) {
        c_P.z() += sz * half.z();
        n_P.z() += sz;
      }
  } else {
    // Outward normals of BoxFace order: top, bottom, +x, -x, +y, -y.
    for (int face = 0; face < 6; ++face) {
      if ((face_mask & (1u << face)) == 0) continue;
      Eigen::Vector3d nf = Eigen::Vector3d::Zero();
      nf[face / 2 == 0 ? 2 : face / 2 - 1] = face % 2 == 0 ? 1.0 : -1.0;
      n_P += nf;
      c_P += half.cwiseProduct(nf);
    }
  }
  return {part.X_WP * c_P, (part.X_WP.linear() * n_P).normalized()};
}

}  // namespace tubeplan::scene
