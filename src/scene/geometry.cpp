#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>

#include <tubeplan/scene/elements.hpp>
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

// The part as FCL's shape, centred in its frame as the part is (a mesh: its bounding box).
std::shared_ptr<fcl::CollisionGeometryd> ShapeOf(const Part& part) {
  if (part.shape == PartShape::kCylinder)
    return std::make_shared<fcl::Cylinderd>(0.5 * part.size_m.x(), part.size_m.z());
  return std::make_shared<fcl::Boxd>(part.size_m);
}

// Where ShapeOf's shape sits in the world: a mesh's bounding box need not be centred on P.
Eigen::Isometry3d ShapePose(const Part& part) {
  if (part.shape != PartShape::kMesh) return part.X_WP;
  return part.X_WP * Eigen::Translation3d(BoundsInPart(part).center());
}

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

// --- Mesh parts against any part ------------------------------------------------------------
//
// Why own tests and not FCL: FCL's mesh collision reports triangle pairs that meet, with depths
// from their own intersection, so a mesh resting on a box (coplanar faces) comes out touching or
// overlapping by rounding, and a part wholly inside a mesh meets no triangle at all. Here the
// question is asked of the exact signed distances instead (MeshGeometry for a mesh, closed forms
// for a box and a cylinder): do the vertices, the edges or an inner point of one part reach
// deeper than the tolerance into the other? Two solids share a volume exactly when one's edge
// crosses the other's face, or one holds the other (or they coincide: the inner points), and a
// part on a face only touches it: its vertices and edges lie at distance 0, never deeper.

// Signed distance from p_P (in the part's frame) to the part [m], negative inside. Exact.
double SignedDistanceInPart(const Part& part, const Eigen::Vector3d& p_P) {
  if (part.shape == PartShape::kMesh) return part.mesh->distance_P.Distance(p_P).distance_m;
  const Eigen::Vector3d half = 0.5 * part.size_m;
  if (part.shape == PartShape::kCylinder) {
    const Eigen::Vector2d q(p_P.head<2>().norm() - half.x(), std::abs(p_P.z()) - half.z());
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
  }
  const Eigen::Vector3d q = p_P.cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

// A part's vertices, edges and one point inside it, in its own frame: a box's and a cylinder's
// PolyhedronOf and centre; a mesh's vertices and every triangle side, and a point just behind its
// largest triangle (twice the tolerance in: coinciding parts share it, touching parts do not).
struct Features {
  std::vector<Eigen::Vector3d> points_P;
  std::vector<std::pair<std::size_t, std::size_t>> edges;
  Eigen::Vector3d inner_P = Eigen::Vector3d::Zero();
};

Features FeaturesOf(const Part& part, double tolerance_m) {
  Features f;
  if (part.shape != PartShape::kMesh) {
    Polyhedron poly = PolyhedronOf(part);
    f.points_P = std::move(poly.corners_P);
    f.edges = std::move(poly.edges);
    return f;
  }
  const TriangleMesh& mesh = part.mesh->mesh;
  f.points_P = mesh.vertices_P_m;
  double largest = -1.0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int u = tri[std::size_t(k)], v = tri[std::size_t((k + 1) % 3)];
      if (u < v) f.edges.emplace_back(std::size_t(u), std::size_t(v));  // each side once
    }
    const Eigen::Vector3d &p = mesh.vertices_P_m[std::size_t(tri[0])],
                          &q = mesh.vertices_P_m[std::size_t(tri[1])],
                          &r = mesh.vertices_P_m[std::size_t(tri[2])];
    const double area = (q - p).cross(r - p).norm();
    if (area <= largest) continue;
    largest = area;
    f.inner_P = (p + q + r) / 3.0 - 2.0 * tolerance_m * TriangleNormal(mesh, int(t));
  }
  return f;
}

