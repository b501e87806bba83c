// The bench's scene builders (comparisons/eval/bench_cases.h): the poses and crowds `rbx bench`
// times are what perf.md says they are, checked with the exact SAT oracle.
#include "comparisons/eval/bench_cases.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace rbx {
namespace {

TEST(BenchCases, SphereHullKeepsEveryPointOnTheSphere) {
  std::mt19937_64 rng(1);
  const ConvexPolyhedron hull = sphere_hull(64, rng);
  EXPECT_EQ(hull.vertices().size(), 64u);  // points on a sphere are all extreme
  // Radius 0.5 m up to the round-off of normalising a vector (a few ulps of 0.5).
  for (const Vec3& v : hull.vertices()) EXPECT_NEAR(v.norm(), 0.5 * kBenchShapeSize, 1e-12);
}

TEST(BenchCases, PoseKindsGiveTheStatedDepthsAndGaps) {
  // B is placed `offset` of the size along a random direction d from the touching distance, so
  // the minimum-translation depth is at most |offset| (d need not be the contact normal) and
  // positive for the overlapping kinds. 1e-9 m covers libccd's MPR tolerance (1e-10 m) in the
  // bisection for the touching distance.
  const ContactFn exact = find_backend("exact")->contact;
  std::mt19937_64 shape_rng(3);
  const ConvexPolyhedron shapes[] = {make_box(Vec3::Constant(kBenchShapeSize)),
                                     sphere_hull(32, shape_rng)};
  for (const ConvexPolyhedron& shape : shapes)
    for (const PoseKind& kind : kPoseKinds) {
      std::mt19937_64 rng(5);
      PosedPair p = make_poses(shape, shape.vertices().size() == 8, kind, 4, rng);
      ASSERT_EQ(p.poses_a.size(), 4u);
      for (std::size_t k = 0; k < p.poses_a.size(); ++k) {
        p.a.position = p.poses_a[k].position;
        p.a.orientation = p.poses_a[k].orientation;
        p.b.position = p.poses_b[k].position;
        p.b.orientation = p.poses_b[k].orientation;
        const ContactResult r = exact(p.a, p.b);
        ASSERT_EQ(r.status, Status::Ok) << r.message;
        double depth = 0.0;
        for (const ContactPoint& c : r.contacts) depth = std::max(depth, c.depth);
        if (kind.offset > 0) {
          EXPECT_TRUE(r.contacts.empty()) << kind.name << " pose " << k << " depth " << depth;
        } else {
          EXPECT_FALSE(r.contacts.empty()) << kind.name << " pose " << k;
          EXPECT_GT(depth, 0.0) << kind.name;
          EXPECT_LE(depth, -kind.offset * kBenchShapeSize + 1e-9) << kind.name << " pose " << k;
        }
      }
    }
}

TEST(BenchCases, CrowdHasOneCubePerEighthOfACubicMetre) {
  std::mt19937_64 rng(9);
  const int n = 1000;
  const std::vector<RigidBody> crowd = cube_crowd(n, rng);
  ASSERT_EQ(crowd.size(), static_cast<std::size_t>(n));
  const double side = 0.5 * std::cbrt(static_cast<double>(n));  // 0.125 m^3 per cube
  for (const RigidBody& b : crowd) {
    EXPECT_TRUE((b.position.array() >= 0.0).all() && (b.position.array() <= side).all());
    EXPECT_NEAR(b.shape->vertices()[0].cwiseAbs().maxCoeff(), 0.1, 1e-15);  // 0.2 m cubes
  }
}

TEST(BenchCases, EveryNarrowBackendHasAQueryAndTheQuickPlanIsPartOfTheFullOne) {
  // The timing variants (custom seed, fcl prebuilt) come from the registry's query variants.
  for (const NarrowBackend& b : narrow_backends())
    EXPECT_TRUE(static_cast<bool>(b.contact)) << b.backend << "/" << b.variant;
  const BenchPlan quick = bench_plan(true), full = bench_plan(false);
  for (int n : quick.hull_sizes)
    EXPECT_NE(std::find(full.hull_sizes.begin(), full.hull_sizes.end(), n), full.hull_sizes.end());
  EXPECT_LE(quick.poses, full.poses);
  EXPECT_LE(quick.poses_per_iteration, full.poses_per_iteration);
  // Both runs query a cycle of distinct poses many iterations long (docs/bench.md).
  for (const BenchPlan& p : {quick, full}) EXPECT_GE(p.poses, 20 * p.poses_per_iteration);
}

}  // namespace
}  // namespace rbx
