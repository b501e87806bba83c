// Small helpers to build bodies by hand in engine tests.
#pragma once

#include <memory>

#include "engine/body.h"
#include "engine/polyhedron.h"

namespace rbx::test {

/// A box body with the given full extents, mass, pose and velocities (solid mass model).
inline RigidBody box_body(const std::string& name, const Vec3& size, double mass,
                          const Vec3& position, const Quat& orientation = Quat::Identity(),
                          const Vec3& velocity = Vec3::Zero(),
                          const Vec3& angular_velocity = Vec3::Zero(), bool is_static = false) {
  BodySpec spec;
  spec.name = name;
  spec.shape = std::make_shared<const ConvexPolyhedron>(make_box(size));
  spec.box_size = size;
  spec.mass = mass;
  spec.position = position;
  spec.orientation = orientation;
  spec.velocity = velocity;
  spec.angular_velocity = angular_velocity;
  spec.is_static = is_static;
  return make_body(spec);
}

}  // namespace rbx::test
