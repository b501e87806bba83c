#include "reference/fcl.h"

namespace rbx {
ContactResult fcl_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
ContactResult fcl_epa_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
ContactResult fcl_indep_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
ContactResult fcl_box_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
}  // namespace rbx
