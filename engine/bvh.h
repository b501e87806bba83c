// Bounding volume hierarchy: axis-aligned boxes over indexed primitives, built top-down by median
// splits. One build and one traversal, used by the detector (triangles, vertices and edges of a
// shape, body frame), the broad phase (body boxes, world) and the polyhedron's convexity check.
//
// Design note. The tree is stored flat: nodes[0] is the root, the two children of a node are
// adjacent (child, child + 1), and every node owns the contiguous range order[begin, end) of
// primitive indices. Queries are exact whatever the tree shape: a node is only ever skipped on a
// bound the caller proves, so the tree decides the cost of a query, never its answer.
#pragma once

#include <utility>
#include <vector>

#include "engine/math.h"

namespace rbx {

/// One node of a Bvh.
struct BvhNode {
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();  // m, corners of the primitives' bounding box
  Vec3 center = Vec3::Zero();                   // m, 0.5 (min + max)
  Vec3 half = Vec3::Zero();                     // m, 0.5 (max - min)
  int child = -1;                               // first child (second: child + 1); -1 for a leaf
  int begin = 0, end = 0;                       // the primitives order[begin, end)
};

/// A bounding volume hierarchy over primitives given by their bounding boxes.
struct Bvh {
  std::vector<BvhNode> nodes;  // nodes[0] is the root (empty tree: no nodes)
  std::vector<int> order;      // primitive indices grouped by leaf

  /// Builds over the boxes [lo[i], hi[i]]: each node is split at the median of its primitives'
  /// box centres along the longest axis of those centres (ties by index, so the build is
  /// deterministic), until at most `leaf_size` primitives remain.
  static Bvh build(const std::vector<Vec3>& lo, const std::vector<Vec3>& hi, int leaf_size);

  /// Depth-first branch and bound. `key(k)` scores node k; a node is skipped when `skip(key)`
  /// holds, tested when the node is reached (so against the caller's latest best); the
  /// primitives of a reached leaf go to `visit(i)` in tree order, which returns true to end the
  /// whole search. Of two children the one with the larger `key` is searched first when
  /// `larger_first`, the smaller otherwise (ties: the first child). Returns true when a visit
  /// ended the search.
  template <typename Key, typename Skip, typename Visit>
  bool search(Key key, Skip skip, Visit visit, bool larger_first = true) const;
  /// The same search, with `visit(slot)` given the position of the primitive in `order` (so
  /// that data stored in leaf order can be read in place).
  template <typename Key, typename Skip, typename Visit>
  bool search_slots(Key key, Skip skip, Visit visit, bool larger_first = true) const;
};

template <typename Key, typename Skip, typename Visit>
bool Bvh::search(Key key, Skip skip, Visit visit, bool larger_first) const {
  return search_slots(
      key, skip, [&](int slot) { return visit(order[slot]); }, larger_first);
}

template <typename Key, typename Skip, typename Visit>
bool Bvh::search_slots(Key key, Skip skip, Visit visit, bool larger_first) const {
  if (nodes.empty()) return false;
  // A fixed stack: a median-split tree over 2^31 primitives is < 64 deep and a level pushes two.
  std::pair<int, double> stack[256];
  int size = 0;
  stack[size++] = {0, key(0)};
  while (size > 0) {
    const auto [k, score] = stack[--size];
    if (skip(score)) continue;
    const BvhNode& node = nodes[k];
    if (node.child < 0) {
      for (int i = node.begin; i < node.end; ++i)
        if (visit(i)) return true;
      continue;
    }
    // The preferred child goes on top of the stack.
    const double s0 = key(node.child), s1 = key(node.child + 1);
    const bool second_first = larger_first ? s1 > s0 : s1 < s0;
    if (second_first) {
      stack[size++] = {node.child, s0};
      stack[size++] = {node.child + 1, s1};
    } else {
      stack[size++] = {node.child + 1, s1};
      stack[size++] = {node.child, s0};
    }
  }
  return false;
}

}  // namespace rbx
