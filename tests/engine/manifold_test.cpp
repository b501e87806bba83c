// Contact manifolds: every contact point of a pair, one normal.
#include "engine/manifold.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "engine/detect.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::at;
using test::random_rotation;

TEST(Manifold, FaceLandingHasTheFourCorners) {
  // A unit cube 1 mm into a 4 x 4 x 1 slab: the four base corners, each 1 mm deep, normal +z,
  // placed midway between the cube's base (z = -0.001) and the slab's top (z = 0), as the
  // oracle's patch is (docs/contact_manifold.md).
  const ConvexPolyhedron cube = make_box(Vec3::Ones()), slab = make_box(Vec3(4, 4, 1));
  const auto m =
      build_manifold(cube, at(Vec3(0, 0, 0.499)), slab, at(Vec3(0, 0, -0.5)), Detector::Faithful);
  ASSERT_TRUE(m);
  EXPECT_NEAR((m->normal - Vec3::UnitZ()).norm(), 0.0, 1e-12);
  ASSERT_EQ(m->points.size(), 4u);
  for (const ManifoldPoint& p : m->points) {
    EXPECT_NEAR(std::abs(p.point.x()), 0.5, 1e-12);
    EXPECT_NEAR(std::abs(p.point.y()), 0.5, 1e-12);
    EXPECT_NEAR(p.point.z(), -0.0005, 1e-12);
    EXPECT_NEAR(p.depth, 0.001, 1e-12);
  }
}

TEST(Manifold, CornerLandingIsOnePointAtTheVertex) {
  // Cube turned so that one corner points down, 1 mm into the slab: its three faces there are
  // equally against the slab, so the incident feature is the vertex they share, placed midway
  // between it (z = -0.001) and the slab's top.
  const Quat q = Quat(Eigen::AngleAxisd(std::atan(std::sqrt(2.0)), Vec3(1, -1, 0).normalized()));
  const ConvexPolyhedron cube = make_box(Vec3::Ones()), slab = make_box(Vec3(4, 4, 1));
  const double half_diagonal = std::sqrt(3.0) / 2;
  const Pose pa = at(Vec3(0, 0, half_diagonal - 0.001), q), pb = at(Vec3(0, 0, -0.5));
  const auto m = build_manifold(cube, pa, slab, pb, Detector::Faithful);
  ASSERT_TRUE(m);
  ASSERT_EQ(m->points.size(), 1u);
  EXPECT_NEAR(m->points[0].point.norm(), 0.0005, 1e-9);
  EXPECT_NEAR(m->points[0].depth, 0.001, 1e-9);
}

TEST(Manifold, CrossedEdgesGiveTheirCrossing) {
  // Two bars turned 45 deg about their long axes, crossed (x over y), edges 0.05 m into each
  // other: no vertex inside, one point where the edges cross, the origin.
  const ConvexPolyhedron bar_x = make_box(Vec3(4, 0.2, 0.2)), bar_y = make_box(Vec3(0.2, 4, 0.2));
  const double h = 0.1 * std::sqrt(2.0);
  const Pose pa = at(Vec3(0, 0, h - 0.025), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX())));
  const Pose pb = at(Vec3(0, 0, -h + 0.025), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY())));
  const auto m = build_manifold(bar_x, pa, bar_y, pb, Detector::Faithful);
  ASSERT_TRUE(m);
  ASSERT_EQ(m->points.size(), 1u);
  EXPECT_NEAR(m->points[0].point.norm(), 0.0, 1e-12);
  EXPECT_NEAR(m->points[0].depth, 0.05, 1e-12);
  EXPECT_NEAR(std::abs(m->normal.z()), 1.0, 1e-12);
}

