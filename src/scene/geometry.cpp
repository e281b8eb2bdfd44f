#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/narrowphase/collision_object.h>

#include <tubeplan/scene/geometry.hpp>

namespace tubeplan::scene {

bool BoxesOverlap(const BoxPart& a, const BoxPart& b, double tolerance_m) {
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

std::vector<std::pair<std::size_t, std::size_t>> OverlappingParts(std::span<const BoxPart> parts,
                                                                  double tolerance_m) {
  // Each part's box in FCL's tree, its index as the object's user data.
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::vector<fcl::CollisionObjectd*> registered;
  objects.reserve(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    auto box = std::make_shared<fcl::Boxd>(parts[i].size_m);
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(box, parts[i].X_WP));
    objects.back()->setUserData(reinterpret_cast<void*>(i));
    objects.back()->computeAABB();
    registered.push_back(objects.back().get());
  }
  fcl::DynamicAABBTreeCollisionManagerd manager;
  manager.registerObjects(registered);
  manager.setup();
  // The tree hands over the pairs whose bounding boxes meet; the exact test decides.
  struct Search {
    std::span<const BoxPart> parts;
    double tolerance_m;
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
  } search{parts, tolerance_m, {}};
  manager.collide(&search, [](fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
    auto& s = *static_cast<Search*>(data);
    auto i = reinterpret_cast<std::size_t>(a->getUserData());
    auto j = reinterpret_cast<std::size_t>(b->getUserData());
    if (i < j) std::swap(i, j);
    if (BoxesOverlap(s.parts[j], s.parts[i], s.tolerance_m)) s.pairs.emplace_back(i, j);
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

std::optional<double> StraightTubeOverlap(const Eigen::Isometry3d& X_WH, double radius_m,
                                          double length_m, const BoxPart& part,
                                          double tolerance_m) {
  // The box's corners in the held frame: the tube is the cylinder x^2 + y^2 <= r^2, 0 <= z <= l.
  const Eigen::Isometry3d X_HP = X_WH.inverse() * part.X_WP;
  std::array<Eigen::Vector3d, 8> corners_H;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d c_P((c & 1 ? 0.5 : -0.5) * part.size_m.x(),
                              (c & 2 ? 0.5 : -0.5) * part.size_m.y(),
                              (c & 4 ? 0.5 : -0.5) * part.size_m.z());
    corners_H[std::size_t(c)] = X_HP * c_P;
  }
  // The vertices of the box's piece between the planes z = 0 and z = l, each moved in by the
  // tolerance (a box touching an end's face, to rounding, is not in the tube): its corners
  // there and where its edges cross the planes, seen along the axis.
  const double z_low = tolerance_m, z_high = length_m - tolerance_m;
  std::vector<Point2> piece;
  for (const Eigen::Vector3d& c : corners_H)
    if (c.z() >= z_low && c.z() <= z_high) piece.emplace_back(c.x(), c.y());
  for (int a = 0; a < 8; ++a) {
    for (const int axis : {1, 2, 4}) {
      if (a & axis) continue;  // each edge once, from its corner with the bit clear
      const Eigen::Vector3d& p = corners_H[std::size_t(a)];
      const Eigen::Vector3d& q = corners_H[std::size_t(a | axis)];
      for (const double plane : {z_low, z_high}) {
        if ((p.z() - plane) * (q.z() - plane) >= 0.0) continue;
        const double t = (plane - p.z()) / (q.z() - p.z());
        const Eigen::Vector3d x = p + t * (q - p);
        piece.emplace_back(x.x(), x.y());
      }
    }
  }
  if (piece.empty()) return std::nullopt;
  const double depth_m = radius_m - DistanceFromOrigin(ConvexHull(std::move(piece)));
  if (!(depth_m > tolerance_m)) return std::nullopt;
  return depth_m;
}

}  // namespace tubeplan::scene
