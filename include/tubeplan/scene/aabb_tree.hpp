#pragma once
// A bounding-volume tree of axis-aligned boxes over a fixed set of items (a mesh's triangles):
// built once, then walked without allocation (scene/mesh_distance.hpp's point query, the
// self-intersection check's box query).

#include <vector>

#include <Eigen/Core>

namespace tubeplan::scene {

class AabbTree {
 public:
  /// The most items in a leaf: four triangles cost about what a box test does.
  static constexpr int kLeafSize = 4;
  /// The deepest walk: median splits of at most 2^31 items stay below 40 levels.
  static constexpr int kMaxDepth = 64;

  struct Node {
    Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
    int first = 0;  ///< a leaf: its first entry in items(); else: its first child (two, adjacent)
    int count = 0;  ///< items in a leaf; 0 for an inner node
  };

  AabbTree() = default;
  /// Items i with boxes [lo[i], hi[i]], split at the median of the longest axis of their centres.
  AabbTree(const std::vector<Eigen::Vector3d>& lo, const std::vector<Eigen::Vector3d>& hi);

  const std::vector<Node>& nodes() const { return nodes_; }
  /// Item indices, leaf by leaf.
  const std::vector<int>& items() const { return items_; }

  /// Calls visit(item) for every item whose box meets [lo, hi].
  template <class Visit>
  void Overlapping(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, Visit&& visit) const {
    if (nodes_.empty()) return;
    int stack[kMaxDepth];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[std::size_t(stack[--top])];
      if ((node.lo.array() > hi.array()).any() || (node.hi.array() < lo.array()).any()) continue;
      if (node.count > 0) {
        for (int i = node.first; i < node.first + node.count; ++i) visit(items_[std::size_t(i)]);
      } else {
        stack[top++] = node.first;
        stack[top++] = node.first + 1;
      }
    }
  }

 private:
  std::vector<Node> nodes_;
  std::vector<int> items_;
};

}  // namespace tubeplan::scene
