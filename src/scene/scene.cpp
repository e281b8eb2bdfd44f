#include <algorithm>
#include <stdexcept>
#include <utility>

#include <tubeplan/scene/scene.hpp>

namespace tubeplan::scene {

const char* ToString(TubeModel model) { return model == TubeModel::kLinear ? "linear" : "rod"; }

namespace {

// A mesh's thinnest wall [m]: from a triangle's centroid straight in (along its inward normal)
// to where that line leaves the solid, found by sphere tracing (each step is the distance to the
// nearest surface, so it never steps over one), the least over the triangles. At most 4096
// triangles, evenly spread, are traced (a wall is many triangles of a fine mesh): about 20
// distance queries each: 1.4 ms for the clip (174 triangles), 0.25 s for a 200,000-triangle torus.
double ThinnestWall_m(const PartMesh& m) {
  constexpr std::size_t kMaxTraced = 4096;
  constexpr int kMaxSteps = 64;  // the step at least doubles until the far wall is near
  const std::size_t n = m.mesh.triangles.size();
  const std::size_t stride = (n + kMaxTraced - 1) / kMaxTraced;
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : m.mesh.vertices_P_m) box.extend(v);
  // Where the trace starts past its own face, and how close to the far one counts as there.
  const double start_m = 1e-6 * box.diagonal().norm(), reached_m = 1e-9 * box.diagonal().norm();
  double thinnest_m = box.sizes().minCoeff();
  for (std::size_t t = 0; t < n; t += stride) {
    const auto& tri = m.mesh.triangles[t];
    const Eigen::Vector3d c =
        (m.mesh.vertices_P_m[std::size_t(tri[0])] + m.mesh.vertices_P_m[std::size_t(tri[1])] +
         m.mesh.vertices_P_m[std::size_t(tri[2])]) /
        3.0;
    const Eigen::Vector3d in = -TriangleNormal(m.mesh, int(t));
    double s = start_m;
    for (int step = 0; step < kMaxSteps && s < thinnest_m; ++step) {
      const double d = m.distance_P.Distance(c + s * in).distance_m;
      if (d >= -reached_m) break;
      s -= d;
    }
    thinnest_m = std::min(thinnest_m, s);
  }
  return thinnest_m;
}

}  // namespace

double ThinnestSize_m(const Part& part) {
  if (part.shape == PartShape::kMesh && part.mesh) return part.mesh->thinnest_m;
  return part.size_m.minCoeff();
}

double ContactHoldAtMiddle_N(const Scene& scene, const Part& part) {
  return scene.contact.stiffness_N_per_m * (scene.contact.threshold_m + 0.5 * ThinnestSize_m(part));
}

std::span<const char* const> FaceIds(PartShape shape) {
  if (shape == PartShape::kCylinder) return kCylinderFaceIds;
  return kBoxFaceIds;
}

Part MakeCylinder(std::string name, double radius_m, double length_m,
                  const Eigen::Isometry3d& X_WP) {
  Part part;
  part.name = std::move(name);
  part.shape = PartShape::kCylinder;
  part.size_m = Eigen::Vector3d(2.0 * radius_m, 2.0 * radius_m, length_m);
  part.X_WP = X_WP;
  for (std::size_t f = 0; f < kCylinderFaceIds.size(); ++f)
    part.face_names[f] = kCylinderFaceIds[f];
  return part;
}

Eigen::AlignedBox3d BoundsInPart(const Part& part) {
  if (part.shape == PartShape::kMesh && part.mesh) {
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3d& v : part.mesh->mesh.vertices_P_m) box.extend(v);
    return box;
  }
  return {-0.5 * part.size_m, 0.5 * part.size_m};
}

std::shared_ptr<const PartMesh> MakePartMesh(std::string file, TriangleMesh mesh,
                                             MeshElements elements) {
  auto part_mesh = std::make_shared<PartMesh>();
  part_mesh->file = std::move(file);
  part_mesh->mesh = std::move(mesh);
  part_mesh->elements = std::move(elements);
  const MeshElements& e = part_mesh->elements;
  if (e.faces.size() + e.edges.size() + e.vertices.size() > kMaxElements)
    throw std::invalid_argument("a mesh has more faces, edges and vertices than kMaxElements");
  part_mesh->distance_P =
      MeshGeometry(part_mesh->mesh, part_mesh->elements, Eigen::Isometry3d::Identity());
  part_mesh->thinnest_m = ThinnestWall_m(*part_mesh);
  return part_mesh;
}

Part MakeMeshPart(std::string name, std::shared_ptr<const PartMesh> mesh,
                  const Eigen::Isometry3d& X_WP) {
  Part part;
  part.name = std::move(name);
  part.shape = PartShape::kMesh;
  part.mesh = std::move(mesh);
  part.size_m = BoundsInPart(part).sizes();
  part.X_WP = X_WP;
  return part;
}

const Friction& FrictionAt(const Scene& scene, std::size_t part_index) {
  const auto& own = scene.parts.at(part_index).friction;
  return own ? *own : scene.friction;
}

Eigen::Matrix3d RotationFromRpy(const Eigen::Vector3d& rpy_rad) {
  return (Eigen::AngleAxisd(rpy_rad.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy_rad.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy_rad.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace tubeplan::scene
