// FCL 0.7 adapters: native Box or Convex (`fcl`), every body a Convex with libccd MPR
// (`fcl-hull`), signed distance (GJK + EPA), Convex with GST_INDEP.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// FCL's backends: `fcl` (fcl::collide, GST_LIBCCD, on fcl::Box for box bodies and Convex
/// otherwise), `fcl-hull` (every body a Convex, libccd MPR), `fcl-epa` (signed distance, GJK +
/// EPA) and `fcl-indep` (Convex with GST_INDEP, defects shown as they are); `fcl` and
/// `fcl-hull` with their "prebuilt" variants and FCL's own mass properties.
const Adapter& fcl_adapter();

}  // namespace rbx
