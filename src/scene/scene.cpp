#include <utility>

#include <tubeplan/scene/scene.hpp>

namespace tubeplan::scene {

const char* ToString(TubeModel model) { return model == TubeModel::kLinear ? "linear" : "rod"; }

double ContactHoldAtMiddle_N(const Scene& scene, const Part& part) {
  return scene.contact.stiffness_N_per_m *
         (scene.contact.threshold_m + 0.5 * part.size_m.minCoeff());
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
  part_mesh->distance_P =
      MeshGeometry(part_mesh->mesh, part_mesh->elements, Eigen::Isometry3d::Identity());
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
