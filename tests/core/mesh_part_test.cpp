// Mesh parts in the core, set against the shapes it knows exactly: a box written as twelve
// triangles must be felt as the box part itself, tick by tick, and a round bar written as a
// prism of 64 sides must bend the tube as the closed form says.
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/model/tube.hpp>
#include <tubeplan/scene/elements.hpp>

#include "core/part_geometry.hpp"
#include "core_scenes.hpp"
#include "mesh_parts.hpp"

using namespace tubeplan;

namespace {

constexpr double kPi = 3.14159265358979323846;

using testing::RubberScene;
using testing::SteelScene;

// A box turned 45 deg about y with its top-xpos edge along world y under the tube's path, and
// its end (ypos) face across the path: the tube meets a face, an edge and a vertex.
Eigen::Isometry3d BoxPose(double r1, double eps, double a) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(kPi / 4.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(-(r1 + 0.5 * eps) - 0.01 * std::sqrt(2.0), 0.0, a);
  return X;
}

}  // namespace

TEST_CASE("A box written as twelve triangles is felt as the box part, tick by tick", "[core]") {
  scene::Scene with_box = RubberScene();
  const double l = with_box.tube.length_m, r1 = with_box.tube.outer_radius_m;
  const double eps = with_box.contact.threshold_m;
  const Eigen::Vector3d size(0.02, 0.06, 0.02);
  const Eigen::Isometry3d X_WB = BoxPose(r1, eps, 0.6 * l);
  scene::Part box;
  box.name = "block";
  box.size_m = size;
  box.X_WP = X_WB;
  with_box.parts.push_back(box);
  scene::Scene with_mesh = with_box;
  with_mesh.parts[0] = testing::MeshPart("block", testing::BoxMesh(size), X_WB);
  core::Core box_core(with_box), mesh_core(with_mesh);
  // Pressed onto the edge, slid along it past the box's end (its vertices), then pressed
  // sideways onto the end face while rising: every kind of element in turn.
  const std::array<Eigen::Vector3d, 4> waypoints = {
      Eigen::Vector3d(-6e-3, 0.0, 0.0), Eigen::Vector3d(-6e-3, 0.045, 0.0),
      Eigen::Vector3d(-4e-3, 0.05, -0.02), Eigen::Vector3d(-8e-3, 0.02, 0.01)};
  Eigen::Vector3d from = Eigen::Vector3d::Zero();
  double t = 0.0, largest_N = 0.0;
  int compared = 0, in_contact = 0;
  std::set<std::string> formations;
  for (const Eigen::Vector3d& to : waypoints) {
    for (int i = 1; i <= 600; ++i) {
      Eigen::Isometry3d X = with_box.X_WH_start;
      X.translation() = from + std::min(1.0, i / 400.0) * (to - from);
      t += 1e-3;
      const core::StepOutput& b = box_core.Step(t, X);
      const core::StepOutput& m = mesh_core.Step(t, X);
      CAPTURE(t, box_core.FormationText(), mesh_core.FormationText());
      // The two cores sum the same contacts in another order (their edges are numbered
      // differently), and each stops its Newton solve within 1e-5 N: ten times that apart.
      REQUIRE((b.force_W_N - m.force_W_N).norm() < 1e-4);
      REQUIRE(box_core.FormationText() == mesh_core.FormationText());
      largest_N = std::max(largest_N, b.force_W_N.norm());
      in_contact += b.contact_count > 0;
      formations.insert(box_core.FormationText());
      ++compared;
    }
    from = to;
  }
  // The path is one that presses: the comparison is of contacts, not of free motion.
  CHECK(in_contact > compared / 2);
  CHECK(largest_N > 0.2);
  CHECK(formations.size() >= 3);
}

