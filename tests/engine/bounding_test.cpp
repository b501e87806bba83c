// The seed's bounding check: sphere from a body's box centre to a corner, and the corrected
// sum-of-radii rule (seed correction 7 (bounding check on the sum of radii)).
#include "engine/bounding.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "engine/body_facts.h"
#include "engine/detect.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

// Radii and centres are a square root and a rotation of O(1) numbers: round-off ~1e-16.
constexpr double kRadiusRoundOff = 1e-12;

RigidBody body_with(const ConvexPolyhedron& shape, const Vec3& position,
                    const Quat& orientation = Quat::Identity()) {
  RigidBody b;
  b.shape = std::make_shared<const ConvexPolyhedron>(shape);
  b.position = position;
  b.orientation = orientation;
  return b;
}

TEST(BoundingSphere, RadiusIsHalfTheBoxDiagonal) {
  // Box (1, 2, 3): centre to corner = |(0.5, 1, 1.5)| = sqrt(14) / 2. The box is centred on the
  // body origin, so the sphere's centre is the body position whatever the orientation.
  const Quat q(Eigen::AngleAxisd(0.4, Vec3(1, -1, 2).normalized()));
  const RigidBody b = body_with(make_box(Vec3(1, 2, 3)), Vec3(4, -5, 6), q);
  const BoundingSphere s = bounding_sphere(b);
  EXPECT_NEAR(s.radius, std::sqrt(14.0) / 2, kRadiusRoundOff);
  EXPECT_LE((s.center - Vec3(4, -5, 6)).norm(), kRadiusRoundOff);
}

TEST(BoundingSphere, OffCentreShapeUsesItsBoxCentreInTheWorld) {
  // Unit right tetrahedron: local box [0, 1]^3, centre (1/2, 1/2, 1/2), radius sqrt(3)/2.
  // Placed by (R, p), the centre is R (1/2, 1/2, 1/2) + p.
  const ConvexPolyhedron tetra = ConvexPolyhedron::from_triangles(
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
  const Quat q(Eigen::AngleAxisd(1.1, Vec3(0, 1, 1).normalized()));
  const Vec3 p(1, 2, 3);
  const BoundingSphere s = bounding_sphere(body_with(tetra, p, q));
  EXPECT_NEAR(s.radius, std::sqrt(3.0) / 2, kRadiusRoundOff);
  EXPECT_LE((s.center - (q * Vec3(0.5, 0.5, 0.5) + p)).norm(), kRadiusRoundOff);
}

TEST(BoundingSphere, FromTheBodysFactsItIsTheSameBitForBit) {
  // The extended step places a crowd's spheres from the bodies' facts, without reading their
  // shapes: the same numbers, for a centred box and an off-centre tetrahedron, at any pose.
  const ConvexPolyhedron tetra = ConvexPolyhedron::from_triangles(
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  for (const ConvexPolyhedron& shape : {make_box(Vec3(0.3, 1.7, 0.9)), tetra}) {
    for (int k = 0; k < 200; ++k) {
      const RigidBody b =
          body_with(shape, Vec3(u(rng), u(rng), u(rng)), test::random_rotation(rng));
      const BodyFacts facts = BodyFacts::of(b);
      const BoundingSphere s = bounding_sphere(b), f = bounding_sphere(b, facts);
      EXPECT_EQ(s.center, f.center);
      EXPECT_TRUE(test::same_bits(s.radius, f.radius));
    }
  }
}

TEST(BoundingCheck, SumOfRadiiIsTheThreshold) {
  // Unit cube (r_a = sqrt(3)/2) and a (2, 2, 2) cube (r_b = sqrt(3)) along a generic direction:
  // centres r_a + r_b -+ eps apart. eps = 1e-9 (r_a + r_b) is far above the ~1e-16 round-off of
  // the centre distance, so each side of the threshold is resolved.
  const double r_a = std::sqrt(3.0) / 2, r_b = std::sqrt(3.0);
  const double eps = 1e-9 * (r_a + r_b);
  const Vec3 dir = Vec3(1, 2, -2).normalized();
  const RigidBody a = body_with(make_box(Vec3(1, 1, 1)), Vec3(0.5, 0.25, 0));
  const RigidBody inside = body_with(make_box(Vec3(2, 2, 2)), a.position + (r_a + r_b - eps) * dir);
  const RigidBody outside =
      body_with(make_box(Vec3(2, 2, 2)), a.position + (r_a + r_b + eps) * dir);
  EXPECT_TRUE(bounding_check(a, inside));
  EXPECT_TRUE(bounding_check(inside, a));
  EXPECT_FALSE(bounding_check(a, outside));
  EXPECT_FALSE(bounding_check(outside, a));
}

TEST(BoundingCheck, LiteralLessThanBothRadiiMissesOverlappingBoxes) {
  // seed correction 7 (bounding check on the sum of radii). Two unit cubes whose centres are 0.9
  // apart along x overlap by 0.1 (the detector sees it), but 0.9 > r = sqrt(3)/2 = 0.866: the
  // seed's "distance less than both radii" drops the pair; the sum rule (0.9 <= 1.732) keeps it.
  const ConvexPolyhedron cube = make_box(Vec3(1, 1, 1));
  const RigidBody a = body_with(cube, Vec3(0, 0, 0));
  const RigidBody b = body_with(cube, Vec3(0.9, 0, 0));
  const BoundingSphere sa = bounding_sphere(a), sb = bounding_sphere(b);
  const double d = (sa.center - sb.center).norm();
  const bool literal = d < sa.radius && d < sb.radius;
  EXPECT_FALSE(literal);
  EXPECT_TRUE(bounding_check(a, b));
  EXPECT_TRUE(detect(cube, a.pose(), cube, b.pose()).has_value());
}

TEST(BoundingCheck, NeverRejectsATouchingPair) {
  // The sphere contains the body, so any pair the detector sees must pass the check. Random
  // poses (fixed seed) of two boxes with centres up to 3 m apart, where about half touch.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const ConvexPolyhedron long_box = make_box(Vec3(2.0, 0.4, 0.6));
  const ConvexPolyhedron cube = make_box(Vec3(0.8, 0.8, 0.8));
  int touching = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const RigidBody a =
        body_with(long_box, Vec3::Zero(), Quat(u(rng), u(rng), u(rng), u(rng)).normalized());
    const RigidBody b = body_with(cube, 1.5 * Vec3(u(rng), u(rng), u(rng)),
                                  Quat(u(rng), u(rng), u(rng), u(rng)).normalized());
    if (!detect(long_box, a.pose(), cube, b.pose()).has_value()) continue;
    ++touching;
    EXPECT_TRUE(bounding_check(a, b)) << "trial " << trial;
  }
  EXPECT_GT(touching, 30);  // the sample does exercise the check
}

}  // namespace
}  // namespace rbx
