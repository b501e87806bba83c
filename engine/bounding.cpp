#include "engine/bounding.h"

namespace rbx {

BoundingSphere bounding_sphere(const RigidBody& body) {
  const Aabb& box = body.shape->bounds();
  return {body.pose().apply(box.center()), box.half_extents().norm()};
}

bool bounding_check(const RigidBody& a, const RigidBody& b) {
  const BoundingSphere sa = bounding_sphere(a), sb = bounding_sphere(b);
  return (sa.center - sb.center).norm() <= sa.radius + sb.radius;
}

}  // namespace rbx
