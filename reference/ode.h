// ODE 0.16.2: dCreateConvex geoms, dCollide, and dWorldStep with bounce = e, mu = 0.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// `ode`: dCollide on dCreateConvex geoms.
ContactResult ode_contact(const RigidBody& a, const RigidBody& b);
/// `ode` dynamics: dWorldStep with dContactBounce.
DynamicsResult ode_dynamics(const Scene& scene, const DynamicsOptions& opt);

}  // namespace rbx
