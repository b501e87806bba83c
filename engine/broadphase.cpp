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

// Whether two closed boxes overlap (touching counts).
bool overlap(const Vec3& a_min, const Vec3& a_max, const Vec3& b_min, const Vec3& b_max) {
  return a_min.x() <= b_max.x() && b_min.x() <= a_max.x() && a_min.y() <= b_max.y() &&
         b_min.y() <= a_max.y() && a_min.z() <= b_max.z() && b_min.z() <= a_max.z();
}

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
  return rbx::spheres_touch(spheres_[i], spheres_[j]);
}

void BroadPhase::test_pair(int i, int j) {
  if (i > j) std::swap(i, j);
  if (spheres_touch(i, j)) pairs_.push_back({i, j});
}

const std::vector<BodyPair>& BroadPhase::find_pairs(const std::vector<RigidBody>& bodies,
                                                    double grow) {
  // The seed's spheres, once per body.
  base_.resize(bodies.size());
  for (size_t i = 0; i < bodies.size(); ++i) base_[i] = bounding_sphere(bodies[i]);
  return pairs_of_base(bodies, grow);
}

const std::vector<BodyPair>& BroadPhase::find_pairs(const std::vector<RigidBody>& bodies,
                                                    const std::vector<BoundingSphere>& spheres,
                                                    double grow) {
  base_.assign(spheres.begin(), spheres.end());
  return pairs_of_base(bodies, grow);
}

const std::vector<BodyPair>& BroadPhase::pairs_of_base(const std::vector<RigidBody>& bodies,
                                                       double grow) {
  const int n = static_cast<int>(bodies.size());
  static_.resize(n);
  for (int i = 0; i < n; ++i) static_[i] = bodies[i].is_static;
  if (method_ == BroadPhaseMethod::AllPairs || !(tunables_.pair_cache_margin > 0.0)) {
    index(grow);
    return pairs_;
  }
  // The kept pairs of spheres grown further, while they still hold every pair (cache_holds),
  // else a new index with room to move; then the seed's test on this call's spheres. The kept
  // pairs are in (i, j) order, and so is any subset of them.
  if (!cache_holds(grow)) {
    const double room = tunables_.pair_cache_margin * median_moving_radius();
    index(grow + room);
    cache_pairs_.swap(pairs_);
    cache_centres_.resize(n);
    cache_radii_.resize(n);
    double scale = 0.0;
    for (int i = 0; i < n; ++i) {
      cache_centres_[i] = base_[i].center;
      cache_radii_[i] = base_[i].radius;
      scale = std::max(scale, base_[i].center.cwiseAbs().maxCoeff() + base_[i].radius);
    }
    cache_static_ = static_;
    cache_grow_ = grow + room;
    cache_slack_ = kPad * (1.0 + scale);
    ++cache_builds_;
  }
  pairs_.clear();
  for (const BodyPair& p : cache_pairs_) {
    BoundingSphere a = base_[p.first], b = base_[p.second];
    a.radius += grow;
    b.radius += grow;
    if (rbx::spheres_touch(a, b)) pairs_.push_back(p);
  }
  return pairs_;
}

bool BroadPhase::cache_holds(double grow) const {
  // A pair whose spheres, grown by `grow`, touch now was within 2 cache_grow_ of touching when
  // the cache was built if neither centre has since moved more than cache_grow_ - grow (the
  // triangle inequality); the slack covers the round-off of the norms on both sides.
  const int n = static_cast<int>(base_.size());
  if (cache_builds_ == 0 || static_cast<int>(cache_centres_.size()) != n ||
      static_ != cache_static_)
    return false;
  const double reach = cache_grow_ - grow - cache_slack_;
  if (!(reach >= 0.0)) return false;
  for (int i = 0; i < n; ++i) {
    if (base_[i].radius != cache_radii_[i]) return false;
    if (!((base_[i].center - cache_centres_[i]).squaredNorm() <= reach * reach)) return false;
  }
  return true;
}

double BroadPhase::median_moving_radius() {
  radii_.clear();
  for (std::size_t i = 0; i < base_.size(); ++i)
    if (!static_[i]) radii_.push_back(base_[i].radius);
  if (radii_.empty()) return 0.0;
  std::nth_element(radii_.begin(), radii_.begin() + radii_.size() / 2, radii_.end());
  return radii_[radii_.size() / 2];
}

