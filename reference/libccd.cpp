#include "reference/libccd.h"

namespace rbx {
ContactResult libccd_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
}  // namespace rbx