TEST_CASE("The side on a frictionless bar of 64 flat sides: 3EI/a^3 in series", "[core]") {
  // The round bar's test (core_test.cpp) with the bar written as a prism: its ridges bear on the
  // tube between the sections as the cylinder's side does.
  scene::Scene s = SteelScene();
  const double l = s.tube.length_m, r1 = s.tube.outer_radius_m, eps = s.contact.threshold_m;
  const double a = 2.0 * l / 3.0, R = 5e-3;
  Eigen::Isometry3d X_WB = Eigen::Isometry3d::Identity();
  X_WB.linear() = Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  X_WB.translation() = Eigen::Vector3d(-(r1 + 0.5 * eps + R), 0.0, a);
  s.parts.push_back(testing::MeshPart("bar", testing::PrismMesh(R, 0.1, 64), X_WB));
  core::Core c(s);
  const double EI = model::ComputeSection(s.tube).bending_stiffness_Nm2;
  const double k_side = 3.0 * EI / (a * a * a);
  const double k_series = 1.0 / (1.0 / 400.0 + 1.0 / s.contact.stiffness_N_per_m + 1.0 / k_side);
  double t = 0.0, F_prev = 0.0, x_prev = 0.0;
  for (const double x_m : {-1e-3, -2e-3, -3e-3}) {
    Eigen::Isometry3d X = s.X_WH_start;
    X.translation().x() = x_m;
    const core::StepOutput* out = &c.last();
    for (int i = 1; i <= 500; ++i) {
      Eigen::Isometry3d Y = X;
      Y.translation().x() = x_prev + std::min(1.0, i / 200.0) * (x_m - x_prev);
      out = &c.Step(t += 1e-3, Y);
    }
    INFO(c.FormationText());
    REQUIRE(out->contact_count == 1);
    const core::ContactState& pc = out->contacts[0];
    CHECK(pc.tube == states::TubeElement::kSide);
    CHECK(c.elements()[std::size_t(pc.part_element)].name == "bar.side");
    CHECK(pc.s_m == Approx(a).margin(1e-3));
    if (F_prev > 0.0) {
      const double k = (out->force_W_N.x() - F_prev) / (x_prev - x_m);
      // 1 %: as the cylinder's test; the prism's flats lie within R (1 - cos(pi/64)), 6 um, of
      // the circle, and the stiffness is a difference of forces.
      CHECK(k == Approx(k_series).epsilon(0.01));
    }
    F_prev = out->force_W_N.x();
    x_prev = x_m;
  }
}

TEST_CASE("A box mesh's geometry: the box's distances, edges, corners and thickness", "[core]") {
  const Eigen::Vector3d size(0.02, 0.06, 0.01);
  Eigen::Isometry3d X_WP = Eigen::Isometry3d::Identity();
  X_WP.linear() = scene::RotationFromRpy({0.3, -0.5, 0.9});
  X_WP.translation() = Eigen::Vector3d(0.01, 0.02, -0.03);
  scene::Part box;
  box.name = "block";
  box.size_m = size;
  box.X_WP = X_WP;
  const scene::Part mesh = testing::MeshPart("block", testing::BoxMesh(size), X_WP);
  const core::PartGeometry gb(box), gm(mesh);
  const std::vector<scene::PartElement> eb = scene::ElementsOf(box, 0),
                                        em = scene::ElementsOf(mesh, 0);
  REQUIRE(eb.size() == em.size());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-0.05, 0.05);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d p_W =
        X_WP * Eigen::Vector3d(coordinate(rng), coordinate(rng), 0.3 * coordinate(rng));
    const core::PartDistance b = gb.Distance(p_W), m = gm.Distance(p_W);
    CAPTURE(p_W.transpose(), b.distance_m);
    // Outside and inside alike (inside, the box without an entry face leaves by the nearest
    // face, as the mesh does), to rounding.
    CHECK(m.distance_m == Approx(b.distance_m).margin(1e-12));
    // The normal is the distance's gradient, the mesh's from its pseudo-normals: rounding of
    // the nearest point's coordinates (1e-17 m) over distances of 1e-8 m and more.
    CHECK((m.normal_W - b.normal_W).norm() < 1e-9);
    // Away from a tie between two elements (either is right there) and from the surface (where
    // the curvature, C / d, grows without bound): the same element, and the curvature to 1e-6
    // of its size 1/d.
    if (std::abs(b.distance_m) > 1e-6) {
      CHECK(em[m.element].name == eb[b.element].name);
      CHECK((m.curvature_per_m - b.curvature_per_m).norm() < 1e-6 / std::abs(b.distance_m));
    }
  }
  // Twelve edges and eight corners, each with the box's elements at its ends.
  REQUIRE(gm.edges().size() == 12);
  REQUIRE(gm.vertices_W().size() == 8);
  for (const core::PartEdge& e : gm.edges()) {
    bool found = false;
    for (const core::PartEdge& f : gb.edges()) {
      const bool same = (e.a_W - f.a_W).norm() < 1e-12 && (e.b_W - f.b_W).norm() < 1e-12;
      const bool swapped = (e.a_W - f.b_W).norm() < 1e-12 && (e.b_W - f.a_W).norm() < 1e-12;
      if (!same && !swapped) continue;
      found = true;
      CHECK(em[e.element].name == eb[f.element].name);
      CHECK(em[e.a_element].name == eb[same ? f.a_element : f.b_element].name);
      CHECK(e.a_bears);
      CHECK(e.b_bears);
    }
    CHECK(found);
  }
  // An edge bounds its faces, a corner its edges, and not the other way.
  const auto index = [&](const std::string& name) {
    return core::ElementIndex(scene::FindElement(em, "block." + name));
  };
  CHECK(gm.Bounds(index("top_xpos"), index("top")));
  CHECK(gm.Bounds(index("top_xpos_ypos"), index("top_xpos")));
  CHECK_FALSE(gm.Bounds(index("top"), index("top_xpos")));
  CHECK_FALSE(gm.Bounds(index("top_xpos"), index("bottom")));
  // The thinnest wall is the box's thinnest side: straight through it from a face, to rounding.
  CHECK(gm.thinnest_m() == Approx(0.01).margin(1e-9));
}

