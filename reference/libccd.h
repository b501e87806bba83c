// libccd 2.1 called directly: MPR and GJK + EPA, each its own backend, on libccd's documented box
// support for boxes and the hull's vertex support otherwise (reference/libccd.cpp).
#pragma once

#include "reference/backend.h"

namespace rbx {

/// `libccd-mpr`: one contact from ccdMPRPenetration (feature "mpr").
ContactResult libccd_mpr_contact(const RigidBody& a, const RigidBody& b);
/// `libccd-epa`: one contact from ccdGJKPenetration, GJK then EPA (feature "gjk-epa").
ContactResult libccd_epa_contact(const RigidBody& a, const RigidBody& b);

}  // namespace rbx
