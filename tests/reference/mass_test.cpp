// Each library's own mass properties of a hull, against closed forms: what FCL, Bullet and
// MuJoCo compute by themselves (the report shows them; runs are always given the exact values).
#include <gtest/gtest.h>

#include <memory>

#include "reference/bullet.h"
#include "reference/fcl.h"
#include "reference/mujoco.h"

namespace rbx {
namespace {

// The backends under test, by their registry names.
const Backend& bullet_hull_mass = bullet_adapter().backend("bullet-hull");
const Backend& fcl_hull_mass = fcl_adapter().backend("fcl-hull");
const Backend& mujoco_hull_mass = mujoco_adapter().backend("mujoco-hull");

RigidBody box_body(const Vec3& size, double mass) {
  BodySpec spec;
  spec.name = "A";
  spec.shape = std::make_shared<const ConvexPolyhedron>(make_box(size));
  spec.box_size = size;
  spec.mass = mass;
  return make_body(spec);
}

// Solid box a x b x c of mass m: I = m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2).
Mat3 box_inertia(const Vec3& s, double m) {
  return Vec3(m / 12 * (s.y() * s.y() + s.z() * s.z()), m / 12 * (s.x() * s.x() + s.z() * s.z()),
              m / 12 * (s.x() * s.x() + s.y() * s.y()))
      .asDiagonal();
}

TEST(LibraryMass, MujocoMeshInertiaIsExact) {
  // MuJoCo integrates the mesh volume: exact up to its float vertices (relative 1e-7).
  const Vec3 size(1, 2, 3);
  const MassResult r = mujoco_hull_mass.mass(box_body(size, 6));
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  EXPECT_NEAR(r.mass, 6, 1e-12);
  EXPECT_LT(r.center_of_mass.norm(), 1e-6);
  EXPECT_LT((r.inertia - box_inertia(size, 6)).norm(), 1e-6 * box_inertia(size, 6).norm());
}

TEST(LibraryMass, FclConvexInertiaIsPerUnitMassNotPerUnitDensity) {
  // Pinned defect of FCL 0.7: Convex::computeMomentofInertia divides by the volume, so under
  // the unit-density convention of Box and of the parallel-axis shift the result is I / V.
  // Box 1 x 2 x 3 (V = 6) of 6 kg: density 1, so the adapter's scaling is 1 and FCL gives I/6.
  const Vec3 size(1, 2, 3);
  const MassResult r = fcl_hull_mass.mass(box_body(size, 6));
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  EXPECT_NEAR(r.volume, 6, 1e-12);  // volume and centre of mass are right
  EXPECT_LT(r.center_of_mass.norm(), 1e-12);
  EXPECT_LT((r.inertia - box_inertia(size, 6) / 6.0).norm(), 1e-12);
}

TEST(LibraryMass, BulletHullInertiaIsTheMarginInflatedBoundingBox) {
  // calculateLocalInertia: the box inertia of an AABB about the shape origin, the margin
  // k = 0.04 m added three times to each half extent (the hull's cached AABB is built from
  // support points with margin, getAabb adds the margin, the routine adds it again): full
  // extents size + 6k, I = m/12 ((b+6k)^2 + (c+6k)^2), ...
  const Vec3 size(1, 2, 3);
  const MassResult r = bullet_hull_mass.mass(box_body(size, 6));
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  const Vec3 grown = size + Vec3::Constant(6 * 0.04);
  // Bullet writes 1/12 as 0.08333333 (relative error 4e-8): 1e-7 relative.
  EXPECT_LT((r.inertia - box_inertia(grown, 6)).norm(), 1e-7 * box_inertia(size, 6).norm());
  EXPECT_GT((r.inertia - box_inertia(size, 6)).norm(), 0.05 * box_inertia(size, 6).norm());
}

}  // namespace
}  // namespace rbx
