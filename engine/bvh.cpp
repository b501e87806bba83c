#include "engine/bvh.h"

#include <algorithm>

namespace rbx {

Bvh Bvh::build(const std::vector<Vec3>& lo, const std::vector<Vec3>& hi, int leaf_size) {
  Bvh t;
  const int n = static_cast<int>(lo.size());
  if (n == 0) return t;
  t.order.resize(n);
  for (int i = 0; i < n; ++i) t.order[i] = i;
  t.nodes.reserve(2 * (n / std::max(1, leaf_size) + 1));
  t.nodes.push_back({});
  t.nodes[0].begin = 0;
  t.nodes[0].end = n;
  std::vector<int> work = {0};
  while (!work.empty()) {
    const int k = work.back();
    work.pop_back();
    const int b = t.nodes[k].begin, e = t.nodes[k].end;
    // Bounding box of the primitives, and of their centres.
    Vec3 box_lo = lo[t.order[b]], box_hi = hi[t.order[b]];
    Vec3 c_lo = 0.5 * (box_lo + box_hi), c_hi = c_lo;
    for (int i = b + 1; i < e; ++i) {
      const int p = t.order[i];
      box_lo = box_lo.cwiseMin(lo[p]);
      box_hi = box_hi.cwiseMax(hi[p]);
      const Vec3 c = 0.5 * (lo[p] + hi[p]);
      c_lo = c_lo.cwiseMin(c);
      c_hi = c_hi.cwiseMax(c);
    }
    BvhNode& node = t.nodes[k];
    node.min = box_lo;
    node.max = box_hi;
    node.center = 0.5 * (box_lo + box_hi);
    node.half = 0.5 * (box_hi - box_lo);
    if (e - b <= leaf_size) continue;
    // Median split along the longest axis of the centres.
    int axis = 0;
    (c_hi - c_lo).maxCoeff(&axis);
    const int mid = (b + e) / 2;
    std::nth_element(t.order.begin() + b, t.order.begin() + mid, t.order.begin() + e,
                     [&](int x, int y) {
                       const double cx = lo[x][axis] + hi[x][axis], cy = lo[y][axis] + hi[y][axis];
                       return cx < cy || (cx == cy && x < y);
                     });
    const int child = static_cast<int>(t.nodes.size());
    t.nodes[k].child = child;
    t.nodes.push_back({});
    t.nodes.push_back({});
    t.nodes[child].begin = b;
    t.nodes[child].end = mid;
    t.nodes[child + 1].begin = mid;
    t.nodes[child + 1].end = e;
    work.push_back(child);
    work.push_back(child + 1);
  }
  return t;
}

}  // namespace rbx
