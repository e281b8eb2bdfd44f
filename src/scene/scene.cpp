#include <tubeplan/scene/scene.hpp>

namespace tubeplan::scene {

const char* ToString(TubeModel model) { return model == TubeModel::kLinear ? "linear" : "rod"; }

double ContactHoldAtMiddle_N(const Scene& scene, const BoxPart& part) {
  return scene.contact.stiffness_N_per_m *
         (scene.contact.threshold_m + 0.5 * part.size_m.minCoeff());
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
