#include <algorithm>
#include <cassert>
#include <numeric>

#include <tubeplan/scene/aabb_tree.hpp>

namespace tubeplan::scene {

AabbTree::AabbTree(const std::vector<Eigen::Vector3d>& lo, const std::vector<Eigen::Vector3d>& hi) {
  const int n = static_cast<int>(lo.size());
  if (n == 0) return;
  items_.resize(std::size_t(n));
  std::iota(items_.begin(), items_.end(), 0);
  nodes_.reserve(std::size_t(2 * n));
  nodes_.emplace_back();
  // Nodes to split: (node, first item, item count), depth first.
  struct Task {
    int node, first, count;
  };
  std::vector<Task> tasks{{0, 0, n}};
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();
    Eigen::Vector3d box_lo = lo[std::size_t(items_[std::size_t(task.first)])], box_hi = box_lo;
    Eigen::Vector3d c_lo = box_lo, c_hi = box_lo;
    for (int i = task.first; i < task.first + task.count; ++i) {
      const std::size_t item = std::size_t(items_[std::size_t(i)]);
      box_lo = box_lo.cwiseMin(lo[item]);
      box_hi = box_hi.cwiseMax(hi[item]);
      const Eigen::Vector3d centre = lo[item] + hi[item];
      if (i == task.first) c_lo = c_hi = centre;
      c_lo = c_lo.cwiseMin(centre);
      c_hi = c_hi.cwiseMax(centre);
    }
    nodes_[std::size_t(task.node)].lo = box_lo;
    nodes_[std::size_t(task.node)].hi = box_hi;
    if (task.count <= kLeafSize) {
      nodes_[std::size_t(task.node)].first = task.first;
      nodes_[std::size_t(task.node)].count = task.count;
      continue;
    }
    // Half the items each side of the median centre along the longest axis: depth log2(n).
    Eigen::Index axis = 0;
    (c_hi - c_lo).maxCoeff(&axis);
    const int half = task.count / 2;
    auto begin = items_.begin() + task.first;
    std::nth_element(begin, begin + half, begin + task.count, [&](int a, int b) {
      const double ca = lo[std::size_t(a)][axis] + hi[std::size_t(a)][axis];
      const double cb = lo[std::size_t(b)][axis] + hi[std::size_t(b)][axis];
      return ca < cb || (ca == cb && a < b);
    });
    const int child = static_cast<int>(nodes_.size());
    nodes_[std::size_t(task.node)].first = child;
    nodes_[std::size_t(task.node)].count = 0;
    nodes_.emplace_back();
    nodes_.emplace_back();
    tasks.push_back({child + 1, task.first + half, task.count - half});
    tasks.push_back({child, task.first, half});
  }
  assert(nodes_.size() < std::size_t(2 * n));
}

}  // namespace tubeplan::scene
