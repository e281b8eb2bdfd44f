// The mesh's distance query against a loop over every triangle with a nearest-point routine of
// its own, signed by the generalized winding number (a method independent of pseudo-normals);
// no allocation per query; and, behind "[.bench]", its speed against FCL's BVHModel.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include <catch2/catch.hpp>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include <tubeplan/io/mesh_file.hpp>
#include <tubeplan/scene/mesh_distance.hpp>
#include <tubeplan/scene/scene.hpp>

#include "../alloc_count.hpp"

namespace {

using tubeplan::scene::MeshDistance;
using tubeplan::scene::MeshFeature;
using tubeplan::scene::MeshFeatureKind;
using tubeplan::scene::MeshGeometry;

// The nearest point of a segment to p.
Eigen::Vector3d OnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b) {
  const double s = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return a + s * (b - a);
}

// The nearest point of a triangle to p: the foot on its plane when that lies inside (by the
// signs of three areas), else the nearest of its three sides.
Eigen::Vector3d OnTriangle(const Eigen::Vector3d& p, const std::array<Eigen::Vector3d, 3>& t) {
  const Eigen::Vector3d n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
  const Eigen::Vector3d foot = p - n.dot(p - t[0]) * n;
  bool inside = true;
  for (std::size_t k = 0; k < 3; ++k)
    inside = inside && n.dot((t[(k + 1) % 3] - t[k]).cross(foot - t[k])) >= 0.0;
  if (inside) return foot;
  Eigen::Vector3d best = OnSegment(p, t[0], t[1]);
  for (std::size_t k = 1; k < 3; ++k) {
    const Eigen::Vector3d q = OnSegment(p, t[k], t[(k + 1) % 3]);
    if ((p - q).squaredNorm() < (p - best).squaredNorm()) best = q;
  }
  return best;
}

