// Single-point impulse response with restitution (the seed's, corrected: seed corrections 3-5
// (impulse, velocity updates, world inertia)).
#pragma once

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

}  // namespace rbx
