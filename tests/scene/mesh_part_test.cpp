// Mesh parts in the scene's checks: a 12-triangle box mesh answers Contains, PartsOverlap,
// StraightTubeOverlap and PointOnElement as the exact box code answers for the same box (an
// independent reference, on random placements), touching is not overlapping, and a concave mesh
// is measured by its own surface, not its hull.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/io/mesh_file.hpp>
#include <tubeplan/scene/elements.hpp>
#include <tubeplan/scene/geometry.hpp>

#include "../io/mesh_test_meshes.hpp"

namespace {

using tubeplan::scene::Part;

Eigen::Isometry3d Pose(const Eigen::Vector3d& position_m,
                       const Eigen::Vector3d& rpy_rad = Eigen::Vector3d::Zero()) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = tubeplan::scene::RotationFromRpy(rpy_rad);
  X.translation() = position_m;
  return X;
}

Part Box(const Eigen::Vector3d& size_m, const Eigen::Isometry3d& X_WP) {
  Part b;
  b.name = "box";
  b.size_m = size_m;
  b.X_WP = X_WP;
  return b;
}

// The same box as a mesh of 12 triangles centred on its frame (the cube's fans, scaled).
Part BoxMesh(const Eigen::Vector3d& size_m, const Eigen::Isometry3d& X_WP) {
  tubeplan::scene::TriangleMesh mesh;
  for (int i = 0; i < 8; ++i)
    mesh.vertices_P_m.push_back(
        (tubeplan::testing::CubeCorner(i) - Eigen::Vector3d::Constant(0.5)).cwiseProduct(size_m));
  for (const auto& f : tubeplan::testing::kCubeFaces)
    for (int k = 1; k <= 2; ++k)
      mesh.triangles.push_back({f[0], f[std::size_t(k)], f[std::size_t(k + 1)]});
  mesh.triangle_names.assign(mesh.triangles.size(), -1);  // no groups: faces f0, f1, ...
  REQUIRE(tubeplan::scene::CheckMesh(mesh).empty());
  tubeplan::scene::MeshElements elements = tubeplan::scene::FindElements(mesh);
  return tubeplan::scene::MakeMeshPart(
      "boxmesh", tubeplan::scene::MakePartMesh("box.obj", std::move(mesh), std::move(elements)),
      X_WP);
}

// A mesh part from OBJ text in metres.
Part ObjPart(const std::string& obj, const Eigen::Isometry3d& X_WP) {
  auto loaded = tubeplan::io::LoadMeshBytes(obj, "part.obj", 1.0);
  INFO(loaded.diagnostics.FormatAll());
  REQUIRE(loaded.mesh);
  return tubeplan::scene::MakeMeshPart(
      "part", tubeplan::scene::MakePartMesh("part.obj", *loaded.mesh, *loaded.elements), X_WP);
}

struct RandomPlacement {
  std::mt19937 random{11};
  std::uniform_real_distribution<double> at{-0.02, 0.02}, size{0.004, 0.03}, turn{-3.0, 3.0};
  Eigen::Vector3d Size() { return {size(random), size(random), size(random)}; }
  Eigen::Isometry3d Pose(bool turned) {
    return ::Pose({at(random), at(random), at(random)},
                  turned ? Eigen::Vector3d(turn(random), turn(random), turn(random))
                         : Eigen::Vector3d::Zero());
  }
};

}  // namespace

TEST_CASE("A box mesh contains the points its box contains", "[scene][mesh]") {
  RandomPlacement r;
  std::uniform_real_distribution<double> point(-0.02, 0.02);
  int inside = 0;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d size = r.Size();
    const Eigen::Isometry3d X = r.Pose(i % 2 == 1);
    const Part box = Box(size, X), mesh = BoxMesh(size, X);
    for (int j = 0; j < 20; ++j) {
      const Eigen::Vector3d p(point(r.random), point(r.random), point(r.random));
      const double margin = j % 2 == 0 ? 0.0 : 0.001;
      const bool expected = tubeplan::scene::Contains(box, p, margin);
      CHECK(tubeplan::scene::Contains(mesh, p, margin) == expected);
      inside += expected;
    }
  }
  CHECK(inside > 100);  // both answers are tried
  CHECK(inside < 3900);
}

