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

}  // namespace tubeplan::scene
