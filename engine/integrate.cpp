#include "engine/integrate.h"

#include <cmath>

namespace rbx {

namespace {

// Quaternion of the rotation by angle |phi| about phi (exponential map), exact for any angle.
Quat exp_map(const Vec3& phi) {
  const double angle = phi.norm();
  if (angle < 1e-300) return Quat::Identity();
  return Quat(Eigen::AngleAxisd(angle, phi / angle));
}

}  // namespace

void integrate_euler(RigidBody& body, const Vec3& gravity, double dt) {
  if (body.is_static) return;
  // The seed: rotate about world x, then y, then z by w * dt with its matrices, and shift the
  // centre by v dt. The world angular velocity stays constant between impacts (the seed has no
  // gyroscopic term), as does its explicit-Euler order: position uses the old velocity.
  const Vec3 a = body.angular_velocity * dt;
  const Mat3 step = rotation_z(a.z()) * rotation_y(a.y()) * rotation_x(a.x());
  const Mat3 r = step * body.orientation.toRotationMatrix();
  body.orientation = Quat(r).normalized();
  body.position += body.velocity * dt;
  // Departure: the seed has no gravity; an explicit step adds it after the move.
  body.velocity += gravity * dt;
}

void integrate_symplectic(RigidBody& body, const Vec3& gravity, double dt) {
  if (body.is_static) return;
  // Semi-implicit Euler: velocity from forces first, then position with the new velocity.
  body.velocity += gravity * dt;
  body.position += body.velocity * dt;
  // Torque-free rotation. Design note: the world angular momentum L = I_w w is the conserved
  // quantity, so we carry L across the step: rotate by the exponential map of w dt, then
  // recover w = I_w(new)^-1 L. This keeps L exact to round-off for any dt and gives the
  // gyroscopic precession of asymmetric bodies (w changes as I_w rotates); the energy error is
  // first order in dt. (An implicit body-frame gyroscopic solve, as in Box2D/Catto, would
  // instead trade exact L for damping.)
  const Vec3 momentum = body.inertia_world() * body.angular_velocity;
  body.orientation = (exp_map(body.angular_velocity * dt) * body.orientation).normalized();
  body.angular_velocity = body.inverse_inertia_world() * momentum;
}

void integrate(RigidBody& body, const SimSettings& sim, double dt) {
  if (sim.integrator == Integrator::Euler)
    integrate_euler(body, sim.gravity, dt);
  else
    integrate_symplectic(body, sim.gravity, dt);
}

}  // namespace rbx
