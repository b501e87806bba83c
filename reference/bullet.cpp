#include "reference/bullet.h"

namespace rbx {
ContactResult bullet_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
ContactResult bullet_sat_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
DynamicsResult bullet_dynamics(const Scene&, const DynamicsOptions&) { DynamicsResult r; r.status = Status::Unsupported; r.message = "not built yet"; return r; }
}  // namespace rbx
