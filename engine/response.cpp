#include "engine/response.h"

namespace rbx {

Vec3 relative_velocity(const RigidBody& a, const RigidBody& b, const Vec3& p) {
  const Vec3 ra = p - a.position, rb = p - b.position;
  return (a.velocity + a.angular_velocity.cross(ra)) - (b.velocity + b.angular_velocity.cross(rb));
}

double impulse_magnitude(const RigidBody& a, const RigidBody& b, const ContactPoint& c,
                         double restitution) {
  const Vec3& n = c.normal;
  const double vn = relative_velocity(a, b, c.point).dot(n);
  // Only approaching contacts get an impulse (seed correction 3 ((1 + e) on the whole impulse, only
  // while approaching)); separating ones are left alone.
  if (!(vn < 0.0)) return 0.0;
  const Vec3 ra = c.point - a.position, rb = c.point - b.position;
  const Vec3 ran = ra.cross(n), rbn = rb.cross(n);
  const double denom = a.inverse_mass + b.inverse_mass + ran.dot(a.inverse_inertia_world() * ran) +
                       rbn.dot(b.inverse_inertia_world() * rbn);
  if (!(denom > 0.0)) return 0.0;  // both static: nothing can move
  // seed correction 3 ((1 + e) on the whole impulse, only while approaching): the seed applies (1 +
  // e) to the linear term only and adds the angular terms outside it; the correct single-point
  // formula scales the whole relative normal velocity.
  return -(1.0 + restitution) * vn / denom;
}

double apply_impulse(RigidBody& a, RigidBody& b, const ContactPoint& c, double restitution) {
  const double j = impulse_magnitude(a, b, c, restitution);
  if (j <= 0.0) return 0.0;
  apply_impulse_at(a, b, c.point, j * c.normal);
  return j;
}

void apply_impulse_at(RigidBody& a, RigidBody& b, const Vec3& point, const Vec3& impulse) {
  const Vec3 ra = point - a.position, rb = point - b.position;
  // seed correction 4 (velocity update signs): the seed subtracts on both bodies and writes J x r,
  // which does not conserve momentum; A (pushed along n, away from B) gains, B loses, and the
  // torque is r x J.
  a.velocity += a.inverse_mass * impulse;
  b.velocity -= b.inverse_mass * impulse;
  a.angular_velocity += a.inverse_inertia_world() * ra.cross(impulse);
  b.angular_velocity -= b.inverse_inertia_world() * rb.cross(impulse);
}

}  // namespace rbx
