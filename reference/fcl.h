// FCL 0.7 adapters: Convex with libccd MPR, signed distance (GJK + EPA), Convex with GST_INDEP, and
// the Box-Box path.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// `fcl`: fcl::collide on Convex shapes with GST_LIBCCD (libccd MPR).
ContactResult fcl_contact(const RigidBody& a, const RigidBody& b);
/// `fcl` with each shape's fcl::Convex built once and kept (the last few shapes, held by their
/// shared_ptr) instead of on every call: the same query, for timing FCL without its set-up, as
/// a user holding FCL objects across steps runs it. Used by `rbx bench` (variant "prebuilt").
ContactResult fcl_contact_prebuilt(const RigidBody& a, const RigidBody& b);
/// `fcl-epa`: fcl::distance with signed distance (GJK + EPA).
ContactResult fcl_epa_contact(const RigidBody& a, const RigidBody& b);
/// `fcl-indep`: fcl::collide on Convex shapes with GST_INDEP, defects shown as they are.
ContactResult fcl_indep_contact(const RigidBody& a, const RigidBody& b);
/// `fcl-box`: FCL Box-Box (boxBoxIntersect); unsupported unless both bodies are boxes.
ContactResult fcl_box_contact(const RigidBody& a, const RigidBody& b);
/// FCL's own Convex volume, centre of mass and inertia (computeVolume, computeCOM,
/// computeMomentofInertiaRelatedToCOM at uniform density mass / volume).
MassResult fcl_mass(const RigidBody& body);

}  // namespace rbx
