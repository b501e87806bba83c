// Bullet 3.24 (double precision): zero-margin convex hulls, GJK + EPA and polyhedral clipping, and btDiscreteDynamicsWorld as a fair single-impulse reference.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// `bullet`: btConvexHullShape (margin 0) pair through GJK + EPA.
ContactResult bullet_contact(const RigidBody& a, const RigidBody& b);
/// `bullet-sat`: the same hulls with initializePolyhedralFeatures (SAT + clipping).
ContactResult bullet_sat_contact(const RigidBody& a, const RigidBody& b);
/// Bullet's own btConvexHullShape::calculateLocalInertia with its default margin (0.04 m): the
/// inertia of the bounding box about the shape origin, each extent grown by 6 margins (the
/// cached AABB, getAabb and the routine each add one on both sides); no centre of mass.
MassResult bullet_mass(const RigidBody& body);
/// `bullet` dynamics: btDiscreteDynamicsWorld with the fair settings of REFERENCES.md.
DynamicsResult bullet_dynamics(const Scene& scene, const DynamicsOptions& opt);
/// The same world with Bullet's default settings (kept to pin the known defects they cause).
DynamicsResult bullet_dynamics_default_world(const Scene& scene, const DynamicsOptions& opt);

}  // namespace rbx