// The winding number of the closed mesh around p: 1 inside, 0 outside (Jacobson et al. 2013,
// the solid angle of each triangle by Van Oosterom and Strackee's formula).
double WindingNumber(const std::vector<std::array<Eigen::Vector3d, 3>>& triangles,
                     const Eigen::Vector3d& p) {
  double sum = 0.0;
  for (const auto& t : triangles) {
    const Eigen::Vector3d a = t[0] - p, b = t[1] - p, c = t[2] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2.0 * std::atan2(a.dot(b.cross(c)),
                            la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return sum / (4.0 * std::numbers::pi);
}

struct Placed {
  tubeplan::scene::TriangleMesh mesh;
  tubeplan::scene::MeshElements elements;
  std::vector<std::array<Eigen::Vector3d, 3>> triangles_W;
  MeshGeometry geometry;
};

Placed Place(const tubeplan::scene::TriangleMesh& mesh,
             const tubeplan::scene::MeshElements& elements, const Eigen::Isometry3d& X_WP) {
  Placed placed{mesh, elements, {}, MeshGeometry(mesh, elements, X_WP)};
  for (const auto& t : mesh.triangles)
    placed.triangles_W.push_back({X_WP * mesh.vertices_P_m[std::size_t(t[0])],
                                  X_WP * mesh.vertices_P_m[std::size_t(t[1])],
                                  X_WP * mesh.vertices_P_m[std::size_t(t[2])]});
  return placed;
}

Placed Clip(const Eigen::Isometry3d& X_WP) {
  const auto loaded =
      tubeplan::io::LoadMeshFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/clip.obj", 0.001);
  INFO(loaded.diagnostics.FormatAll());
  REQUIRE(loaded.mesh);
  return Place(*loaded.mesh, *loaded.elements, X_WP);
}

// A torus of `around` x `across` quads (2 triangles each) about z: radii 30 and 10 mm.
tubeplan::scene::TriangleMesh Torus(int around, int across) {
  tubeplan::scene::TriangleMesh mesh;
  const double R = 0.030, r = 0.010;
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < across; ++j) {
      const double u = 2.0 * std::numbers::pi * i / around, v = 2.0 * std::numbers::pi * j / across;
      mesh.vertices_P_m.emplace_back((R + r * std::cos(v)) * std::cos(u),
                                     (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
  auto at = [&](int i, int j) { return (i % around) * across + (j % across); };
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < across; ++j) {
      // Counter-clockwise seen from outside: along u, then along v.
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      mesh.triangle_names.push_back(-1);
      mesh.triangle_names.push_back(-1);
    }
  return mesh;
}

}  // namespace

TEST_CASE("The mesh distance equals a loop over every triangle, signed by winding", "[mesh]") {
  // The clip turned and moved off the origin, so that nothing lines up with the axes.
  Eigen::Isometry3d X_WP = Eigen::Isometry3d::Identity();
  X_WP.linear() = tubeplan::scene::RotationFromRpy({0.3, -0.7, 1.1});
  X_WP.translation() = Eigen::Vector3d(0.05, -0.02, 0.01);
  const Placed clip = Clip(X_WP);
  const MeshGeometry& g = clip.geometry;
  // Points in the clip's bounding box grown by 5 mm: outside, inside, near every element.
  std::mt19937 random(11);
  const Eigen::Vector3d lo = g.min_W() - Eigen::Vector3d::Constant(0.005);
  const Eigen::Vector3d hi = g.max_W() + Eigen::Vector3d::Constant(0.005);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int inside = 0, on_face = 0, on_edge = 0, on_vertex = 0;
  for (int n = 0; n < 3000; ++n) {
    const Eigen::Vector3d p =
        lo + (hi - lo).cwiseProduct(Eigen::Vector3d(unit(random), unit(random), unit(random)));
    const MeshDistance d = g.Distance(p);
    // The loop: the nearest point over all triangles, the sign from the winding number.
    Eigen::Vector3d q = OnTriangle(p, clip.triangles_W[0]);
    int nearest = 0;
    for (std::size_t t = 1; t < clip.triangles_W.size(); ++t) {
      const Eigen::Vector3d c = OnTriangle(p, clip.triangles_W[t]);
      if ((p - c).squaredNorm() < (p - q).squaredNorm()) {
        q = c;
        nearest = static_cast<int>(t);
      }
    }
    const double winding = WindingNumber(clip.triangles_W, p);
    // Winding numbers are 0 or 1 up to rounding (1e-9 is many orders above it).
    REQUIRE(std::min(std::abs(winding), std::abs(winding - 1.0)) < 1e-9);
    const double expected_m = (winding > 0.5 ? -1.0 : 1.0) * (p - q).norm();
    // The same distance to rounding: both compute |p - q| for the same nearest point, by
    // different arithmetic, on distances of centimetres (1e-12 m is ~1e-10 of them).
    CHECK(d.distance_m == Approx(expected_m).margin(1e-12));
    CHECK((d.point_W - q).norm() < 1e-9);
    // The gradient points from the nearest point to p outside, away from p inside.
    CHECK((d.normal_W - (p - q) / expected_m).norm() < 1e-9);
    // The element the nearest point lies on, found by where q is.
    MeshFeature feature{MeshFeatureKind::kFace, clip.elements.triangle_face[std::size_t(nearest)]};
    for (std::size_t s = 0; s < g.edge_segments().size(); ++s) {
      const auto& seg = g.edge_segments()[s];
      if ((OnSegment(q, seg.a_W, seg.b_W) - q).norm() < 1e-9)
        feature = {MeshFeatureKind::kEdge, seg.edge};
    }
    for (std::size_t v = 0; v < g.vertices_W().size(); ++v)
      if ((g.vertices_W()[v] - q).norm() < 1e-9)
        feature = {MeshFeatureKind::kVertex, static_cast<int>(v)};
    CHECK(d.feature == feature);
    inside += expected_m < 0.0;
    on_face += feature.kind == MeshFeatureKind::kFace;
    on_edge += feature.kind == MeshFeatureKind::kEdge;
    on_vertex += feature.kind == MeshFeatureKind::kVertex;
    // Curvature across a line or a point only: the normal is a null direction of it, and its
    // trace times d is the curving directions' count: 1 along a feature edge, 2 at a corner.
    if (feature.kind == MeshFeatureKind::kFace) {
      CHECK(d.curvature_per_m.isZero());
    } else {
      CHECK((d.curvature_per_m * d.normal_W).norm() * std::abs(d.distance_m) < 1e-9);
      const double directions = d.curvature_per_m.trace() * d.distance_m;
      if (feature.kind == MeshFeatureKind::kVertex)
        CHECK(directions == Approx(2.0));
      else
        CHECK((directions == Approx(1.0) || directions == Approx(2.0)));
    }
  }
  // The points reached every kind of element, inside and out.
  CHECK(inside > 100);
  CHECK(on_face > 100);
  CHECK(on_edge > 100);
  CHECK(on_vertex > 20);
}

TEST_CASE("The curvature near a feature edge and a vertex of a box-like corner", "[mesh]") {
  const Placed clip = Clip(Eigen::Isometry3d::Identity());
  // 2 mm beyond the clip's left side (x = -10.5 mm) and its front (y = 0), halfway up: nearest
  // to the upright edge between left_outer and front, whose direction is z.
  const MeshDistance edge = clip.geometry.Distance(Eigen::Vector3d(-0.0125, -0.002, 0.011));
  REQUIRE(edge.feature.kind == MeshFeatureKind::kEdge);
  CHECK(clip.elements.edges[std::size_t(edge.feature.index)].name == "left_outer_front");
  CHECK(edge.distance_m == Approx(std::sqrt(8e-6)).epsilon(1e-12));
  // (I - n n^T - z z^T) / d with n = (-1, -1, 0) / sqrt 2: the exact figures, to rounding.
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  expected << 0.5, -0.5, 0.0, -0.5, 0.5, 0.0, 0.0, 0.0, 0.0;
  expected /= std::sqrt(8e-6);
  CHECK((edge.curvature_per_m - expected).norm() < 1e-9 * expected.norm());
  // Beyond the corner along all three: the vertex bottom_left_outer_front.
  const MeshDistance vertex = clip.geometry.Distance(Eigen::Vector3d(-0.0115, -0.002, -0.002));
  REQUIRE(vertex.feature.kind == MeshFeatureKind::kVertex);
  CHECK(clip.elements.vertices[std::size_t(vertex.feature.index)].name ==
        "bottom_left_outer_front");
  CHECK(vertex.distance_m == Approx(std::sqrt(9e-6)).epsilon(1e-12));
  const Eigen::Matrix3d v_expected =
      (Eigen::Matrix3d::Identity() - vertex.normal_W * vertex.normal_W.transpose()) /
      std::sqrt(9e-6);
  CHECK((vertex.curvature_per_m - v_expected).norm() < 1e-9 * v_expected.norm());
  CHECK((vertex.normal_W - Eigen::Vector3d(-1, -2, -2) / 3.0).norm() < 1e-12);
}

TEST_CASE("A mesh distance query allocates nothing", "[mesh]") {
  const Placed clip = Clip(Eigen::Isometry3d::Identity());
  std::vector<Eigen::Vector3d> points;
  std::mt19937 random(3);
  std::uniform_real_distribution<double> at(-0.03, 0.03);
  for (int i = 0; i < 1000; ++i) points.emplace_back(at(random), at(random), at(random));
  double sum = 0.0;
  const std::int64_t before = tubeplan::testing::g_allocations;
  for (const Eigen::Vector3d& p : points) sum += clip.geometry.Distance(p).distance_m;
  CHECK(tubeplan::testing::g_allocations - before == 0);
  CHECK(std::isfinite(sum));
}

TEST_CASE("Mesh distance: own AABB tree against FCL's BVHModel", "[.bench][mesh]") {
  // A 10,000-triangle torus (radii 30 and 10 mm); points within 5 mm of its surface (the
  // contact stage asks about the tube's sections near a part), and within 1 mm (epsilon).
  const tubeplan::scene::TriangleMesh torus = Torus(100, 50);
  REQUIRE(torus.triangles.size() == 10000);
  REQUIRE(tubeplan::scene::CheckMesh(torus).empty());
  const tubeplan::scene::MeshElements elements = tubeplan::scene::FindElements(torus);
  const MeshGeometry geometry(torus, elements, Eigen::Isometry3d::Identity());
  // FCL: the torus as a BVHModel of OBBRSS, the point as a sphere of radius 0.
  auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  std::vector<fcl::Vector3d> vertices(torus.vertices_P_m.begin(), torus.vertices_P_m.end());
  std::vector<fcl::Triangle> triangles;
  for (const auto& t : torus.triangles)
    triangles.emplace_back(std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2]));
  model->beginModel();
  model->addSubModel(vertices, triangles);
  model->endModel();
  fcl::CollisionObjectd mesh_object(model);
  fcl::CollisionObjectd point_object(std::make_shared<fcl::Sphered>(0.0));
  using Clock = std::chrono::steady_clock;
  auto median_ns = [](std::vector<double> t) {
    std::nth_element(t.begin(), t.begin() + long(t.size() / 2), t.end());
    return t[t.size() / 2];
  };
  for (const double within_m : {0.005, 0.001}) {
    std::mt19937 random(5);
    std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi),
        offset(-within_m, within_m);
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 2000; ++i) {
      const double u = angle(random), v = angle(random), r = 0.010 + offset(random);
      points.emplace_back((0.030 + r * std::cos(v)) * std::cos(u),
                          (0.030 + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
    std::vector<double> own_ns, fcl_ns, clock_ns, own_m;
    for (int round = 0; round < 5; ++round)
      for (const Eigen::Vector3d& p : points) {
        const auto t0 = Clock::now();
        const MeshDistance d = geometry.Distance(p);
        const auto t1 = Clock::now();
        const auto t2 = Clock::now();
        own_ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
        clock_ns.push_back(std::chrono::duration<double, std::nano>(t2 - t1).count());
        if (round == 0) own_m.push_back(std::abs(d.distance_m));
      }
    double worst_difference_m = 0.0;
    std::int64_t fcl_allocations = 0;
    for (int round = 0; round < 5; ++round)
      for (std::size_t i = 0; i < points.size(); ++i) {
        const auto t0 = Clock::now();
        const std::int64_t before = tubeplan::testing::g_allocations;
        point_object.setTranslation(points[i]);
        point_object.computeAABB();
        fcl::DistanceRequestd request(true);
        fcl::DistanceResultd result;
        fcl::distance(&mesh_object, &point_object, request, result);
        fcl_allocations += tubeplan::testing::g_allocations - before;
        const auto t1 = Clock::now();
        fcl_ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
        if (round == 0)
          worst_difference_m =
              std::max(worst_difference_m, std::abs(result.min_distance - own_m[i]));
      }
    std::printf(
        "mesh distance, 10,000-triangle torus, %zu points within %g mm, 5 rounds:\n"
        "  own AABB tree: median %.0f ns a query\n"
        "  FCL BVHModel<OBBRSS>, a sphere of radius 0: median %.0f ns a query, "
        "%.1f allocations a query\n"
        "  (a clock reading, within both: median %.0f ns)\n"
        "  largest |FCL - own| unsigned distance: %.3g m\n",
        points.size(), within_m * 1e3, median_ns(own_ns), median_ns(fcl_ns),
        double(fcl_allocations) / double(fcl_ns.size()), median_ns(clock_ns), worst_difference_m);
    // Both find the same nearest distance; FCL's sphere-triangle distance is exact too.
    CHECK(worst_difference_m < 1e-12);
  }
}

TEST_CASE("Mesh set-up time at the triangle limit", "[.bench][mesh]") {
  // A torus of 200,000 triangles (scene::kMaxTriangles): check, elements, the tree.
  const tubeplan::scene::TriangleMesh torus = Torus(500, 200);
  REQUIRE(torus.triangles.size() == tubeplan::scene::kMaxTriangles);
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const tubeplan::scene::TriangleMesh welded =
      tubeplan::scene::WeldVertices(torus, tubeplan::scene::WeldTolerance_m(torus));
  const auto t1 = Clock::now();
  REQUIRE(tubeplan::scene::CheckMesh(welded).empty());
  const auto t2 = Clock::now();
  const tubeplan::scene::MeshElements elements = tubeplan::scene::FindElements(welded);
  const auto t3 = Clock::now();
  const MeshGeometry geometry(welded, elements, Eigen::Isometry3d::Identity());
  const auto t4 = Clock::now();
  auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  std::printf(
      "200,000-triangle torus: weld %.0f ms, checks %.0f ms, elements %.0f ms, "
      "distance tree %.0f ms\n",
      ms(t0, t1), ms(t1, t2), ms(t2, t3), ms(t3, t4));
  CHECK(elements.faces.size() == 1);
}
