#include "engine/bounding.h"

namespace rbx {

BoundingSphere bounding_sphere(const RigidBody& body) {
  const Aabb& box = body.shape->bounds();
  return {body.pose().apply(box.center()), box.half_extents().norm()};
}

bool bounding_check(const RigidBody& a, const RigidBody& b) {
  return spheres_touch(bounding_sphere(a), bounding_sphere(b));
}

}  // namespace rbx
