// rbx distance's verdicts (judge_distance) on answers made by hand, and its comparison on a scene
// (compare_distances): the oracle and custom agree, a backend without the query is unsupported.
#include "comparisons/eval/distance_query.h"

#include <gtest/gtest.h>

#include <cmath>

#include "comparisons/scene/scene_file.h"
#include "reference/exact.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

// Two unit cubes, A 0.25 above B across parallel faces (z), offset by (0.2, 0.1): the closest
// pairs are every point of the faces' overlap straight across.
struct Pair {
  RigidBody a = test::unit_cube("A", Vec3(0.2, 0.1, 1.25));
  RigidBody b = test::unit_cube("B", Vec3::Zero());
};

DistanceResult apart(double d, const Vec3& pa, const Vec3& pb) {
  DistanceResult r;
  r.distance = d;
  r.point_a = pa;
  r.point_b = pb;
  return r;
}

DistanceResult overlapping() {
  DistanceResult r;
  r.overlapping = true;
  return r;
}

TEST(JudgeDistance, AnyClosestPairAtTheTrueDistanceIsRight) {
  const Pair p;
  const DistanceResult truth = apart(0.25, Vec3(0, 0, 0.75), Vec3(0, 0, 0.5));
  // The same pair, and another corner of the faces' overlap: both closest pairs.
  for (const Vec3& at : {Vec3(0, 0, 0), Vec3(0.45, 0.45, 0)}) {
    const DistanceVerdict v =
        judge_distance(apart(0.25, at + Vec3(0, 0, 0.75), at + Vec3(0, 0, 0.5)), truth, p.a, p.b);
    EXPECT_TRUE(v.comparable);
    EXPECT_EQ(v.mark, "") << v.why;
    EXPECT_LT(v.distance_err, 1e-15);
    EXPECT_LT(v.witness_err, 1e-15);
  }
}

TEST(JudgeDistance, AWrongDistanceOrAPointOffItsBodyDisagrees) {
  const Pair p;
  const DistanceResult truth = apart(0.25, Vec3(0, 0, 0.75), Vec3(0, 0, 0.5));
  // 1e-3 too far: relative error 4e-3.
  DistanceVerdict v =
      judge_distance(apart(0.251, Vec3(0, 0, 0.751), Vec3(0, 0, 0.5)), truth, p.a, p.b);
  EXPECT_EQ(v.mark, "disagrees");
  EXPECT_NEAR(v.distance_err, 0.004, 1e-12);
  // The right distance, but B's point 0.01 outside B (beyond its face's edge at x = 0.5).
  v = judge_distance(apart(0.25, Vec3(0.51, 0, 0.75), Vec3(0.51, 0, 0.5)), truth, p.a, p.b);
  EXPECT_EQ(v.mark, "disagrees");
  EXPECT_NEAR(v.witness_err, 0.01 / 0.25, 1e-12);
  // The points swapped: each 0.25 off its own body.
  v = judge_distance(apart(0.25, Vec3(0, 0, 0.5), Vec3(0, 0, 0.75)), truth, p.a, p.b);
  EXPECT_EQ(v.mark, "disagrees");
  // 1e-8 of the distance off: beyond round-off, within the disagreement threshold.
  v = judge_distance(apart(0.25 * (1 + 1e-8), Vec3(0, 0, 0.75), Vec3(0, 0, 0.5)), truth, p.a, p.b);
  EXPECT_EQ(v.mark, "deviates");
  // Cubes 1e-10 apart (below the floor, 1e-8 of the pair's extent 1.9): round-off of the
  // coordinates (3e-16 here) is no mark, the oracle's own answers carry that much; 1e-13 off is
  // beyond it and, over the floor, beyond 1e-6 as well: it disagrees.
  const RigidBody a = test::unit_cube("A", Vec3(0.2, 0.1, 1.0 + 1e-10)), b = p.b;
  const double gap = (a.position.z() - 0.5) - 0.5;
  const DistanceResult hair = apart(gap, Vec3(0, 0, 0.5 + gap), Vec3(0, 0, 0.5));
  v = judge_distance(apart(gap + 3e-16, Vec3(0, 0, 0.5 + gap), Vec3(0, 0, 0.5)), hair, a, b);
  EXPECT_EQ(v.mark, "") << v.why;
  v = judge_distance(apart(gap + 1e-13, Vec3(0, 0, 0.5 + gap), Vec3(0, 0, 0.5)), hair, a, b);
  EXPECT_EQ(v.mark, "disagrees") << v.why;
}

