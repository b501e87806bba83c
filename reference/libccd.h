// libccd 2.1 called directly: MPR and GJK + EPA, each its own backend, on libccd's documented box
// support for boxes and the hull's vertex support otherwise (reference/libccd.cpp).
#pragma once

#include "reference/backend.h"

namespace rbx {

/// libccd's backends, contact queries only: `libccd-mpr` (ccdMPRPenetration, feature "mpr") and
/// `libccd-epa` (ccdGJKPenetration, GJK then EPA, feature "gjk-epa"), one contact each.
const Adapter& libccd_adapter();

}  // namespace rbx
