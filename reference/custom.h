// The custom engine behind the backend interface.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// Contact at the current poses by the Moore & Wilhelms detector (first hit, seed order).
ContactResult custom_contact(const RigidBody& a, const RigidBody& b);
/// Contact by the faithful seed loops (the oracle of the fast detector).
ContactResult custom_seed_contact(const RigidBody& a, const RigidBody& b);
/// Whole-scene run with the engine.
DynamicsResult custom_dynamics(const Scene& scene, const DynamicsOptions& opt);

}  // namespace rbx
