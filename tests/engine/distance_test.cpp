// The separation distance (engine/distance.h) on closed forms: each expected value is derived in
// the comment beside it. Random pairs against the exact oracle: tests/reference/exact_test.cpp.
#include "engine/distance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::at;

// Round-off of GJK's last simplex on unit-scale shapes: a few dozen operations on coordinates of
// order 1 (~1e-15); 1e-12 leaves a wide margin and is far below any wrong feature (>= 1e-3 here).
constexpr double kGjkRoundOff = 1e-12;

Quat about(double deg, const Vec3& axis) { return Quat(Eigen::AngleAxisd(deg * M_PI / 180, axis)); }

// The answer in both body orders: the same distance, the points swapped.
void expect_pair(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                 const Pose& pb, double distance, const Vec3& on_a, const Vec3& on_b) {
  for (bool swapped : {false, true}) {
    const Separation s = swapped ? shape_distance(b, pb, a, pa) : shape_distance(a, pa, b, pb);
    ASSERT_FALSE(s.overlapping);
    EXPECT_NEAR(s.distance, distance, kGjkRoundOff);
    EXPECT_NEAR(((swapped ? s.point_b : s.point_a) - on_a).norm(), 0.0, kGjkRoundOff);
    EXPECT_NEAR(((swapped ? s.point_a : s.point_b) - on_b).norm(), 0.0, kGjkRoundOff);
  }
}

TEST(ShapeDistance, VertexAgainstAFace) {
  // A unit cube turned so that its corner (0.5, 0.5, 0.5) points along +x: that corner is at
  // x = sqrt(3)/2 on the axis. B, a unit cube at x = sqrt(3)/2 + 0.75, has its -x face at
  // sqrt(3)/2 + 0.25: the gap is 0.25, from the corner straight across to B's face.
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const Quat corner_to_x = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3::UnitX());
  const double tip = std::sqrt(3.0) / 2;
  expect_pair(cube, at(Vec3::Zero(), corner_to_x), cube, at(Vec3(tip + 0.75, 0, 0)), 0.25,
              Vec3(tip, 0, 0), Vec3(tip + 0.25, 0, 0));
}

TEST(ShapeDistance, EdgeAcrossAnEdge) {
  // A turned 45 deg about z: its nearest feature toward +x is the edge x = sqrt(2)/2, y = 0,
  // along z. B turned 45 deg about y at x = c: its edge x = c - sqrt(2)/2, z = 0, along y. The
  // edges cross at right angles; their closest points are (sqrt(2)/2, 0, 0) and
  // (c - sqrt(2)/2, 0, 0), c - sqrt(2) apart. With c = sqrt(2) + 0.3: 0.3.
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const double h = std::sqrt(2.0) / 2, c = std::sqrt(2.0) + 0.3;
  expect_pair(cube, at(Vec3::Zero(), about(45, Vec3::UnitZ())), cube,
              at(Vec3(c, 0, 0), about(45, Vec3::UnitY())), 0.3, Vec3(h, 0, 0), Vec3(c - h, 0, 0));
}

TEST(ShapeDistance, ParallelFacesGiveTheGapAndPointsStraightAcross) {
  // Unit cubes, B at (1.5, 0.2, -0.1): the faces x = 0.5 and x = 1.0 face each other over the
  // overlap y in [-0.3, 0.5], z in [-0.5, 0.4]; every pair straight across is closest, 0.5
  // apart. Whichever GJK returns lies on both faces, in the overlap, straight across.
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const Separation s = shape_distance(cube, at(Vec3::Zero()), cube, at(Vec3(1.5, 0.2, -0.1)));
  ASSERT_FALSE(s.overlapping);
  EXPECT_NEAR(s.distance, 0.5, kGjkRoundOff);
  EXPECT_NEAR(s.point_a.x(), 0.5, kGjkRoundOff);
  EXPECT_NEAR(s.point_b.x(), 1.0, kGjkRoundOff);
  EXPECT_NEAR((s.point_b - s.point_a - Vec3(0.5, 0, 0)).norm(), 0.0, kGjkRoundOff);
  EXPECT_GE(s.point_a.y(), -0.3 - kGjkRoundOff);
  EXPECT_LE(s.point_a.y(), 0.5 + kGjkRoundOff);
  EXPECT_GE(s.point_a.z(), -0.5 - kGjkRoundOff);
  EXPECT_LE(s.point_a.z(), 0.4 + kGjkRoundOff);
}

TEST(ShapeDistance, FromAHairToTenSizesApart) {
  // Face to face along x at gaps from 1e-9 to 10 m: the gap, to round-off of the coordinates
  // (the face planes sit at 0.5 and 0.5 + gap; the difference loses ~1e-16 of their size).
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  for (double gap : {1e-9, 1e-6, 1e-3, 1.0, 10.0}) {
    const Separation s = shape_distance(cube, at(Vec3::Zero()), cube, at(Vec3(1.0 + gap, 0, 0)));
    ASSERT_FALSE(s.overlapping) << gap;
    EXPECT_NEAR(s.distance, gap, 1e-15 * (1.0 + gap)) << gap;
  }
}

TEST(ShapeDistance, OverlappingAndTouchingPairsHaveNoDistance) {
  // 0.1 m into each other, and exactly face to face: the contact query's cases.
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  EXPECT_TRUE(shape_distance(cube, at(Vec3::Zero()), cube, at(Vec3(0.9, 0, 0))).overlapping);
  EXPECT_TRUE(shape_distance(cube, at(Vec3::Zero()), cube, at(Vec3(1.0, 0, 0))).overlapping);
  EXPECT_TRUE(shape_distance(cube, at(Vec3::Zero()), cube, at(Vec3::Zero())).overlapping);
}

TEST(ShapeDistance, ASphereHullTakesItsNearestFacet) {
  // An icosphere (642 vertices, climbed, not scanned) of radius 1 and a unit cube whose -x face
  // is at x = 1.25: the icosphere's vertex (1, 0, 0) is its furthest point along +x (one of the
  // icosahedron's twelve), so the gap is 0.25 from it straight across.
  const ConvexPolyhedron ball = make_icosphere(1.0, 3), cube = make_box(Vec3::Ones());
  ASSERT_GT(ball.vertices().size(), 160u);
  const Quat vertex_to_x = Quat::FromTwoVectors(ball.vertices()[0].normalized(), Vec3::UnitX());
  expect_pair(ball, at(Vec3::Zero(), vertex_to_x), cube, at(Vec3(1.75, 0, 0)), 0.25, Vec3(1, 0, 0),
              Vec3(1.25, 0, 0));
}

}  // namespace
}  // namespace rbx
