// `custom`'s time of impact under the stated motion (engine/sweep.h) on closed forms: a cube
// falling flat, fast or a hair a second, and a rod turning about its centre until its corner
// meets a face.
#include "engine/sweep.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rbx {
namespace {

TEST(SweptPose, MovesTheCentreAndTurnsAboutIt) {
  const Sweep s{{Vec3(1, 2, 3), Quat::Identity()}, Vec3(0.5, 0, -1), Vec3(0, 0, M_PI)};
  const Pose p = swept_pose(s, 0.5);
  EXPECT_LT((p.position - Vec3(1.25, 2, 2.5)).norm(), 1e-15);
  // A quarter turn about z takes x to y.
  EXPECT_LT((p.orientation * Vec3::UnitX() - Vec3::UnitY()).norm(), 1e-15);
}

TEST(SweepTimeOfImpact, AFallingCubeTouchesWhenTheGapCloses) {
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  // A 0.3 m above B, falling at 2 m/s: touches at 0.15 s, normal from B toward A (+z).
  const Sweep a{{Vec3(0.2, 0.1, 1.3), Quat::Identity()}, Vec3(0, 0, -2), Vec3::Zero()};
  const Sweep b{{Vec3::Zero(), Quat::Identity()}, Vec3::Zero(), Vec3::Zero()};
  const SweepImpact hit = sweep_time_of_impact(cube, a, cube, b, 0.5);
  ASSERT_TRUE(hit.hit);
  ASSERT_TRUE(hit.located);
  // Its last safe step lands on the touch: round-off of the coordinates over the speed.
  EXPECT_NEAR(hit.time, 0.15, 1e-15);
  EXPECT_GT(hit.normal.z(), 1 - 1e-12);
  EXPECT_NEAR(hit.point.z(), 0.5, 1e-9);
  // Too short an interval, or moving away: no touch.
  EXPECT_FALSE(sweep_time_of_impact(cube, a, cube, b, 0.1).hit);
  const Sweep away{a.start, Vec3(0, 0, 2), Vec3::Zero()};
  EXPECT_FALSE(sweep_time_of_impact(cube, away, cube, b, 10.0).hit);
}

// A slow approach: the same cubes 1e-8 m apart closing at 1e-8 m/s touch at 1 s. Stopping at
// the touching distance (kSweepTouchRel of the size, 1.7e-11 m) would be 1.7e-3 s early; the
// last safe step lands on the touch. What is left is round-off: the coordinates' (1e-16 m) over
// the closing speed is 1e-8 s.
TEST(SweepTimeOfImpact, ASlowApproachTouchesOnTimeNotATolerancesWorthEarly) {
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const Sweep a{{Vec3(0.2, 0.1, 1.0 + 1e-8), Quat::Identity()}, Vec3(0, 0, -1e-8), Vec3::Zero()};
  const Sweep b{{Vec3::Zero(), Quat::Identity()}, Vec3::Zero(), Vec3::Zero()};
  const SweepImpact hit = sweep_time_of_impact(cube, a, cube, b, 2.0);
  ASSERT_TRUE(hit.hit);
  ASSERT_TRUE(hit.located);
  EXPECT_NEAR(hit.time, 1.0, 1e-7);
  EXPECT_GT(hit.normal.z(), 1 - 1e-6);
  // The same approach turning slowly about z: still never late, and now within the spin's bound.
  const Sweep turning{a.start, a.velocity, Vec3(0, 0, 1e-9)};
  const SweepImpact spun = sweep_time_of_impact(cube, turning, cube, b, 2.0);
  ASSERT_TRUE(spun.hit);
  EXPECT_LE(spun.time, 1.0 + 1e-7);
}

// A rod (half-length L = 1, half-thickness h = 0.05) along x turns about z at w; a unit cube's
// lower face is at y = 0.9, across x in [-0.5, 0.5]. The rod's corner (L, h), at radius
// R = sqrt(L^2 + h^2) and angle phi = atan(h / L), reaches y = 0.9 when R sin(wt + phi) = 0.9,
// at x = sqrt(R^2 - 0.81) = 0.439, on the face. Nothing touches before: the cube's corners lie
// beyond R from the axis, and the corner's circle crosses x = 0.5 below y = 0.9.
TEST(SweepTimeOfImpact, ATurningRodsCornerMeetsAFaceAtTheClosedFormTime) {
  const ConvexPolyhedron rod = make_box(Vec3(2.0, 0.1, 0.1));
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const double w = 2.0, radius = std::hypot(1.0, 0.05), phi = std::atan2(0.05, 1.0);
  const double t_star = (std::asin(0.9 / radius) - phi) / w;
  const Sweep a{{Vec3::Zero(), Quat::Identity()}, Vec3::Zero(), Vec3(0, 0, w)};
  const Sweep b{{Vec3(0, 1.4, 0), Quat::Identity()}, Vec3::Zero(), Vec3::Zero()};
  const SweepImpact hit = sweep_time_of_impact(rod, a, cube, b, 1.0);
  ASSERT_TRUE(hit.hit);
  ASSERT_TRUE(hit.certified);
  // The corner closes on the face at w R cos(wt + phi) = 0.88 m/s: kSweepTouchRel of the size
  // (about 1.9) over it is 2e-11 s.
  EXPECT_LE(hit.time, t_star + 1e-14);
  EXPECT_GE(hit.time, t_star - 1e-10);
  EXPECT_LT((hit.normal - Vec3(0, -1, 0)).norm(), 1e-6);  // from B (above) toward A
  EXPECT_NEAR(hit.point.x(), std::sqrt(radius * radius - 0.81), 1e-6);
}

}  // namespace
}  // namespace rbx