void BroadPhase::index(double grow) {
  // Padded boxes around the spheres, each grown by `grow`.
  const int n = static_cast<int>(base_.size());
  spheres_.resize(n);
  box_min_.resize(n);
  box_max_.resize(n);
  for (int i = 0; i < n; ++i) {
    spheres_[i] = base_[i];
    if (grow > 0.0) spheres_[i].radius += grow;
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
  // The seed's loop order: by i, then j. A counting sort on i (O(pairs + bodies)), then each
  // body's few partners sorted (cheaper than a comparison sort of every pair).
  if (method_ != BroadPhaseMethod::AllPairs) {
    bucket_start_.assign(n + 1, 0);
    for (const BodyPair& p : pairs_) ++bucket_start_[p.first + 1];
    for (int i = 0; i < n; ++i) bucket_start_[i + 1] += bucket_start_[i];
    sorted_.resize(pairs_.size());
    std::vector<int>& next = bucket_fill_;
    next.assign(bucket_start_.begin(), bucket_start_.end() - 1);
    for (const BodyPair& p : pairs_) sorted_[next[p.first]++] = p;
    for (int i = 0; i < n; ++i)
      std::sort(sorted_.begin() + bucket_start_[i], sorted_.begin() + bucket_start_[i + 1]);
    pairs_.swap(sorted_);
  }
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

bool BroadPhase::grid() {
  // Many moving bodies of like size packed in a volume (a pile, a gas of cubes): a uniform grid,
  // cell = the largest box, each body in the cell of its box's lower corner, cells stored
  // densely (a counting sort of the bodies by cell). Two boxes no larger than a cell overlap only
  // if their cells are neighbours (each index within 1), so each body looks in its own cell and
  // 13 of its 26 neighbours (the other 13 look back at it): O(N + cells + pairs). Used when
  // there are at least grid_min_moving bodies (WorldSettings), every moving box is within 2x of the
  // median size, and the grid has at most 8 cells per body (else it is mostly empty and the tree is
  // the better index).
  const int m_count = static_cast<int>(moving_.size());
  if (m_count < tunables_.grid_min_moving) return false;
  extent_.resize(m_count);
  for (int m = 0; m < m_count; ++m)
    extent_[m] = (box_max_[moving_[m]] - box_min_[moving_[m]]).maxCoeff();
  std::vector<double> sorted = extent_;
  std::nth_element(sorted.begin(), sorted.begin() + m_count / 2, sorted.end());
  const double median = sorted[m_count / 2];
  const double h = *std::max_element(extent_.begin(), extent_.end());
  if (!(h > 0.0) || !(h <= 2.0 * median)) return false;
  Vec3 lo = box_min_[moving_[0]], hi = lo;
  for (int j : moving_) {
    lo = lo.cwiseMin(box_min_[j]);
    hi = hi.cwiseMax(box_min_[j]);
  }
  const Vec3 span = ((hi - lo) / h).array().floor() + 1.0;  // cells per axis
  if (!(span.prod() <= 8.0 * m_count)) return false;
  const int nx = static_cast<int>(span.x()), ny = static_cast<int>(span.y()),
            nz = static_cast<int>(span.z());
  // Counting sort of the moving bodies by cell (x-major), stable: body order within a cell.
  cell_of_.resize(m_count);
  cell_start_.assign(static_cast<size_t>(nx) * ny * nz + 1, 0);
  for (int m = 0; m < m_count; ++m) {
    const Vec3 c = ((box_min_[moving_[m]] - lo) / h).array().floor();
    const int cx = std::min(static_cast<int>(c.x()), nx - 1),
              cy = std::min(static_cast<int>(c.y()), ny - 1),
              cz = std::min(static_cast<int>(c.z()), nz - 1);
    cell_of_[m] = (cx * ny + cy) * nz + cz;
    ++cell_start_[cell_of_[m] + 1];
  }
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  in_cells_.resize(m_count);
  bucket_fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (int m = 0; m < m_count; ++m) in_cells_[bucket_fill_[cell_of_[m]]++] = moving_[m];
  // Boxes and spheres in cell order, so that neighbours are read from nearby memory; then the
  // seed's sphere test on the pair, lower body index first.
  leaf_min_.resize(m_count);
  leaf_max_.resize(m_count);
  leaf_spheres_.resize(m_count);
  for (int x = 0; x < m_count; ++x) {
    leaf_min_[x] = box_min_[in_cells_[x]];
    leaf_max_[x] = box_max_[in_cells_[x]];
    leaf_spheres_[x] = spheres_[in_cells_[x]];
  }
  auto test = [&](int x, int y) {
    if (!overlap(leaf_min_[x], leaf_max_[x], leaf_min_[y], leaf_max_[y])) return;
    int i = in_cells_[x], j = in_cells_[y];
    if (i > j) std::swap(x, y), std::swap(i, j);
    const BoundingSphere &sa = leaf_spheres_[x], &sb = leaf_spheres_[y];
    if (rbx::spheres_touch(sa, sb)) pairs_.push_back({i, j});
  };
  // Half the neighbourhood: offsets after (0, 0, 0) in lexicographic order.
  static constexpr int kHalf[13][3] = {{0, 0, 1},  {0, 1, -1}, {0, 1, 0},  {0, 1, 1}, {1, -1, -1},
                                       {1, -1, 0}, {1, -1, 1}, {1, 0, -1}, {1, 0, 0}, {1, 0, 1},
                                       {1, 1, -1}, {1, 1, 0},  {1, 1, 1}};
  for (int cx = 0; cx < nx; ++cx)
    for (int cy = 0; cy < ny; ++cy)
      for (int cz = 0; cz < nz; ++cz) {
        const int cell = (cx * ny + cy) * nz + cz;
        const int r = cell_start_[cell], e = cell_start_[cell + 1];
        if (r == e) continue;
        for (int x = r; x < e; ++x)
          for (int y = x + 1; y < e; ++y) test(x, y);
        for (const auto& o : kHalf) {
          const int ox = cx + o[0], oy = cy + o[1], oz = cz + o[2];
          if (ox >= nx || oy < 0 || oy >= ny || oz < 0 || oz >= nz) continue;
          const int other = (ox * ny + oy) * nz + oz;
          for (int x = r; x < e; ++x)
            for (int y = cell_start_[other]; y < cell_start_[other + 1]; ++y) test(x, y);
        }
      }
  return true;
}

// The tree's stages: statics apart, then the grid or the hierarchy (build, statics against it,
// the tree against itself).
void BroadPhase::tree() {
  const int n = static_cast<int>(spheres_.size());
  used_grid_ = false;
  if (n < 2) return;
  split_statics();
  if (moving_.empty()) return;
  used_grid_ = grid();
  if (used_grid_) {
    for (int i : statics_)
      for (int j : moving_)
        if (overlap(box_min_[j], box_max_[j], box_min_[i], box_max_[i])) test_pair(i, j);
    return;
  }
  build_tree();
  statics_against_tree();
  tree_against_itself();
}

void BroadPhase::split_statics() {
  // Static bodies (walls, a floor) stay out of the tree, whose nodes their boxes would widen:
  // each is queried against the tree of moving bodies, and statics against statics in a double
  // loop. That is for a few statics; beyond statics_apart (a static terrain) they go into the
  // tree with the rest, as before, and the double loop is not run.
  const int n = static_cast<int>(spheres_.size());
  moving_.clear();
  statics_.clear();
  for (int i = 0; i < n; ++i) (static_[i] ? statics_ : moving_).push_back(i);
  if (statics_.size() > tunables_.statics_apart) {
    moving_.resize(n);
    for (int i = 0; i < n; ++i) moving_[i] = i;
    statics_.clear();
  }
  for (size_t s = 0; s < statics_.size(); ++s)
    for (size_t t = s + 1; t < statics_.size(); ++t) {
      const int i = statics_[s], j = statics_[t];
      if (overlap(box_min_[i], box_max_[i], box_min_[j], box_max_[j])) test_pair(i, j);
    }
}

void BroadPhase::build_tree() {
  // Build: the shared hierarchy (engine/bvh.h) over the moving bodies' padded boxes.
  const int m_count = static_cast<int>(moving_.size());
  leaf_min_.resize(m_count);
  leaf_max_.resize(m_count);
  for (int m = 0; m < m_count; ++m) {
    leaf_min_[m] = box_min_[moving_[m]];
    leaf_max_[m] = box_max_[moving_[m]];
  }
  tree_ = Bvh::build(leaf_min_, leaf_max_, kLeafSize);
  // Tree positions to bodies.
  tree_order_.resize(m_count);
  for (int m = 0; m < m_count; ++m) tree_order_[m] = moving_[tree_.order[m]];
  // The leaves' boxes in tree order, so that the traversal reads memory in sequence.
  leaf_spheres_.resize(m_count);
  for (int m = 0; m < m_count; ++m) {
    leaf_min_[m] = box_min_[tree_order_[m]];
    leaf_max_[m] = box_max_[tree_order_[m]];
    leaf_spheres_[m] = spheres_[tree_order_[m]];
  }
}

void BroadPhase::statics_against_tree() {
  // Each static body against the tree: every moving body whose box overlaps its box.
  const std::vector<BvhNode>& nodes = tree_.nodes;
  for (int i : statics_) {
    tree_.search(
        [&](int k) { return overlap(nodes[k].min, nodes[k].max, box_min_[i], box_max_[i]); },
        [](double touching) { return touching == 0.0; },
        [&](int m) {
          const int j = moving_[m];
          if (overlap(box_min_[j], box_max_[j], box_min_[i], box_max_[i])) test_pair(i, j);
          return false;
        });
  }
}

void BroadPhase::test_leaves(int m, int q) {
  // Boxes at tree positions m and q overlap: the seed's test on the same spheres, written with
  // the lower body index first as bounding_check(bodies[i], bodies[j]) is, i < j.
  if (!overlap(leaf_min_[m], leaf_max_[m], leaf_min_[q], leaf_max_[q])) return;
  if (tree_order_[m] > tree_order_[q]) std::swap(m, q);
  const BoundingSphere& sa = leaf_spheres_[m];
  const BoundingSphere& sb = leaf_spheres_[q];
  if (rbx::spheres_touch(sa, sb)) pairs_.push_back({tree_order_[m], tree_order_[q]});
}

void BroadPhase::tree_against_itself() {
  // A dual traversal. A node is paired with itself (its two children with themselves and with
  // each other) and two nodes whose boxes overlap are opened, the larger first; two leaves
  // test their bodies' boxes, then the seed's sphere test. Every pair of bodies is reached
  // exactly once, through the lowest node holding both.
  const std::vector<BvhNode>& nodes = tree_.nodes;
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
