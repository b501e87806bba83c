#include "reference/mujoco.h"

namespace rbx {
ContactResult mujoco_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
DynamicsResult mujoco_dynamics(const Scene&, const DynamicsOptions&) { DynamicsResult r; r.status = Status::Unsupported; r.message = "not built yet"; return r; }
}  // namespace rbx