TEST_CASE("A box mesh overlaps exactly where its box overlaps", "[scene][mesh]") {
  // The reference is the separating-axis test of the two boxes (BoxesOverlap); the mesh is
  // checked against a box part and against the other box as a mesh. Random placements meet at
  // a depth far from the tolerance of 1 nm (the loader's), where the two definitions agree.
  RandomPlacement r;
  int overlaps = 0, apart = 0;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d size_a = r.Size(), size_b = r.Size();
    const Eigen::Isometry3d X_a = r.Pose(i % 3 != 0), X_b = r.Pose(i % 2 == 0);
    const Part box_a = Box(size_a, X_a), box_b = Box(size_b, X_b);
    const Part mesh_a = BoxMesh(size_a, X_a), mesh_b = BoxMesh(size_b, X_b);
    const bool expected = tubeplan::scene::BoxesOverlap(box_a, box_b, 1e-9);
    CAPTURE(i);
    CHECK(tubeplan::scene::PartsOverlap(mesh_a, box_b, 1e-9) == expected);
    CHECK(tubeplan::scene::PartsOverlap(box_b, mesh_a, 1e-9) == expected);
    CHECK(tubeplan::scene::PartsOverlap(mesh_a, mesh_b, 1e-9) == expected);
    (expected ? overlaps : apart)++;
  }
  CHECK(overlaps > 50);
  CHECK(apart > 50);
}

TEST_CASE("A mesh resting on a box touches it and does not overlap it", "[scene][mesh]") {
  using tubeplan::scene::PartsOverlap;
  const Part floor = Box({0.06, 0.2, 0.01}, Pose({0, 0, -0.005}, {0, 0, 0}));
  const Eigen::Vector3d size(0.02, 0.03, 0.01);
  // On the floor's top: flat, turned about the vertical, and at the floor's edge (its side flush
  // with the floor's side); as a box part too, against the exact test.
  for (const Eigen::Isometry3d& X :
       {Pose({0, 0, 0.005}, {0, 0, 0}), Pose({0.003, 0.01, 0.005}, {0, 0, 0.7}),
        Pose({0.02, 0.085, 0.005}, {0, 0, 0})}) {
    CHECK_FALSE(tubeplan::scene::BoxesOverlap(Box(size, X), floor, 1e-9));
    CHECK_FALSE(PartsOverlap(BoxMesh(size, X), floor, 1e-9));
    CHECK_FALSE(PartsOverlap(floor, BoxMesh(size, X), 1e-9));
    CHECK_FALSE(PartsOverlap(BoxMesh(size, X), BoxMesh({0.06, 0.2, 0.01}, floor.X_WP), 1e-9));
    // Sunk by 1 um: an overlap, far above the tolerance.
    Eigen::Isometry3d sunk = X;
    sunk.translation().z() -= 1e-6;
    CHECK(PartsOverlap(BoxMesh(size, sunk), floor, 1e-9));
    CHECK(PartsOverlap(BoxMesh(size, sunk), BoxMesh({0.06, 0.2, 0.01}, floor.X_WP), 1e-9));
  }
  // Side by side on the floor, face to face: touching.
  CHECK_FALSE(PartsOverlap(BoxMesh(size, Pose({0, 0, 0.005}, {0, 0, 0})),
                           BoxMesh(size, Pose({0.02, 0, 0.005}, {0, 0, 0})), 1e-9));
  // The same mesh twice in one place, one inside the other, a box inside a mesh: overlaps.
  CHECK(PartsOverlap(BoxMesh(size, floor.X_WP), BoxMesh(size, floor.X_WP), 1e-9));
  CHECK(PartsOverlap(BoxMesh({0.001, 0.001, 0.001}, floor.X_WP), floor, 1e-9));
  CHECK(PartsOverlap(Box({0.001, 0.001, 0.001}, floor.X_WP), BoxMesh(size, floor.X_WP), 1e-9));
  CHECK(PartsOverlap(BoxMesh({0.06, 0.2, 0.01}, floor.X_WP), BoxMesh(size, floor.X_WP), 1e-9));
}