TEST(JudgeDistance, OverlapAgainstDistanceDisagreesExceptAtATouch) {
  const Pair p;
  const DistanceVerdict said_overlap =
      judge_distance(overlapping(), apart(0.25, Vec3(0, 0, 0.75), Vec3(0, 0, 0.5)), p.a, p.b);
  EXPECT_EQ(said_overlap.mark, "disagrees");
  EXPECT_FALSE(said_overlap.comparable);
  const DistanceVerdict gave_distance =
      judge_distance(apart(0.0, Vec3::Zero(), Vec3::Zero()), overlapping(), p.a, p.b);
  EXPECT_EQ(gave_distance.mark, "disagrees");
  // Touching (the true distance 0): "overlapping" is as right as 0.
  const DistanceVerdict at_touch =
      judge_distance(overlapping(), apart(0.0, Vec3(0, 0, 0.5), Vec3(0, 0, 0.5)), p.a, p.b);
  EXPECT_EQ(at_touch.mark, "");
  // An error status is shown as the status, not judged.
  DistanceResult failed;
  failed.status = Status::Error;
  EXPECT_EQ(judge_distance(failed, overlapping(), p.a, p.b).mark, "");
}

TEST(CompareDistances, TheOracleAndCustomAgreeAndAMissingQueryIsUnsupported) {
  // A turned cube 0.4 or so above a static floor: one pair. `custom-seed` has no distance query
  // and libccd 2.1 offers none (its GJK answers overlap only).
  const Scene scene = parse_scene(
      "[sim]\nduration = 0\n"
      "[[body]]\nname = \"floor\"\nstatic = true\nsize = [4, 4, 1]\nposition = [0, 0, -0.5]\n"
      "[[body]]\nname = \"cube\"\nposition = [0.3, -0.2, 1.4]\nrotation = [20, 35, 10]\n",
      "scene.toml");
  const DistanceComparison c = compare_distances(scene, {"custom", "custom-seed", "libccd-mpr"}, 0);
  ASSERT_EQ(c.pairs.size(), 1u);
  const DistancePair& pair = c.pairs[0];
  EXPECT_EQ(pair.a, "floor");
  EXPECT_EQ(pair.b, "cube");
  ASSERT_EQ(pair.truth.status, Status::Ok);
  ASSERT_FALSE(pair.truth.overlapping);
  ASSERT_EQ(pair.rows.size(), 3u);
  EXPECT_EQ(pair.rows[0].result.status, Status::Ok);
  EXPECT_TRUE(pair.rows[0].verdict.comparable);
  EXPECT_EQ(pair.rows[0].verdict.mark, "") << pair.rows[0].verdict.why;
  EXPECT_NEAR(pair.rows[0].result.distance, pair.truth.distance, 1e-12);
  for (size_t k : {1u, 2u}) {
    EXPECT_EQ(pair.rows[k].result.status, Status::Unsupported) << pair.rows[k].backend;
    EXPECT_EQ(pair.rows[k].verdict.mark, "");
  }
  // The JSON carries every row by name, with the errors only where they are comparable.
  const Json j = distance_json(c);
  EXPECT_EQ(j["query"], "distance");
  const Json& rows = j["pairs"][0]["backends"];
  EXPECT_EQ(rows["custom"]["status"], "ok");
  EXPECT_TRUE(rows["custom"].contains("distance_err_rel"));
  EXPECT_EQ(rows["libccd-mpr"]["status"], "unsupported");
  EXPECT_FALSE(rows["libccd-mpr"].contains("distance_err_rel"));
}

}  // namespace
}  // namespace rbx
