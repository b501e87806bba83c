#include "reference/custom.h"
namespace rbx {
ContactResult custom_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
ContactResult custom_seed_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
DynamicsResult custom_dynamics(const Scene&, const DynamicsOptions&) { return {}; }
}  // namespace rbx
