// The bench's scene builders (comparisons/eval/bench_cases.h): the poses and crowds `rbx bench`
// times are what perf.md says they are, checked with the exact SAT oracle.
#include "comparisons/eval/bench_cases.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

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

TEST(BenchCases, EveryRowOfARunIsTimedInRoundsWithItsColdPassApart) {
  // A run as small as the families allow: the box and one hull, one crowd, a few steps, a few
  // explore samples, and times so short that every case stops at its minimum count of rounds
  // (a slow call at the smaller count TimingPlan allows it).
  BenchPlan plan = bench_plan(true);
  plan.hull_sizes = {32};
  plan.min_time = 1e-4;
  plan.crowd_sizes = {200};
  plan.crowd_min_time = 1e-4;
  plan.steps_100 = {2, 4};
  plan.steps_1000 = {1, 2};
  plan.step_min_time = 1e-4;
  plan.step_rounds = 3;
  plan.explore_samples = 20;
  plan.explore_min_time = 1e-4;
  const BenchResults r = run_bench(plan);
  auto well_formed = [](const BenchTime& t, int min_rounds, const std::string& what) {
    EXPECT_GE(t.rounds, min_rounds) << what;
    EXPECT_EQ(t.per_round.size(), static_cast<std::size_t>(t.rounds)) << what;
    EXPECT_LE(t.q25, t.median) << what;
    EXPECT_LE(t.median, t.q75) << what;
  };
  ASSERT_FALSE(r.narrow.empty());
  for (const NarrowRow& row : r.narrow) {
    const std::string what =
        row.backend + "/" + row.variant + "/" + std::to_string(row.vertices) + "/" + row.pose;
    EXPECT_EQ(row.status, "ok") << what;
    well_formed(row.ns_per_query, TimingPlan{}.min_rounds_slow, what);
    EXPECT_GT(row.ns_per_query.median, 0.0) << what;
    EXPECT_GT(row.ns_per_query.cold, 0.0) << what;
    EXPECT_GE(row.ns_per_query.calls, row.ns_per_query.rounds) << what;
  }
  // Every backend of one size and kind was timed in the same turns: any two share rounds.
  for (const NarrowRow& a : r.narrow)
    for (const NarrowRow& b : r.narrow) {
      if (a.vertices == b.vertices && a.pose == b.pose) {
        EXPECT_GT(bench_ratio(a.ns_per_query, b.ns_per_query).rounds, 0);
      }
    }
  ASSERT_EQ(r.broad.size(), 3u);
  for (const BroadRow& row : r.broad)
    well_formed(row.ns_per_step, TimingPlan{}.min_rounds_slow, row.method);
  // Two scenes, four engines.
  ASSERT_EQ(r.step.size(), 8u);
  for (const StepRow& row : r.step) {
    const std::string what = row.scene + "/" + row.backend + "/" + row.variant;
    // A round's figure is a difference of two runs of a few steps: it may be lost in the noise
    // of building the world, and the row then says so instead of giving a number.
    if (row.status == "ok") {
      well_formed(row.us_per_body_step, TimingPlan{}.min_rounds_slow, what);
    } else {
      EXPECT_EQ(row.status, "extra steps within the timing noise of the set-up") << what;
    }
  }
  ASSERT_EQ(r.explore.size(), 1u);
  well_formed(r.explore[0].samples_per_minute, 3, "explore");
  EXPECT_GT(r.explore[0].samples, 0);
}

}  // namespace
}  // namespace rbx
