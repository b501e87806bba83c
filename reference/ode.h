// ODE 0.16.2: dCreateBox for boxes and dCreateConvex otherwise (`ode`), or dCreateConvex for
// every body (`ode-hull`); dCollide, and dWorldStep with bounce = e.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// How bodies become ODE geoms and how the world is set up. Every field's choice is measured
/// against its alternatives in tests/reference/fair_settings_test.cpp.
struct OdeSettings {
  bool native_boxes = true;  // dCreateBox for is_native_box bodies; false: every body convex
  double cfm = 1e-10;        // world constraint force mixing (ODE's default)
  double erp = 0.2;          // world error reduction parameter (ODE's default)
};

/// `ode-hull`: every body a dCreateConvex geom, ODE's default world.
OdeSettings ode_hull_settings();

/// `ode`: dCollide on dCreateBox geoms for boxes (dBoxBox), dCreateConvex otherwise.
ContactResult ode_contact(const RigidBody& a, const RigidBody& b);
/// `ode-hull`: dCollide on dCreateConvex geoms (libccd MPR in Debian's build, one point).
ContactResult ode_hull_contact(const RigidBody& a, const RigidBody& b);
/// `ode` and `ode-hull` with each shape's geom built once and kept (reference/prebuilt_cache.h),
/// placed at each query: variant "prebuilt".
ContactResult ode_contact_prebuilt(const RigidBody& a, const RigidBody& b);
ContactResult ode_hull_contact_prebuilt(const RigidBody& a, const RigidBody& b);
/// `ode` dynamics: dWorldStep with dContactBounce on the native geoms.
DynamicsResult ode_dynamics(const Scene& scene, const DynamicsOptions& opt);
/// `ode-hull` dynamics: the same world on convex geoms.
DynamicsResult ode_hull_dynamics(const Scene& scene, const DynamicsOptions& opt);
/// The dynamics run with explicit settings.
DynamicsResult ode_dynamics_with(const Scene& scene, const DynamicsOptions& opt,
                                 const OdeSettings& settings);

}  // namespace rbx