TEST_CASE("A mesh meets a cylinder as the cylinder's box test says", "[scene][mesh]") {
  // A post (radius 5 mm, 20 mm long, along z) on the floor's top, and beside a block: touching.
  const Part post = tubeplan::scene::MakeCylinder("post", 0.005, 0.02, Pose({0, 0, 0.01}));
  const Eigen::Vector3d size(0.01, 0.01, 0.01);
  CHECK_FALSE(tubeplan::scene::PartsOverlap(post, BoxMesh(size, Pose({0, 0, -0.005})), 1e-9));
  CHECK_FALSE(tubeplan::scene::PartsOverlap(post, BoxMesh(size, Pose({0.01, 0, 0.005})), 1e-9));
  // 0.1 mm into its side or into its end.
  CHECK(tubeplan::scene::PartsOverlap(post, BoxMesh(size, Pose({0.0099, 0, 0.005})), 1e-9));
  CHECK(tubeplan::scene::PartsOverlap(post, BoxMesh(size, Pose({0, 0, -0.0049})), 1e-9));
}

TEST_CASE("A box mesh reaches into the straight tube as deep as its box", "[scene][mesh]") {
  // The same depth by two routes: the box's convex piece, and the mesh's triangles' pieces. The
  // numbers are millimetres in metres and a few operations deep: 1e-12 m is far above their
  // rounding and far below any depth that matters.
  RandomPlacement r;
  std::uniform_real_distribution<double> turn(-3.0, 3.0);
  int reached = 0;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d size = r.Size();
    const Eigen::Isometry3d X_WP = r.Pose(i % 2 == 0);
    const Eigen::Isometry3d X_WH = Pose({r.at(r.random), r.at(r.random), r.at(r.random)},
                                        {turn(r.random), turn(r.random), turn(r.random)});
    const auto expected =
        tubeplan::scene::StraightTubeOverlap(X_WH, 0.008, 0.05, Box(size, X_WP), 1e-9);
    const auto got =
        tubeplan::scene::StraightTubeOverlap(X_WH, 0.008, 0.05, BoxMesh(size, X_WP), 1e-9);
    CAPTURE(i);
    REQUIRE(got.has_value() == expected.has_value());
    if (!expected) continue;
    CHECK(*got == Approx(*expected).margin(1e-12));
    ++reached;
  }
  CHECK(reached > 50);
  CHECK(reached < 350);
}

TEST_CASE("An L beside the straight tube is measured by its surface, not its hull",
          "[scene][mesh]") {
  // An L-shaped prism (legs 20 mm long, 2 mm thick) along z; the tube (radius 8 mm) along z in
  // its notch, 4 mm from each leg: 4 mm into it. The L's hull holds the axis (the whole radius).
  const std::vector<Eigen::Vector2d> l = {{0.0, 0.0},     {0.02, 0.0},   {0.02, 0.002},
                                          {0.002, 0.002}, {0.002, 0.02}, {0.0, 0.02}};
  const Part ell = ObjPart(tubeplan::testing::PrismObj(l, 0.1), Eigen::Isometry3d::Identity());
  using tubeplan::scene::StraightTubeOverlap;
  const auto depth = StraightTubeOverlap(Pose({0.006, 0.006, 0.01}), 0.008, 0.05, ell, 1e-9);
  REQUIRE(depth);
  CHECK(*depth == Approx(0.004).margin(1e-12));  // millimetres in metres: rounding far below
  // 9 mm from each leg: clear. Beyond the prism's end: clear. The axis inside a leg: the radius.
  CHECK_FALSE(StraightTubeOverlap(Pose({0.011, 0.011, 0.01}), 0.008, 0.05, ell, 1e-9));
  CHECK_FALSE(StraightTubeOverlap(Pose({0.006, 0.006, 0.1}), 0.008, 0.05, ell, 1e-9));
  CHECK(StraightTubeOverlap(Pose({0.001, 0.01, 0.01}), 0.008, 0.05, ell, 1e-9).value() == 0.008);
}