// The deepest the segment ab (in the target's frame) reaches into the target [m] (negative: how
// far it stays outside). The signed distance changes by at most the distance moved, so a segment
// whose ends are far enough out cannot reach in; otherwise a golden-section search for the
// deepest point, exact for a convex target (the depth is then concave along the segment). A
// mesh may be concave: the search runs on pieces no longer than a sixteenth of its thinnest
// box extent (64 pieces at most), so walls farther apart than a piece are each seen; two walls
// within one piece can hide the one the search does not converge to.
double SegmentDepth(const Part& target, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    double tolerance_m) {
  const auto depth = [&](double t) { return -SignedDistanceInPart(target, a + t * (b - a)); };
  const double length = (b - a).norm(), da = depth(0.0), db = depth(1.0);
  double best = std::max(da, db);
  if (best > tolerance_m || (length + da + db) / 2.0 <= tolerance_m) return best;
  int pieces = 1;
  if (target.shape == PartShape::kMesh) {
    const double piece = target.size_m.minCoeff() / 16.0;
    pieces = int(std::clamp(std::ceil(length / std::max(piece, 1e-12)), 1.0, 64.0));
  }
  constexpr double kGolden = 0.6180339887498949;
  double d_lo = da;
  for (int i = 0; i < pieces && best <= tolerance_m; ++i) {
    double lo = double(i) / pieces, hi = double(i + 1) / pieces;
    // A piece whose ends are far enough out is passed over, as the whole segment above.
    const double d_hi = i + 1 == pieces ? db : depth(hi);
    best = std::max(best, d_hi);
    const bool reaches = (length * (hi - lo) + d_lo + d_hi) / 2.0 > tolerance_m;
    d_lo = d_hi;
    if (!reaches) continue;
    double x1 = hi - kGolden * (hi - lo), x2 = lo + kGolden * (hi - lo);
    double f1 = depth(x1), f2 = depth(x2);
    // 60 steps shrink the piece by 0.618^60 = 3e-13: the deepest point to 3e-13 of its length.
    for (int step = 0; step < 60; ++step) {
      if (f1 < f2) {
        lo = x1, x1 = x2, f1 = f2, x2 = lo + kGolden * (hi - lo), f2 = depth(x2);
      } else {
        hi = x2, x2 = x1, f2 = f1, x1 = hi - kGolden * (hi - lo), f1 = depth(x1);
      }
    }
    best = std::max({best, f1, f2});
  }
  return best;
}

// Whether a vertex, an edge or the inner point of `a` reaches deeper than the tolerance into `b`.
bool FeatureReaches(const Part& a, const Part& b, double tolerance_m) {
  const Features f = FeaturesOf(a, tolerance_m);
  const Eigen::Isometry3d X_BA = b.X_WP.inverse() * a.X_WP;
  std::vector<Eigen::Vector3d> points_B;
  points_B.reserve(f.points_P.size());
  // Only what lies in b's bounding box can reach into b deeper than the tolerance.
  Eigen::AlignedBox3d box_B = BoundsInPart(b);
  for (const Eigen::Vector3d& p : f.points_P) {
    points_B.push_back(X_BA * p);
    if (box_B.contains(points_B.back()) && SignedDistanceInPart(b, points_B.back()) < -tolerance_m)
      return true;
  }
  if (SignedDistanceInPart(b, X_BA * f.inner_P) < -tolerance_m) return true;
  for (const auto& [i, j] : f.edges) {
    Eigen::AlignedBox3d edge_box(points_B[i].cwiseMin(points_B[j]),
                                 points_B[i].cwiseMax(points_B[j]));
    if (!edge_box.intersects(box_B)) continue;
    if (SegmentDepth(b, points_B[i], points_B[j], tolerance_m) > tolerance_m) return true;
  }
  return false;
}

}  // namespace

bool PartsOverlap(const Part& a, const Part& b, double tolerance_m) {
  if (a.shape == PartShape::kBox && b.shape == PartShape::kBox)
    return BoxesOverlap(a, b, tolerance_m);
  if (a.shape == PartShape::kMesh || b.shape == PartShape::kMesh)
    return FeatureReaches(a, b, tolerance_m) || FeatureReaches(b, a, tolerance_m);
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
    objects.push_back(
        std::make_unique<fcl::CollisionObjectd>(ShapeOf(parts[i]), ShapePose(parts[i])));
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

// The polygon triangle abc (in the held frame) cuts from the slab z_low <= z <= z_high, seen
// along z: its corners there and where its sides cross the planes.
std::vector<Point2> SlabPiece(const std::array<Eigen::Vector3d, 3>& tri, double z_low,
                              double z_high) {
  std::vector<Point2> piece;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d& p = tri[std::size_t(k)];
    const Eigen::Vector3d& q = tri[std::size_t((k + 1) % 3)];
    if (p.z() >= z_low && p.z() <= z_high) piece.emplace_back(p.x(), p.y());
    for (const double plane : {z_low, z_high}) {
      if ((p.z() - plane) * (q.z() - plane) >= 0.0) continue;
      const Eigen::Vector3d x = p + (plane - p.z()) / (q.z() - p.z()) * (q - p);
      piece.emplace_back(x.x(), x.y());
    }
  }
  return piece;
}

