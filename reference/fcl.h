// FCL 0.7 adapters: native Box or Convex (`fcl`), every body a Convex with libccd MPR
// (`fcl-hull`), signed distance (GJK + EPA), Convex with GST_INDEP.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// `fcl`: fcl::collide, GST_LIBCCD, on fcl::Box for box bodies and Convex otherwise (two boxes:
/// boxBoxIntersect, up to 4 points; otherwise libccd MPR).
ContactResult fcl_contact(const RigidBody& a, const RigidBody& b);
/// `fcl-hull`: fcl::collide on Convex shapes with GST_LIBCCD (libccd MPR), boxes included.
ContactResult fcl_hull_contact(const RigidBody& a, const RigidBody& b);
/// `fcl` with each shape's geometry (Box or Convex) built once and kept (reference/
/// prebuilt_cache.h) instead of on every call: the same query, for timing FCL without its
/// set-up, as a user holding FCL objects across steps runs it. Variant "prebuilt" of `fcl`
/// (`rbx bench` on hulls, the report's query times).
ContactResult fcl_contact_prebuilt(const RigidBody& a, const RigidBody& b);
/// `fcl-hull` with each shape's fcl::Convex built once and kept: variant "prebuilt".
ContactResult fcl_hull_contact_prebuilt(const RigidBody& a, const RigidBody& b);
/// `fcl-epa`: fcl::distance with signed distance (GJK + EPA).
ContactResult fcl_epa_contact(const RigidBody& a, const RigidBody& b);
/// `fcl-indep`: fcl::collide on Convex shapes with GST_INDEP, defects shown as they are.
ContactResult fcl_indep_contact(const RigidBody& a, const RigidBody& b);
/// `fcl` mass: fcl::Box's volume and inertia for box bodies (unit density, scaled by mass /
/// volume), fcl_hull_mass otherwise.
MassResult fcl_mass(const RigidBody& body);
/// `fcl-hull` mass: FCL's own Convex volume, centre of mass and inertia (computeVolume, computeCOM,
/// computeMomentofInertiaRelatedToCOM at uniform density mass / volume).
MassResult fcl_hull_mass(const RigidBody& body);

}  // namespace rbx
