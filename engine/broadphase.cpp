#include "engine/broadphase.h"

#include <algorithm>
#include <cmath>

namespace rbx {

namespace {

// Relative padding of the boxes around the spheres. The exact test compares |c_i - c_j| with
// r_i + r_j, each rounded to a few ulps (~1e-16 relative) of the coordinates; a box overlap
// test on the same numbers could reject a pair the sphere test accepts at exactly touching.
// Padding each box by 1e-9 of its coordinate scale is ~10^7 times that round-off, so every
// pair the seed's test accepts has overlapping boxes, and the padding admits only pairs that
// are a nanometre-per-metre from touching (which the exact test then rejects).
constexpr double kPad = 1e-9;
// Bodies per leaf of the tree.
constexpr int kLeafSize = 4;

}  // namespace

const char* to_string(BroadPhaseMethod method) {
  switch (method) {
    case BroadPhaseMethod::AllPairs:
      return "all-pairs";
    case BroadPhaseMethod::SweepAndPrune:
      return "sweep-and-prune";
    case BroadPhaseMethod::Tree:
      return "tree";
  }
  return "tree";
}

bool BroadPhase::spheres_touch(int i, int j) const {
  // Exactly bounding_check(): the same spheres (bounding_sphere() is deterministic), the same
  // expression.
  const BoundingSphere& sa = spheres_[i];
  const BoundingSphere& sb = spheres_[j];
  return (sa.center - sb.center).norm() <= sa.radius + sb.radius;
}

void BroadPhase::test_pair(int i, int j) {
  if (i > j) std::swap(i, j);
  if (spheres_touch(i, j)) pairs_.push_back({i, j});
}

const std::vector<BodyPair>& BroadPhase::find_pairs(const std::vector<RigidBody>& bodies) {
  // The seed's spheres, once per body, and padded boxes around them.
  const int n = static_cast<int>(bodies.size());
  spheres_.resize(n);
  box_min_.resize(n);
  box_max_.resize(n);
  for (int i = 0; i < n; ++i) {
    spheres_[i] = bounding_sphere(bodies[i]);
    const double pad =
        spheres_[i].radius + kPad * (spheres_[i].radius + spheres_[i].center.cwiseAbs().maxCoeff());
    box_min_[i] = spheres_[i].center.array() - pad;
    box_max_[i] = spheres_[i].center.array() + pad;
  }
  pairs_.clear();
  switch (method_) {
    case BroadPhaseMethod::AllPairs:
      all_pairs();
      break;
    case BroadPhaseMethod::SweepAndPrune:
      sweep_and_prune();
      break;
    case BroadPhaseMethod::Tree:
      tree();
      break;
  }
  // The seed's loop order: by i, then j.
  if (method_ != BroadPhaseMethod::AllPairs) std::sort(pairs_.begin(), pairs_.end());
  return pairs_;
}

void BroadPhase::all_pairs() {
  // The seed's double loop: already in (i, j) order.
  const int n = static_cast<int>(spheres_.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (spheres_touch(i, j)) pairs_.push_back({i, j});
}

void BroadPhase::sweep_and_prune() {
  const int n = static_cast<int>(spheres_.size());
  // Sweep along the axis where the centres spread most (fewest overlaps on it).
  Vec3 mean = Vec3::Zero(), mean_sq = Vec3::Zero();
  for (const BoundingSphere& s : spheres_) {
    mean += s.center;
    mean_sq += s.center.cwiseProduct(s.center);
  }
  int axis = 0;
  if (n > 0) (mean_sq / n - (mean / n).cwiseProduct(mean / n)).maxCoeff(&axis);
  // Keep the last order when the axis and the bodies are the same: after a small motion it is
  // nearly sorted, and insertion sort costs O(N + swaps). Otherwise sort from scratch.
  const auto lower = [&](int a, int b) {
    return box_min_[a][axis] < box_min_[b][axis] ||
           (box_min_[a][axis] == box_min_[b][axis] && a < b);
  };
  if (axis != sap_axis_ || static_cast<int>(order_.size()) != n) {
    order_.resize(n);
    for (int i = 0; i < n; ++i) order_[i] = i;
    std::sort(order_.begin(), order_.end(), lower);
  } else {
    for (int k = 1; k < n; ++k) {
      const int moving = order_[k];
      int m = k;
      for (; m > 0 && lower(moving, order_[m - 1]); --m) order_[m] = order_[m - 1];
      order_[m] = moving;
    }
  }
  sap_axis_ = axis;
  // Sweep: each box against the boxes starting before it ends, on the other two axes too.
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  for (int k = 0; k < n; ++k) {
    const int i = order_[k];
    const double end = box_max_[i][axis];
    for (int m = k + 1; m < n; ++m) {
      const int j = order_[m];
      if (box_min_[j][axis] > end) break;
      if (box_min_[j][u] > box_max_[i][u] || box_min_[i][u] > box_max_[j][u]) continue;
      if (box_min_[j][v] > box_max_[i][v] || box_min_[i][v] > box_max_[j][v]) continue;
      test_pair(i, j);
    }
  }
}

void BroadPhase::tree() {
  const int n = static_cast<int>(spheres_.size());
  if (n < 2) return;
  // Build: the shared hierarchy (engine/bvh.h) over the padded boxes.
  tree_ = Bvh::build(box_min_, box_max_, kLeafSize);
  const std::vector<int>& order = tree_.order;
  const std::vector<BvhNode>& nodes = tree_.nodes;
  // Query: the tree against itself (a dual traversal). A node is paired with itself (its two
  // children with themselves and with each other) and two nodes whose boxes overlap are opened,
  // the larger first; two leaves test their bodies' boxes, then the seed's sphere test. Every
  // pair of bodies is reached exactly once, through the lowest node holding both.
  auto overlap = [](const Vec3& a_min, const Vec3& a_max, const Vec3& b_min, const Vec3& b_max) {
    return a_min.x() <= b_max.x() && b_min.x() <= a_max.x() && a_min.y() <= b_max.y() &&
           b_min.y() <= a_max.y() && a_min.z() <= b_max.z() && b_min.z() <= a_max.z();
  };
  // The leaves' boxes in tree order, so that the traversal reads memory in sequence.
  leaf_min_.resize(n);
  leaf_max_.resize(n);
  leaf_spheres_.resize(n);
  for (int m = 0; m < n; ++m) {
    leaf_min_[m] = box_min_[order[m]];
    leaf_max_[m] = box_max_[order[m]];
    leaf_spheres_[m] = spheres_[order[m]];
  }
  // Boxes at tree positions m and q overlap: the seed's test on the same spheres, written with
  // the lower body index first as bounding_check(bodies[i], bodies[j]) is, i < j.
  auto test_leaves = [&](int m, int q) {
    if (!overlap(leaf_min_[m], leaf_max_[m], leaf_min_[q], leaf_max_[q])) return;
    if (order[m] > order[q]) std::swap(m, q);
    const BoundingSphere& sa = leaf_spheres_[m];
    const BoundingSphere& sb = leaf_spheres_[q];
    if ((sa.center - sb.center).norm() <= sa.radius + sb.radius)
      pairs_.push_back({order[m], order[q]});
  };
  std::vector<std::pair<int, int>>& stack = node_pairs_;
  stack.clear();
  stack.push_back({0, 0});
  while (!stack.empty()) {
    const auto [ka, kb] = stack.back();
    stack.pop_back();
    const BvhNode& a = nodes[ka];
    const BvhNode& b = nodes[kb];
    if (ka == kb) {
      if (a.child < 0) {
        for (int m = a.begin; m < a.end; ++m)
          for (int q = m + 1; q < a.end; ++q) test_leaves(m, q);
      } else {
        stack.push_back({a.child, a.child});
        stack.push_back({a.child + 1, a.child + 1});
        stack.push_back({a.child, a.child + 1});
      }
      continue;
    }
    if (!overlap(a.min, a.max, b.min, b.max)) continue;
    if (a.child < 0 && b.child < 0) {
      for (int m = a.begin; m < a.end; ++m)
        for (int q = b.begin; q < b.end; ++q) test_leaves(m, q);
      continue;
    }
    // Open the node with more bodies (a leaf is never opened).
    const bool open_a = b.child < 0 || (a.child >= 0 && a.end - a.begin >= b.end - b.begin);
    if (open_a) {
      stack.push_back({a.child, kb});
      stack.push_back({a.child + 1, kb});
    } else {
      stack.push_back({ka, b.child});
      stack.push_back({ka, b.child + 1});
    }
  }
}

}  // namespace rbx