TEST_CASE("Two edges between the same two faces of a mesh bound neither each other", "[core]") {
  // A D-shaped bar: a half-round side of 20 flats (one curved face) closed by a flat, which
  // meets the side along two separate lines: two edges, each ending in its own two corners.
  const double R = 0.01, h = 0.02;
  scene::TriangleMesh mesh;
  mesh.names = {"top", "bottom", "side", "flat"};
  for (const double z : {h, -h})
    for (int k = 0; k <= 20; ++k) {
      const double phi = M_PI * (-0.5 + k / 20.0);
      mesh.vertices_P_m.emplace_back(R * std::cos(phi), R * std::sin(phi), z);
    }
  for (int k = 1; k < 20; ++k) {
    mesh.triangles.push_back({0, k, k + 1});
    mesh.triangles.push_back({21, 21 + k + 1, 21 + k});
    mesh.triangle_names.insert(mesh.triangle_names.end(), {0, 1});
  }
  for (int k = 0; k < 20; ++k) testing::AddQuad(mesh, 21 + k, 21 + k + 1, k + 1, k, 2);
  testing::AddQuad(mesh, 41, 21, 0, 20, 3);
  REQUIRE(scene::CheckMesh(mesh).empty());
  const scene::Part part = testing::MeshPart("d", mesh, Eigen::Isometry3d::Identity());
  const scene::MeshElements& el = part.mesh->elements;
  const core::PartGeometry g(part);
  const int faces = int(el.faces.size()), edges = int(el.edges.size());
  // The two side-flat edges, and the corners at y < 0 and y > 0 on the top.
  std::vector<int> lines;
  for (int e = 0; e < edges; ++e) {
    const scene::MeshEdge& edge = el.edges[std::size_t(e)];
    if (el.faces[std::size_t(edge.face_a)].name + el.faces[std::size_t(edge.face_b)].name ==
        "sideflat")
      lines.push_back(faces + e);
  }
  REQUIRE(lines.size() == 2);
  std::vector<int> corners(2, -1);
  for (int v = 0; v < int(el.vertices.size()); ++v) {
    const Eigen::Vector3d& p = el.vertices[std::size_t(v)].position_P_m;
    if (p.z() > 0.0) corners[p.y() > 0.0 ? 1 : 0] = faces + edges + v;
  }
  REQUIRE(corners[0] >= 0);
  REQUIRE(corners[1] >= 0);
  // Which line each corner ends: the line whose first segment starts or ends at its height.
  const auto line_of = [&](int corner) {
    const int mesh_vertex = el.vertices[std::size_t(corner - faces - edges)].mesh_vertex;
    for (const int l : lines)
      for (const auto& segment : el.edges[std::size_t(l - faces)].segments)
        if (segment[0] == mesh_vertex || segment[1] == mesh_vertex) return l;
    return -1;
  };
  const int l0 = line_of(corners[0]), l1 = line_of(corners[1]);
  REQUIRE(l0 >= 0);
  REQUIRE(l1 >= 0);
  REQUIRE(l0 != l1);
  const auto bounds = [&](int a, int b) {
    return g.Bounds(core::ElementIndex(a), core::ElementIndex(b));
  };
  CHECK_FALSE(bounds(lines[0], lines[1]));
  CHECK_FALSE(bounds(lines[1], lines[0]));
  CHECK(bounds(corners[0], l0));
  CHECK_FALSE(bounds(corners[0], l1));
  CHECK(bounds(corners[1], l1));
  CHECK_FALSE(bounds(corners[0], corners[1]));
  // Each line lies on both its faces; a corner on its three.
  const int side = scene::FindElement(scene::ElementsOf(part, 0), "d.side");
  const int flat = scene::FindElement(scene::ElementsOf(part, 0), "d.flat");
  CHECK(bounds(l0, side));
  CHECK(bounds(l0, flat));
  CHECK(bounds(corners[1], side));
}
