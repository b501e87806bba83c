// Broad phase: the pairs of bodies that pass the seed's bounding check (seed correction 7 (bounding
// check on the sum of radii)), found without testing every pair.
//
// Design note. Every method returns exactly the pairs i < j for which bounding_check(bodies[i],
// bodies[j]) is true, sorted by (i, j): the same set, in the order of the seed's double loop, so
// the world resolves the same contacts in the same order whatever the method. The faster
// methods only decide which pairs get the exact test: each bounding sphere is enclosed in an
// axis-aligned box padded far beyond round-off, boxes that do not overlap cannot hold spheres
// that do, and every surviving pair is then tested with the seed's own sphere expression.
//   - all-pairs: the seed's loop, O(N^2); kept as the reference.
//   - sweep-and-prune: boxes sorted along the axis of largest spread (kept from call to call, so
//     a small motion costs an insertion sort), then swept; O(N log N + pairs overlapping on that
//     axis), which for bodies spread through a volume grows like N^(5/3).
//   - tree: a bounding volume hierarchy of the moving bodies' boxes, rebuilt whenever an index
//     is built (median splits) and traversed against itself, each static body's box queried against
//     it; O(N log N + pairs), whatever the mix of body sizes. For many moving bodies of like size
//     it takes a uniform grid instead (O(N + cells + pairs)).
// The faster methods keep their pairs from call to call (as Bullet's dynamic tree keeps fattened
// boxes): each index is built for spheres grown by room to move (pair_cache_margin in
// WorldSettings), and while no centre has moved further than that room since, a call only runs
// the seed's test over the kept pairs. The kept pairs are a superset of the call's (the triangle
// inequality, in cache_holds), in order, so the answer is the same.
#pragma once

#include <utility>
#include <vector>

#include "engine/body.h"
#include "engine/bounding.h"
#include "engine/bvh.h"
#include "engine/settings.h"

namespace rbx {

/// How candidate pairs are found (all give the same pairs; see the design note).
enum class BroadPhaseMethod { AllPairs, SweepAndPrune, Tree };

/// "all-pairs" | "sweep-and-prune" | "tree".
const char* to_string(BroadPhaseMethod method);

/// Two body indices, i < j.
using BodyPair = std::pair<int, int>;

/// A broad phase with reusable storage (and, for sweep and prune, the order of the last call).
class BroadPhase {
 public:
  /// `tunables`: when the tree takes the grid or keeps statics apart (the pairs do not depend
  /// on them).
  explicit BroadPhase(BroadPhaseMethod method = BroadPhaseMethod::Tree,
                      const WorldSettings& tunables = WorldSettings())
      : method_(method), tunables_(tunables) {}

  /// Every pair i < j of `bodies` for which bounding_check is true, sorted by (i, j). The
  /// reference stays valid until the next call. With `grow` > 0 (m), the pairs whose bounding
  /// spheres, each grown by `grow`, touch: a superset, for a caller that filters it with the
  /// seed's test at more than one pose of the bodies.
  const std::vector<BodyPair>& find_pairs(const std::vector<RigidBody>& bodies, double grow = 0.0);
  /// The same, with the bodies' bounding spheres given (`spheres[i]` bounding_sphere(bodies[i]),
  /// bit for bit: a caller that keeps them).
  const std::vector<BodyPair>& find_pairs(const std::vector<RigidBody>& bodies,
                                          const std::vector<BoundingSphere>& spheres,
                                          double grow = 0.0);

  /// The method this broad phase runs.
  BroadPhaseMethod method() const { return method_; }

  /// How many times an index was built (the rest of the calls reused the kept pairs).
  long index_builds() const { return cache_builds_; }

  /// Whether the last tree call took the uniform grid (many moving bodies of like size, packed)
  /// instead of the hierarchy; the pairs are the same either way.
  bool used_grid() const { return used_grid_; }

 private:
  // find_pairs on this call's spheres, placed in base_.
  const std::vector<BodyPair>& pairs_of_base(const std::vector<RigidBody>& bodies, double grow);
  // Indexes this call's spheres (base_), each grown by `grow`, into pairs_ in (i, j) order.
  void index(double grow);
  // Whether the kept pairs hold every pair of this call's spheres grown by `grow`.
  bool cache_holds(double grow) const;
  // The median bounding radius of the moving bodies (m; 0 without any).
  double median_moving_radius();
  void all_pairs();
  void sweep_and_prune();
  void tree();
  // The tree's stages: statics apart from the moving bodies (tested among themselves), the
  // hierarchy over the moving bodies, each static against it, the hierarchy against itself.
  void split_statics();
  void build_tree();
  void statics_against_tree();
  void tree_against_itself();
  // Two leaves at tree positions m and q: box overlap, then the seed's sphere test.
  void test_leaves(int m, int q);
  // The tree's alternative for many moving bodies of like size; false when not suitable.
  bool grid();
  // The seed's test (bounding_check) on the cached spheres: |c_i - c_j| <= r_i + r_j.
  bool spheres_touch(int i, int j) const;
  // Records (min(i, j), max(i, j)) when the spheres touch.
  void test_pair(int i, int j);

  BroadPhaseMethod method_;
  WorldSettings tunables_;
  bool used_grid_ = false;
  std::vector<BoundingSphere> base_;             // this call's bounding spheres (bounding_sphere())
  std::vector<BoundingSphere> spheres_;          // the index's: base_ grown
  std::vector<Vec3> box_min_, box_max_;          // m, padded boxes around them
  std::vector<int> order_;                       // sweep and prune: sorted along sap_axis_
  int sap_axis_ = -1;                            // axis of the last sweep (-1: none yet)
  Bvh tree_;                                     // tree: over the padded boxes
  std::vector<std::pair<int, int>> node_pairs_;  // tree: traversal stack
  std::vector<Vec3> leaf_min_, leaf_max_;        // tree: boxes in tree order
  std::vector<BoundingSphere> leaf_spheres_;     // tree: spheres in tree order
  std::vector<bool> static_;                     // this call's bodies: static or not
  std::vector<int> moving_, statics_;            // tree: body indices of each kind
  std::vector<int> tree_order_;                  // tree: body at each tree position
  std::vector<int> bucket_start_, bucket_fill_;  // the pairs' counting sort on i
  std::vector<BodyPair> sorted_;                 // the pairs' counting sort: output
  std::vector<double> extent_;                   // grid: each moving box's largest side
  std::vector<int> cell_of_;                     // grid: each moving body's cell
  std::vector<int> cell_start_;                  // grid: first position of each cell
  std::vector<int> in_cells_;                    // grid: bodies in cell order
  std::vector<double> radii_;                    // median_moving_radius: scratch
  std::vector<BodyPair> cache_pairs_;            // kept: the pairs of the spheres grown by
  double cache_grow_ = 0.0;                      //   cache_grow_ (m),
  std::vector<Vec3> cache_centres_;              //   at these centres,
  std::vector<double> cache_radii_;              //   with these radii,
  std::vector<bool> cache_static_;               //   of these static flags
  double cache_slack_ = 0.0;                     // m, round-off allowance of cache_holds
  long cache_builds_ = 0;                        // indexes built
  std::vector<BodyPair> pairs_;
};

}  // namespace rbx