TEST(Manifold, ACubeTurnedAMicroradianKeepsTheFourCornersOfItsFace) {
  // A unit cube turned 1e-6 rad about z, 1 mm into another: the region is an octagon whose
  // corners come in pairs ~5e-7 m apart; within the slack (1e-4 of the size) of the line through
  // their neighbours, one of each pair goes, and the four left are the square's corners to 1e-6.
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const Pose pa = at(Vec3(0, 0, 0.999), Quat(Eigen::AngleAxisd(1e-6, Vec3::UnitZ())));
  const auto m = build_manifold(cube, pa, cube, at(Vec3::Zero()), Detector::Faithful);
  ASSERT_TRUE(m);
  ASSERT_EQ(m->points.size(), 4u);
  for (const ManifoldPoint& p : m->points) {
    EXPECT_NEAR(std::abs(p.point.x()), 0.5, 1e-6);
    EXPECT_NEAR(std::abs(p.point.y()), 0.5, 1e-6);
  }
  // With no slack the octagon's eight corners stay.
  EXPECT_EQ(
      build_manifold(cube, pa, cube, at(Vec3::Zero()), Detector::Faithful, 0.0)->points.size(), 8u);
}

TEST(Manifold, ACubeTurned45DegreesKeepsItsOctagon) {
  // Turned 45 deg, the octagon is the region itself: no corner is near its neighbours' line.
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const Pose pa = at(Vec3(0, 0, 0.999), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ())));
  const auto m = build_manifold(cube, pa, cube, at(Vec3::Zero()), Detector::Faithful);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->points.size(), 8u);
}

TEST(Manifold, ADeepCornerIsItsVertexAndTiltedTheCornersOfItsFaceBelowTheSlab) {
  // A unit cube corner-down, its centre 0.1 m above a slab's top face: its lowest corner is
  // 0.766 m deep and the three next to it 0.189 m. Its three faces there are equally against
  // the slab: the patch is the vertex they share, as deep as the shapes overlap. Tilted by
  // 0.01 rad, one face is most against the slab, and the patch is that face's corners below
  // the slab's top: the lowest corner and its two neighbours on that face (the fourth is
  // 0.389 m above), each with its own depth.
  const Quat q = Quat(Eigen::AngleAxisd(std::atan(std::sqrt(2.0)), Vec3(1, -1, 0).normalized()));
  const ConvexPolyhedron cube = make_box(Vec3::Ones()), slab = make_box(Vec3(4, 4, 1));
  const Pose pb = at(Vec3(0, 0, -0.5));
  const auto even = build_manifold(cube, at(Vec3(0, 0, 0.1), q), slab, pb, Detector::Faithful);
  ASSERT_TRUE(even);
  EXPECT_NEAR(std::abs(even->normal.z()), 1.0, 1e-12);
  ASSERT_EQ(even->points.size(), 1u);
  EXPECT_NEAR(even->points[0].depth, std::sqrt(3.0) / 2 - 0.1, 1e-12);
  const Quat tilt(Eigen::AngleAxisd(0.01, Vec3::UnitX()));
  const Pose pa = at(Vec3(0, 0, 0.1), tilt * q);
  const auto tilted = build_manifold(cube, pa, slab, pb, Detector::Faithful);
  ASSERT_TRUE(tilted);
  ASSERT_EQ(tilted->points.size(), 3u);
  double deepest = 0.0;
  for (const ManifoldPoint& p : tilted->points) {
    // Each point midway between the cube's corner it comes from and the slab's top: the
    // corner's depth is twice the point's distance below the top.
    EXPECT_NEAR(p.depth, -2.0 * p.point.z(), 1e-12);
    deepest = std::max(deepest, p.depth);
    double nearest = 1.0;  // the distance across the normal to the nearest corner of the cube
    for (const Vec3& v : cube.vertices())
      nearest = std::min(nearest, (pa.apply(v) - p.point).head<2>().norm());
    EXPECT_LE(nearest, 1e-12);
  }
  double lowest = 0.0;
  for (const Vec3& v : cube.vertices()) lowest = std::min(lowest, pa.apply(v).z());
  EXPECT_NEAR(deepest, -lowest, 1e-12);
}

