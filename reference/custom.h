// The custom engine behind the backend interface.
#pragma once

#include "engine/response.h"
#include "reference/backend.h"

namespace rbx {

/// The engine's backends: `custom` (the manifold its world steps with, engine/manifold.h: the
/// plane is the direction of least overlap, engine/contact_plane.h; the points its one point,
/// the centre of the contact region for shapes proved to overlap, else the Moore & Wilhelms
/// tests' point, then the corners of the patch clipped on the plane, engine/contact_region.h;
/// the extended engine's dynamics: manifolds, Coulomb friction, resting contact, time of impact)
/// with its "faithful" variant (the seed's loops where a detector is needed, the same answer),
/// and `custom-seed` (the seed's algorithm: first hit, single-point frictionless impulse, no time
/// of impact).
const Adapter& custom_adapter();
/// `custom-seed` dynamics with each hit resolved by `response` (World::set_response): a
/// researcher's own collision response over the seed's contacts.
DynamicsResult custom_seed_dynamics_with(const WorldDefinition& scene, const DynamicsOptions& opt,
                                         const ResponseFn& response);

}  // namespace rbx
