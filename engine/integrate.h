// Time integration of one body over one step.
#pragma once

#include "engine/body.h"
#include "engine/scene.h"

namespace rbx {

/// The seed's explicit Euler step: rotate the orientation about world x, then y, then z by
/// w * dt with the seed's matrices; move the centre by v * dt; then add gravity to v.
void integrate_euler(RigidBody& body, const Vec3& gravity, double dt);

/// Semi-implicit (symplectic) Euler: v += g dt first, then x += v dt; the angular velocity is
/// advanced with the gyroscopic term (torque-free Euler equations, implicit in the body frame),
/// then the orientation by the quaternion exponential map, renormalised.
void integrate_symplectic(RigidBody& body, const Vec3& gravity, double dt);

/// Dispatches on the scene's integrator. Static bodies never move.
void integrate(RigidBody& body, const SimSettings& sim, double dt);

}  // namespace rbx
