#include "reference/ode.h"

namespace rbx {
ContactResult ode_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
DynamicsResult ode_dynamics(const Scene&, const DynamicsOptions&) { DynamicsResult r; r.status = Status::Unsupported; r.message = "not built yet"; return r; }
}  // namespace rbx
