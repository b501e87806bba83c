// Single-point impulse response with restitution (the seed's, corrected: seed corrections 3-5
// (impulse, velocity updates, world inertia)).
#pragma once

#include <functional>

#include "engine/body.h"
#include "engine/contact.h"

namespace rbx {

/// Relative velocity of A with respect to B at world point p:
/// (v_a + w_a x r_a) - (v_b + w_b x r_b).
Vec3 relative_velocity(const RigidBody& a, const RigidBody& b, const Vec3& p);

/// Impulse magnitude j >= 0 along the contact normal n (from B toward A) for restitution e:
/// j = -(1 + e)(v_rel . n) / (1/m_a + 1/m_b + (r_a x n).Ia^-1(r_a x n) + (r_b x n).Ib^-1(r_b x n)).
/// Zero when the bodies are not approaching (v_rel . n >= 0) or both are static.
double impulse_magnitude(const RigidBody& a, const RigidBody& b, const ContactPoint& c,
                         double restitution);

/// Computes j and applies it: v_a += j/m_a n, v_b -= j/m_b n, w_a += Ia^-1 (r_a x j n),
/// w_b -= Ib^-1 (r_b x j n) (seed correction 4 (velocity update signs)). Returns j (0: nothing
/// applied).
double apply_impulse(RigidBody& a, RigidBody& b, const ContactPoint& c, double restitution);

/// Applies the impulse vector `impulse` (N s) at world point `point`: +impulse on A, -impulse on
/// B, linear and angular (the velocity updates of apply_impulse).
void apply_impulse_at(RigidBody& a, RigidBody& b, const Vec3& point, const Vec3& impulse);

/// A response in place of the seed's impulse: the impulse vector (N s, applied +J on A, -J on B at
/// the contact point) for a contact found by the seed's tests, from the bodies' states before it
/// and the restitution.
using ResponseFn = std::function<Vec3(const RigidBody& a, const RigidBody& b,
                                      const ContactPoint& contact, double restitution)>;

}  // namespace rbx
