#include "engine/body.h"

namespace rbx {

Mat3 RigidBody::inverse_inertia_world() const {
  const Mat3 r = orientation.toRotationMatrix();
  return r * inverse_inertia_body * r.transpose();
}

Mat3 RigidBody::inertia_world() const {
  const Mat3 r = orientation.toRotationMatrix();
  return r * inertia_body * r.transpose();
}

double RigidBody::kinetic_energy() const {
  if (is_static) return 0.0;
  // w . (R I R^T w) = (R^T w) . I (R^T w): one rotation of a vector, no world-frame matrix.
  const Vec3 w_body = orientation.conjugate() * angular_velocity;
  return 0.5 * mass * velocity.squaredNorm() + 0.5 * w_body.dot(inertia_body * w_body);
}

Vec3 RigidBody::linear_momentum() const { return is_static ? Vec3::Zero() : Vec3(mass * velocity); }

Vec3 RigidBody::angular_momentum() const {
  if (is_static) return Vec3::Zero();
  return position.cross(mass * velocity) + inertia_world() * angular_velocity;
}

RigidBody make_body(const BodySpec& spec) {
  RigidBody b;
  b.name = spec.name;
  b.shape_kind = spec.shape_kind;
  b.box_size = spec.box_size;
  b.is_static = spec.is_static;
  const MassProperties mp = mass_properties(*spec.shape, spec.mass, spec.mass_model);
  b.shape = std::make_shared<const ConvexPolyhedron>(spec.shape->translated(-mp.center_of_mass));
  b.shape_origin_offset = -mp.center_of_mass;
  b.mass = mp.mass;
  b.inertia_body = spec.inertia ? *spec.inertia : mp.inertia;
  if (spec.is_static) {
    // seed correction 5 (world-frame inverse inertia, static bodies zero): static bodies have zero
    // inverse mass and inverse inertia.
    b.inverse_mass = 0.0;
    b.inverse_inertia_body.setZero();
  } else {
    b.inverse_mass = 1.0 / mp.mass;
    b.inverse_inertia_body = b.inertia_body.inverse();
  }
  b.orientation = spec.orientation.normalized();
  b.position = spec.position + b.orientation * mp.center_of_mass;
  b.velocity = spec.is_static ? Vec3::Zero() : spec.velocity;
  b.angular_velocity = spec.is_static ? Vec3::Zero() : spec.angular_velocity;
  return b;
}

}  // namespace rbx
