// The custom engine behind the backend interface.
#pragma once

#include "engine/response.h"
#include "reference/backend.h"

namespace rbx {

/// Contact at the current poses: the Moore & Wilhelms detector finds it and its point, the plane
/// is the direction of least overlap (engine/contact_plane.h), from either body order alike.
ContactResult custom_contact(const RigidBody& a, const RigidBody& b);
/// custom_contact on the faithful detector: the seed's loops over every primitive (the
/// accelerated detector's oracle), then the same chosen plane; the same answer, slower.
ContactResult custom_faithful_contact(const RigidBody& a, const RigidBody& b);
/// Whole-scene run with the extended engine: manifolds, Coulomb friction, resting contact, time
/// of impact (the `custom` backend).
DynamicsResult custom_dynamics(const Scene& scene, const DynamicsOptions& opt);
/// Whole-scene run with the seed's algorithm and its corrections only: first hit, single-point
/// frictionless impulse, no time of impact (the `custom-seed` backend).
DynamicsResult custom_seed_dynamics(const Scene& scene, const DynamicsOptions& opt);
/// custom_seed_dynamics with each hit resolved by `response` (World::set_response): a
/// researcher's own collision response over the seed's contacts.
DynamicsResult custom_seed_dynamics_with(const Scene& scene, const DynamicsOptions& opt,
                                         const ResponseFn& response);

}  // namespace rbx
