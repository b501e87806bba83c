// Time integration of one body over one step.
#pragma once

#include "engine/body.h"
#include "engine/world_definition.h"

namespace rbx {

/// The seed's explicit Euler step: rotate the orientation about world x, then y, then z by
/// w * dt with the seed's matrices; move the centre by v * dt; then add gravity to v.
void integrate_euler(RigidBody& body, const Vec3& gravity, double dt);

/// A body-frame inertia's principal moments (kg m^2, ascending) and axes (columns, body
/// frame): what rotate_free_body needs of it. Constant for a body; a world computes it once.
struct PrincipalFrame {
  Vec3 moments = Vec3::Ones();
  Mat3 axes = Mat3::Identity();
};

/// Two principal moments closer than this many epsilons of the largest are one moment: the
/// round-off of a mesh's integrals and of the 3x3 eigensolver (rotate_free_body's splitting).
inline constexpr double kEqualMoments = 64.0;

/// The principal frame of a symmetric positive definite inertia (Eigen's direct 3x3 solver).
PrincipalFrame principal_frame(const Mat3& inertia_body);

/// Semi-implicit (symplectic) Euler: v += g dt first, then x += v dt; the rotation is the
/// torque-free motion with gyroscopic precession (rotate_free_body), carrying the world angular
/// momentum L exactly; then w = I_w^-1 L. Departs from the seed (seed correction 11 (the seed's
/// per-axis Euler kept; symplectic added)), which holds w fixed in the world. `frame`, when
/// given, is principal_frame(body.inertia_body), kept by the caller (the same numbers as
/// computing it here, without the decomposition every step).
void integrate_symplectic(RigidBody& body, const Vec3& gravity, double dt,
                          const PrincipalFrame* frame = nullptr);

/// Orientation after dt of a torque-free body with the principal frame `frame` and world
/// angular momentum `momentum` (kg m^2/s): Strang splitting into a symmetric top and a
/// middle-axis remainder, each by unit quaternions (exponential map), renormalised. Second
/// order; L exact; energy error bounded (no drift); exact for axisymmetric bodies.
Quat rotate_free_body(const Quat& orientation, const PrincipalFrame& frame, const Vec3& momentum,
                      double dt);

/// The most rotate_free_body turns a body per unit of |L| and of time (1 / (kg m^2)): the sum of
/// its sub-turns' rates (the top's turn about L, its symmetry-axis turn, the two middle-axis
/// halves), each a bound on its angle over |L| dt. 1 / I for an isotropic body.
double free_turn_rate(const PrincipalFrame& frame);

/// rotate_free_body with the principal frame of `inertia_body` (kg m^2, body frame).
Quat rotate_free_body(const Quat& orientation, const Mat3& inertia_body, const Vec3& momentum,
                      double dt);

/// The world angular momentum R I R^T w of a body (kg m^2/s), about its centre of mass.
Vec3 world_momentum(const RigidBody& body);

/// The body's orientation after dt of torque-free rotation with world angular momentum
/// `momentum` (rotate_free_body; unchanged when it is zero): the turn integrate_symplectic makes.
Quat free_rotation(const RigidBody& body, const Vec3& momentum, double dt,
                   const PrincipalFrame* frame = nullptr);

/// Dispatches on the scene's integrator. Static bodies never move. `frame` as for
/// integrate_symplectic.
void integrate(RigidBody& body, const SimSettings& sim, double dt,
               const PrincipalFrame* frame = nullptr);

}  // namespace rbx
