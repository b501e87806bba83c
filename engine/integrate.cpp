#include "engine/integrate.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

namespace rbx {

namespace {

// Quaternion of the rotation by angle |phi| about phi (exponential map), exact for any angle.
Quat exp_map(const Vec3& phi) {
  const double angle = phi.norm();
  if (angle < 1e-300) return Quat::Identity();
  return Quat(Eigen::AngleAxisd(angle, phi / angle));
}

}  // namespace

PrincipalFrame principal_frame(const Mat3& inertia_body) {
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(inertia_body);
  return {eig.eigenvalues(), eig.eigenvectors()};
}

Quat rotate_free_body(const Quat& orientation, const Mat3& inertia_body, const Vec3& momentum,
                      double dt) {
  return rotate_free_body(orientation, principal_frame(inertia_body), momentum, dt);
}

namespace {

// The splitting of rotate_free_body: the top's equal moment and the two remainders' constants.
struct Splitting {
  double reference = 1.0;  // kg m^2
  int symmetric_axis = 2;
  double c_sym = 0.0, c_mid = 0.0;  // 1 / (kg m^2)
};

Splitting splitting_of(const Vec3& moments) {
  // The top's equal pair is the middle moment's nearer neighbour.
  Splitting s;
  const bool low_pair = moments(1) - moments(0) <= moments(2) - moments(1);
  s.reference = low_pair ? moments(0) : moments(2);
  s.symmetric_axis = low_pair ? 2 : 0;
  s.c_sym = 1.0 / moments(s.symmetric_axis) - 1.0 / s.reference;
  s.c_mid = 1.0 / moments(1) - 1.0 / s.reference;
  // Moments equal to within the round-off of computing them are equal: a mesh's integrals and
  // the direct 3x3 eigensolver leave a cube's three moments a few ulps apart, and the remainder
  // that difference leaves would turn the body by round-off each step, at the cost of two more
  // turns. Dropped, an isotropic or axisymmetric body moves by the top's exact flow alone.
  const double tol = kEqualMoments * std::numeric_limits<double>::epsilon() * moments(2);
  if (std::abs(moments(s.symmetric_axis) - s.reference) <= tol) s.c_sym = 0.0;
  if (std::abs(moments(1) - s.reference) <= tol) s.c_mid = 0.0;
  return s;
}

}  // namespace

double free_turn_rate(const PrincipalFrame& frame) {
  // Each sub-turn about a unit axis u is by c (u . l) h, |u . l| <= |L|: the middle axis twice
  // for dt / 2, the symmetry axis and the turn about L (rate 1 / I_ref) for dt.
  const Splitting s = splitting_of(frame.moments);
  return std::abs(s.c_mid) + std::abs(s.c_sym) + 1.0 / s.reference;
}

Quat rotate_free_body(const Quat& orientation, const PrincipalFrame& frame, const Vec3& momentum,
                      double dt) {
  // Design note. The free rigid body H = sum_k l_k^2 / (2 I_k) (l = body-frame momentum,
  // I_k principal moments, ascending) is split as a symmetric top, which has an exact flow,
  // plus a remainder on the middle axis, also exact; Strang composition of the two is second
  // order, symplectic and keeps L exactly (Touma & Wisdom 1994; Dullweber, Leimkuhler and
  // McLachlan 1997). The top's equal pair is the middle moment's nearer neighbour, so the
  // remainder is as small as it can be, and zero for axisymmetric and isotropic bodies, whose
  // motion is then exact for any dt. The earlier exponential map of w dt with w recovered from
  // L after the step kept L but let the energy drift at first order (3 % in 16 s of an
  // intermediate-axis spin at dt = 1e-3).
  const Mat3& axes = frame.axes;  // columns: principal axes in the body frame
  const Splitting split = splitting_of(frame.moments);
  const double reference = split.reference;  // the top's equal moment
  const Vec3 u_sym = axes.col(split.symmetric_axis);
  const Vec3 u_mid = axes.col(1);
  const double c_sym = split.c_sym, c_mid = split.c_mid;
  // Flow of c (u.l)^2 / 2 for time h: the body turns about its own axis u by c (u.l) h.
  auto about_body_axis = [&](const Quat& q, const Vec3& u, double c, double h) {
    // No turn (c = 0: an isotropic or axisymmetric body): q times the identity is q exactly.
    if (c == 0.0) return q.normalized();
    const Vec3 l = q.conjugate() * momentum;
    return (q * exp_map(u * (c * u.dot(l) * h))).normalized();
  };
  Quat q = about_body_axis(orientation, u_mid, c_mid, 0.5 * dt);
  // Symmetric top for dt: a turn about L by |L| dt / I_ref (l fixed) and a turn about the
  // symmetry axis (u_sym.l fixed); the two commute.
  const Quat spin = exp_map(momentum * (dt / reference));
  q = (spin * about_body_axis(q, u_sym, c_sym, dt)).normalized();
  return about_body_axis(q, u_mid, c_mid, 0.5 * dt);
}

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

Quat free_rotation(const RigidBody& body, const Vec3& momentum, double dt,
                   const PrincipalFrame* frame) {
  if (!(momentum.norm() > 0.0)) return body.orientation;
  return frame
             ? rotate_free_body(body.orientation, *frame, momentum, dt)
             : rotate_free_body(body.orientation, principal_frame(body.inertia_body), momentum, dt);
}

Vec3 world_momentum(const RigidBody& body) { return body.inertia_world() * body.angular_velocity; }

void integrate_symplectic(RigidBody& body, const Vec3& gravity, double dt,
                          const PrincipalFrame* frame) {
  if (body.is_static) return;
  // Semi-implicit Euler: velocity from forces first, then position with the new velocity.
  body.velocity += gravity * dt;
  body.position += body.velocity * dt;
  // Torque-free rotation: the world angular momentum L is constant, the body turns under it;
  // then w = I_w^-1 L.
  const Vec3 momentum = world_momentum(body);
  body.orientation = free_rotation(body, momentum, dt, frame);
  body.angular_velocity = body.inverse_inertia_world() * momentum;
}

void integrate(RigidBody& body, const SimSettings& sim, double dt, const PrincipalFrame* frame) {
  if (sim.integrator == Integrator::Euler)
    integrate_euler(body, sim.gravity, dt);
  else
    integrate_symplectic(body, sim.gravity, dt, frame);
}

}  // namespace rbx
