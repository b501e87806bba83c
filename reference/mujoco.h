// MuJoCo 2.2.2: box geoms (dynamics) or meshes with multi-point collision (`mujoco`), or one
// mesh geom per hull (`mujoco-hull`); contacts from mj_forward, stepping with restitution mapped
// to a negative solref.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// How bodies become MuJoCo geoms. Every field's choice is measured against its alternatives in
/// tests/reference/fair_settings_test.cpp.
struct MujocoSettings {
  bool box_geoms = true;              // box geoms when every body is a box (all pairs box-box)
  double box_stiffness_factor = 2.0;  // dynamics with box geoms: makes up for the halved depth
  bool multiccd = true;               // mesh pairs: multi-point convex collision
};

/// `mujoco-hull`: every body a mesh geom, single-point MPR.
MujocoSettings mujoco_hull_settings();

/// `mujoco`: contacts from mj_forward on mesh geoms with multiccd (boxes too: MuJoCo 2.2.2's box
/// geoms report half the depth).
ContactResult mujoco_contact(const RigidBody& a, const RigidBody& b);
/// `mujoco-hull`: contacts of mesh geoms from mj_forward.
ContactResult mujoco_hull_contact(const RigidBody& a, const RigidBody& b);
/// `mujoco` and `mujoco-hull` with the pair's model compiled once and kept (reference/
/// prebuilt_cache.h), each query setting the poses and running mj_forward: variant "prebuilt".
ContactResult mujoco_contact_prebuilt(const RigidBody& a, const RigidBody& b);
ContactResult mujoco_hull_contact_prebuilt(const RigidBody& a, const RigidBody& b);
/// The contact query with explicit settings.
ContactResult mujoco_contact_with(const RigidBody& a, const RigidBody& b,
                                  const MujocoSettings& settings);
/// `mujoco` mass: MuJoCo's own inertia of a box geom for a box body (inertiafromgeom), of the
/// hull mesh otherwise.
MassResult mujoco_mass(const RigidBody& body);
/// `mujoco-hull` mass: a free body with one mesh geom of the body's mass, compiled with
/// inertiafromgeom; body_mass, body_ipos and body_inertia/body_iquat read back.
MassResult mujoco_hull_mass(const RigidBody& body);
/// `mujoco` dynamics: mj_step with e mapped to solref, native geoms.
DynamicsResult mujoco_dynamics(const Scene& scene, const DynamicsOptions& opt);
/// `mujoco-hull` dynamics: the same on mesh geoms.
DynamicsResult mujoco_hull_dynamics(const Scene& scene, const DynamicsOptions& opt);
/// The dynamics run with explicit settings.
DynamicsResult mujoco_dynamics_with(const Scene& scene, const DynamicsOptions& opt,
                                    const MujocoSettings& settings);

}  // namespace rbx