// A mesh's distance from the tube's axis within the slab: a mesh need not be convex, so its
// piece's hull would close a clip around the tube. The nearest point of the mesh's piece lies
// on a triangle's piece (each convex, so its hull is exact), or on the axis itself when the axis
// runs inside the mesh without crossing a triangle (entering by one end plane, leaving by the
// other).
double MeshDistanceFromAxis(const Eigen::Isometry3d& X_HP, const Part& part, double z_low,
                            double z_high) {
  const TriangleMesh& mesh = part.mesh->mesh;
  const Eigen::Vector3d axis_P = X_HP.inverse() * Eigen::Vector3d(0.0, 0.0, 0.5 * (z_low + z_high));
  if (part.mesh->distance_P.Distance(axis_P).distance_m < 0.0) return 0.0;
  double distance = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles) {
    const std::array<Eigen::Vector3d, 3> tri_H = {X_HP * mesh.vertices_P_m[std::size_t(t[0])],
                                                  X_HP * mesh.vertices_P_m[std::size_t(t[1])],
                                                  X_HP * mesh.vertices_P_m[std::size_t(t[2])]};
    std::vector<Point2> piece = SlabPiece(tri_H, z_low, z_high);
    if (!piece.empty())
      distance = std::min(distance, DistanceFromOrigin(ConvexHull(std::move(piece))));
  }
  return distance;
}

}  // namespace

std::optional<double> StraightTubeOverlap(const Eigen::Isometry3d& X_WH, double radius_m,
                                          double length_m, const Part& part, double tolerance_m) {
  if (part.shape == PartShape::kMesh) {
    const double depth_m = radius_m - MeshDistanceFromAxis(X_WH.inverse() * part.X_WP, part,
                                                           tolerance_m, length_m - tolerance_m);
    if (!(depth_m > tolerance_m)) return std::nullopt;
    return depth_m;
  }
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
  if (part.shape == PartShape::kMesh)
    return part.mesh->distance_P.Distance(p_P).distance_m < -margin_m;
  const Eigen::Vector3d half = 0.5 * part.size_m;
  if (part.shape == PartShape::kCylinder)
    return half.x() - p_P.head<2>().norm() > margin_m && half.z() - std::abs(p_P.z()) > margin_m;
  return (half.array() - p_P.cwiseAbs().array() > margin_m).all();
}