TEST(Manifold, ARoundBodyOnAVertexIsThatVertex) {
  // An icosphere (radius 0.5, two subdivisions) with a vertex straight down, 0.1 m into a slab:
  // many vertices are inside, but the five triangles around the lowest one are equally against
  // the slab, so the patch is the vertex they share (the oracle's patch, the points where the
  // shapes still touch once pushed apart): one point, as deep as the shapes overlap.
  const ConvexPolyhedron ball = make_icosphere(0.5, 2), slab = make_box(Vec3(4, 4, 1));
  const Vec3 down = Vec3(0, 1, -(1 + std::sqrt(5.0)) / 2).normalized();  // a vertex's direction
  const Quat q = Quat::FromTwoVectors(down, -Vec3::UnitZ());
  const Pose pa = at(Vec3(0, 0, 0.4), q), pb = at(Vec3(0, 0, -0.5));
  int inside = 0;
  for (const Vec3& v : ball.vertices()) inside += pa.apply(v).z() < 0.0 ? 1 : 0;
  const auto m = build_manifold(ball, pa, slab, pb, Detector::Faithful);
  ASSERT_TRUE(m);
  EXPECT_GT(inside, 1);
  ASSERT_EQ(m->points.size(), 1u);
  EXPECT_NEAR(m->points[0].depth, 0.1, 1e-12);
  EXPECT_NEAR(m->points[0].point.head<2>().norm(), 0.0, 1e-12);
}

TEST(Manifold, NothingWhenApart) {
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  EXPECT_FALSE(
      build_manifold(cube, at(Vec3(0, 0, 1.01)), cube, at(Vec3::Zero()), Detector::Faithful));
}

TEST(Manifold, EitherBodyOrderGivesTheSamePointsWithTheNormalReversed) {
  // 1,000 random pairs (boxes of several proportions, a prism, an icosphere; centres 0 to 1.2
  // apart, so most touch, some deeply): the same points from (A, B) and from (B, A), to
  // round-off of the poses' products (1e-9 of the larger shape), and the normal reversed. What
  // broke it before: equally deep points taken in the order found, the detector's first hit
  // where no point qualified, and the plane's frame flipping with the normal, so that
  // near-coincident corners sorted differently.
  const std::vector<ConvexPolyhedron> shapes = {
      make_box(Vec3(1.0, 0.6, 0.3)), make_box(Vec3::Ones()), make_prism(0.4, 1.2, 7),
      make_icosphere(0.5, 2), make_box(Vec3(2.0, 2.0, 0.5))};
  std::mt19937 rng(5150);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(shapes.size()) - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  DetectionCache cache;
  ContactScratch scratch;
  int compared = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const ConvexPolyhedron& a = shapes[pick(rng)];
    const ConvexPolyhedron& b = shapes[pick(rng)];
    const Pose pa{random_rotation(rng) * Vec3::UnitX() * unit(rng) * 1.2, random_rotation(rng)};
    const Pose pb{Vec3::Zero(), random_rotation(rng)};
    const double slop = WorldSettings{}.position_slop;
    const auto ab = build_manifold(a, pa, b, pb, Detector::Accelerated, slop, cache, scratch);
    const auto ba = build_manifold(b, pb, a, pa, Detector::Accelerated, slop, cache, scratch);
    ASSERT_EQ(ab.has_value(), ba.has_value()) << "trial " << trial;
    if (!ab) continue;
    ++compared;
    EXPECT_LE((ab->normal + ba->normal).norm(), 1e-12) << "trial " << trial;
    ASSERT_EQ(ab->points.size(), ba->points.size()) << "trial " << trial;
    const double tol = 1e-9 * std::max(shape_size(a), shape_size(b));
    for (const ManifoldPoint& p : ab->points) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const ManifoldPoint& q : ba->points)
        nearest = std::min(nearest, (p.point - q.point).norm());
      EXPECT_LE(nearest, tol) << "trial " << trial;
    }
  }
  EXPECT_GT(compared, 500);
}

}  // namespace
}  // namespace rbx
