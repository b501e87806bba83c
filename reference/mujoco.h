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
  bool elliptic_cone = true;          // friction: elliptic cone (false: MuJoCo's default pyramid)
  double impratio = 1.0;              // frictional-to-normal impedance ratio (MuJoCo's default)
  int noslip_iterations = 0;          // noslip passes after the main solve (0: MuJoCo's default)
  // Soft-contact duration: an undamped contact lasts this many steps (solref's time constant,
  // as a multiple of dt; the damping then follows from the scene's restitution).
  double contact_steps = 25.0;
  // Constant impedance d for contacts (solimp dmin = dmax): MuJoCo's largest, 1 - 1e-4, unless a
  // fit sets it. Then the solver's acceleration is the reference acceleration to within 1e-4,
  // whatever its diagonal approximation, which the restitution map assumes
  // (restitution_damping_ratio); below it a share 1 - d of the unconstrained acceleration
  // (gravity) leaks through the contact.
  double impedance = 0.9999;
};

/// `mujoco-hull`: every body a mesh geom, single-point MPR.
MujocoSettings mujoco_hull_settings();

/// MuJoCo's backends: `mujoco` (box geoms for two boxes, mesh geoms with multiccd otherwise;
/// mj_step with e mapped to a negative solref) and `mujoco-hull` (one mesh geom per hull, MPR,
/// one point), each with its "prebuilt" variant and MuJoCo's own mass properties.
const Adapter& mujoco_adapter();

/// MuJoCo's contact query and dynamics run at explicit settings.
const AtSettings<MujocoSettings>& mujoco_at_settings();

}  // namespace rbx
