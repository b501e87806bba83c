// A rigid body: shape, mass properties and state.
#pragma once

#include <memory>
#include <string>

#include "engine/mass_properties.h"
#include "engine/polyhedron.h"
#include "engine/world_definition.h"

namespace rbx {

/// A rigid body. The shape is stored in the body frame, whose origin is the centre of mass, so
/// the pose (position, orientation) is that of the centre of mass.
struct RigidBody {
  std::string name;
  ShapeKind shape_kind = ShapeKind::Box;
  Vec3 box_size = Vec3::Ones();                   // m, full extents (box only)
  std::shared_ptr<const ConvexPolyhedron> shape;  // body frame: centre of mass at the origin
  Vec3 shape_origin_offset = Vec3::Zero();        // m, the scene's local origin in the body frame
  bool is_static = false;

  double mass = 1.0;                             // kg (a static body keeps its nominal mass)
  Mat3 inertia_body = Mat3::Identity();          // kg m^2, about the centre of mass, body axes
  double inverse_mass = 1.0;                     // 1/kg; 0 when static
  Mat3 inverse_inertia_body = Mat3::Identity();  // body axes; 0 when static

  Vec3 position = Vec3::Zero();          // m, centre of mass, world
  Quat orientation = Quat::Identity();   // body to world, unit
  Vec3 velocity = Vec3::Zero();          // m/s, centre of mass, world
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, world frame

  /// Pose of the body frame (centre of mass) in the world.
  Pose pose() const { return {position, orientation}; }
  /// World-frame inverse inertia R I^-1 R^T (seed correction 5 (world-frame inverse inertia, static
  /// bodies zero)).
  Mat3 inverse_inertia_world() const;
  /// World-frame inertia R I R^T.
  Mat3 inertia_world() const;
  /// Kinetic energy (J): translational plus rotational. Zero for static bodies.
  double kinetic_energy() const;
  /// Linear momentum (kg m/s). Zero for static bodies.
  Vec3 linear_momentum() const;
  /// Angular momentum about the world origin (kg m^2/s). Zero for static bodies.
  Vec3 angular_momentum() const;
  /// World position of vertex i.
  Vec3 world_vertex(int i) const { return orientation * shape->vertices()[i] + position; }
};

/// Builds a body from its scene specification: mass properties by the spec's model, the shape
/// re-centred on the centre of mass, and the initial state.
RigidBody make_body(const BodySpec& spec);

}  // namespace rbx