namespace {

// Of the candidates (index, score, point), the one of the highest score; among those within
// 1e-9 of it (the triangles of a flat face all face one way), the one nearest `middle_P`.
struct Candidate {
  double score = 0.0;
  Eigen::Vector3d p_P = Eigen::Vector3d::Zero();
  Eigen::Vector3d n_P = Eigen::Vector3d::Zero();
};

Candidate Best(const std::vector<Candidate>& candidates, const Eigen::Vector3d& middle_P) {
  double top = -std::numeric_limits<double>::infinity();
  for (const Candidate& c : candidates) top = std::max(top, c.score);
  const Candidate* best = &candidates.front();
  double nearest = std::numeric_limits<double>::infinity();
  for (const Candidate& c : candidates) {
    if (c.score < top - 1e-9 || (c.p_P - middle_P).norm() >= nearest) continue;
    nearest = (c.p_P - middle_P).norm();
    best = &c;
  }
  return *best;
}

// The point of a mesh's face: of its triangles facing u_P most, the one nearest the face's
// middle (its area centroid), and the point of that triangle nearest the middle (a rectangle's
// middle lies on its diagonal); the triangle's normal.
Candidate MeshFacePoint(const PartMesh& m, int face, const Eigen::Vector3d& u_P) {
  const MeshFace& f = m.elements.faces[std::size_t(face)];
  Eigen::Vector3d middle_P = Eigen::Vector3d::Zero();
  double area = 0.0;
  std::vector<Candidate> candidates;
  for (int t : f.triangles) {
    const auto& tri = m.mesh.triangles[std::size_t(t)];
    const Eigen::Vector3d &a = m.mesh.vertices_P_m[std::size_t(tri[0])],
                          &b = m.mesh.vertices_P_m[std::size_t(tri[1])],
                          &c = m.mesh.vertices_P_m[std::size_t(tri[2])];
    const double at = 0.5 * (b - a).cross(c - a).norm();
    middle_P += at * (a + b + c) / 3.0;
    area += at;
    const Eigen::Vector3d n = TriangleNormal(m.mesh, t);
    candidates.push_back({n.dot(u_P), (a + b + c) / 3.0, n});
  }
  middle_P /= std::max(area, 1e-300);
  Candidate best = Best(candidates, middle_P);
  // Its triangle's point nearest the middle: the signed distance's nearest point, on the face.
  const MeshDistance near = m.distance_P.Distance(middle_P);
  if (m.elements.triangle_face[std::size_t(near.triangle)] == face &&
      TriangleNormal(m.mesh, near.triangle).dot(u_P) >= best.score - 1e-9)
    best.p_P = near.point_W;
  return best;
}

// The point of a mesh's edge: the middle of its segment facing u_P most (by the mean normal of
// the segment's two triangles), the one nearest the edge's middle among equals.
Candidate MeshEdgePoint(const PartMesh& m, int edge, const Eigen::Vector3d& u_P) {
  const MeshEdge& e = m.elements.edges[std::size_t(edge)];
  std::map<std::pair<int, int>, Eigen::Vector3d> normals;  // per segment, its triangles' sum
  for (std::size_t t = 0; t < m.mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      if (m.elements.triangle_edge[t][std::size_t(k)] != edge) continue;
      const int u = m.mesh.triangles[t][std::size_t(k)];
      const int v = m.mesh.triangles[t][std::size_t((k + 1) % 3)];
      auto [it, added] =
          normals.try_emplace({std::min(u, v), std::max(u, v)}, Eigen::Vector3d::Zero());
      it->second += TriangleNormal(m.mesh, int(t));
    }
  Eigen::Vector3d middle_P = Eigen::Vector3d::Zero();
  double length = 0.0;
  std::vector<Candidate> candidates;
  for (const auto& s : e.segments) {
    const Eigen::Vector3d &a = m.mesh.vertices_P_m[std::size_t(s[0])],
                          &b = m.mesh.vertices_P_m[std::size_t(s[1])];
    middle_P += (b - a).norm() * 0.5 * (a + b);
    length += (b - a).norm();
    const auto it = normals.find({std::min(s[0], s[1]), std::max(s[0], s[1])});
    const Eigen::Vector3d n =
        it == normals.end() ? Eigen::Vector3d::UnitZ() : it->second.normalized();
    candidates.push_back({n.dot(u_P), 0.5 * (a + b), n});
  }
  return Best(candidates, middle_P / std::max(length, 1e-300));
}

// A mesh's vertex: its position, and the mean of its faces' normals there (each face's
// triangles at the vertex).
Candidate MeshVertexPoint(const PartMesh& m, int vertex) {
  const MeshVertex& v = m.elements.vertices[std::size_t(vertex)];
  std::map<int, Eigen::Vector3d> per_face;
  for (std::size_t t = 0; t < m.mesh.triangles.size(); ++t)
    for (int corner : m.mesh.triangles[t])
      if (corner == v.mesh_vertex) {
        auto [it, added] =
            per_face.try_emplace(m.elements.triangle_face[t], Eigen::Vector3d::Zero());
        it->second += TriangleNormal(m.mesh, int(t));
      }
  Eigen::Vector3d n_P = Eigen::Vector3d::Zero();
  for (const auto& [face, sum] : per_face) n_P += sum.normalized();
  return {0.0, v.position_P_m, n_P};
}

}  // namespace

ElementPoint PointOnElement(const Part& part, int element, const Eigen::Vector3d& toward_W) {
  if (part.shape == PartShape::kMesh) {
    const PartMesh& m = *part.mesh;
    const Eigen::Vector3d u_P = part.X_WP.linear().transpose() * toward_W.normalized();
    const int faces = int(m.elements.faces.size()), edges = int(m.elements.edges.size());
    const Candidate c = element < faces           ? MeshFacePoint(m, element, u_P)
                        : element < faces + edges ? MeshEdgePoint(m, element - faces, u_P)
                                                  : MeshVertexPoint(m, element - faces - edges);
    return {part.X_WP * c.p_P, (part.X_WP.linear() * c.n_P).normalized()};
  }
  const std::uint8_t face_mask = ElementsOf(part, 0).at(std::size_t(element)).face_mask;
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
