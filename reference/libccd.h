// libccd 2.1 called directly on our support function: MPR and GJK + EPA.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// `libccd`: contacts[0] from ccdMPRPenetration (feature "mpr"), contacts[1] from
/// ccdGJKPenetration (feature "gjk-epa").
ContactResult libccd_contact(const RigidBody& a, const RigidBody& b);

}  // namespace rbx
