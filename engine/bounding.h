// The seed's bounding check: a sphere around each body's box, centre to corner.
#pragma once

#include "engine/body.h"

namespace rbx {

/// Sphere through the corners of the body's local bounding box, placed in the world.
struct BoundingSphere {
  Vec3 center = Vec3::Zero();  // m, world
  double radius = 0.0;         // m, centre-to-corner distance of the box
};

/// The bounding sphere of a body at its current pose.
BoundingSphere bounding_sphere(const RigidBody& body);

/// The seed's test on two spheres (seed correction 7): |c_a - c_b| <= r_a + r_b.
inline bool spheres_touch(const BoundingSphere& a, const BoundingSphere& b) {
  return (a.center - b.center).norm() <= a.radius + b.radius;
}

/// seed correction 7 (bounding check on the sum of radii): two bodies may touch only if |c_a - c_b|
/// <= r_a + r_b. (The seed compares with each radius alone, "less than both", which misses pairs.)
bool bounding_check(const RigidBody& a, const RigidBody& b);

}  // namespace rbx
