// libccd 2.1 called directly on our support function: MPR and GJK + EPA, each its own backend.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// `libccd-mpr`: one contact from ccdMPRPenetration (feature "mpr").
ContactResult libccd_mpr_contact(const RigidBody& a, const RigidBody& b);
/// `libccd-epa`: one contact from ccdGJKPenetration, GJK then EPA (feature "gjk-epa").
ContactResult libccd_epa_contact(const RigidBody& a, const RigidBody& b);

}  // namespace rbx
