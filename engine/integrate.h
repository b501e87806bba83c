// Time integration of one body over one step.
#pragma once

#include "engine/body.h"
#include "engine/scene.h"

namespace rbx {

/// The seed's explicit Euler step: rotate the orientation about world x, then y, then z by
/// w * dt with the seed's matrices; move the centre by v * dt; then add gravity to v.
void integrate_euler(RigidBody& body, const Vec3& gravity, double dt);

/// Semi-implicit (symplectic) Euler: v += g dt first, then x += v dt; the rotation is the
/// torque-free motion with gyroscopic precession (rotate_free_body), carrying the world angular
/// momentum L exactly; then w = I_w^-1 L. Departs from the seed (seed correction 11 (the seed's
/// per-axis Euler kept; symplectic added)), which holds w fixed in the world.
void integrate_symplectic(RigidBody& body, const Vec3& gravity, double dt);

/// Orientation after dt of a torque-free body with body-frame inertia `inertia_body` (kg m^2)
/// and world angular momentum `momentum` (kg m^2/s): Strang splitting into a symmetric top and
/// a middle-axis remainder, each by unit quaternions (exponential map), renormalised. Second
/// order; L exact; energy error bounded (no drift); exact for axisymmetric bodies.
Quat rotate_free_body(const Quat& orientation, const Mat3& inertia_body, const Vec3& momentum,
                      double dt);

/// Dispatches on the scene's integrator. Static bodies never move.
void integrate(RigidBody& body, const SimSettings& sim, double dt);

}  // namespace rbx
