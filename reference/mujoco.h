// MuJoCo 2.2.2: mesh geoms (convex hull), contacts from mj_forward, stepping with restitution mapped to a negative solref.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// `mujoco`: contacts of mesh geoms from mj_forward.
ContactResult mujoco_contact(const RigidBody& a, const RigidBody& b);
/// MuJoCo's own mesh inertia: a free body with one mesh geom of the body's mass, compiled with
/// inertiafromgeom; body_mass, body_ipos and body_inertia/body_iquat read back.
MassResult mujoco_mass(const RigidBody& body);
/// `mujoco` dynamics: mj_step with e mapped to solref.
DynamicsResult mujoco_dynamics(const Scene& scene, const DynamicsOptions& opt);

}  // namespace rbx