TEST_CASE("A box mesh's elements are aimed at as the box's are", "[scene][mesh]") {
  // Each mesh element must give a point and a normal that one of the box's 26 elements gives:
  // faces their middles (on the diagonal of the two triangles), edges their middles with the
  // mean of the two faces' normals, vertices the corners with the mean of three.
  const Eigen::Vector3d size(0.01, 0.02, 0.03);
  const Eigen::Isometry3d X = Pose({0.01, -0.02, 0.03}, {0.3, -0.5, 1.1});
  const Part box = Box(size, X), mesh = BoxMesh(size, X);
  const Eigen::Vector3d toward(0.2, 0.3, 1.0);
  const auto mesh_elements = tubeplan::scene::ElementsOf(mesh, 0);
  const auto box_elements = tubeplan::scene::ElementsOf(box, 0);
  REQUIRE(mesh_elements.size() == box_elements.size());
  for (int e = 0; e < int(mesh_elements.size()); ++e) {
    const auto got = tubeplan::scene::PointOnElement(mesh, e, toward);
    bool found = false;
    for (int b = 0; b < int(box_elements.size()); ++b) {
      if (box_elements[std::size_t(b)].kind != mesh_elements[std::size_t(e)].kind) continue;
      const auto want = tubeplan::scene::PointOnElement(box, b, toward);
      // Rounding of millimetre sizes through a turned frame: far below 1 nm and 1e-9.
      found = found || ((got.p_W - want.p_W).norm() < 1e-12 && (got.n_W - want.n_W).norm() < 1e-9);
    }
    CAPTURE(mesh_elements[std::size_t(e)].name, got.p_W.transpose(), got.n_W.transpose());
    CHECK(found);
  }
}

TEST_CASE("A round mesh face is aimed at where it faces the direction given", "[scene][mesh]") {
  // A 64-sided cylinder (radius 1 m, along z from 0 to 2): its side, seen from +x turned 0.3 rad
  // about z, is aimed at the facet whose normal is nearest that direction (within half a facet,
  // pi / 64), at a point on the surface.
  const Part cylinder = ObjPart(tubeplan::testing::CylinderObj(64), Eigen::Isometry3d::Identity());
  const auto elements = tubeplan::scene::ElementsOf(cylinder, 0);
  const Eigen::Vector3d toward(std::cos(0.3), std::sin(0.3), 0.0);
  int checked = 0;
  for (int e = 0; e < int(elements.size()); ++e) {
    const auto at = tubeplan::scene::PointOnElement(cylinder, e, toward);
    const double distance = cylinder.mesh->distance_P.Distance(at.p_W).distance_m;
    CHECK(std::abs(distance) < 1e-12);  // on the surface, to rounding
    if (elements[std::size_t(e)].kind != tubeplan::scene::ElementKind::kFace) continue;
    if (std::abs(at.n_W.z()) > 0.5) continue;  // an end
    CHECK(at.n_W.dot(toward) >= std::cos(std::numbers::pi / 64) - 1e-12);
    ++checked;
  }
  CHECK(checked == 1);
}

TEST_CASE("A mesh's thinnest size is its thinnest wall, not its box", "[scene][mesh]") {
  // A box mesh: its least side. The shipped clip: 2 mm walls and lips in a 21 x 20 x 27 mm box.
  // Sphere tracing lands on a wall square to the trace to within the stop distance (1e-9 of the
  // box's diagonal): 1e-10 m covers it.
  CHECK(tubeplan::scene::ThinnestSize_m(BoxMesh(
            {0.01, 0.02, 0.03}, Eigen::Isometry3d::Identity())) == Approx(0.01).margin(1e-10));
  const auto clip =
      tubeplan::io::LoadMeshFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/clip.obj", 0.001);
  REQUIRE(clip.mesh);
  const Part part = tubeplan::scene::MakeMeshPart(
      "clip", tubeplan::scene::MakePartMesh("clip.obj", *clip.mesh, *clip.elements),
      Eigen::Isometry3d::Identity());
  CHECK(part.size_m.minCoeff() == Approx(0.020));
  CHECK(tubeplan::scene::ThinnestSize_m(part) == Approx(0.002).margin(1e-10));
}
