#include "engine/time_of_impact.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/integrate.h"

namespace rbx {

double shape_thickness(const ConvexPolyhedron& shape) {
  double thinnest = std::numeric_limits<double>::infinity();
  for (const Plane& p : shape.planes()) {
    double lo = std::numeric_limits<double>::infinity();
    for (const Vec3& v : shape.vertices()) lo = std::min(lo, p.normal.dot(v));
    thinnest = std::min(thinnest, p.offset - lo);
  }
  return thinnest;
}

RigidBody advanced(const RigidBody& body, double t, const PrincipalFrame* frame) {
  RigidBody moved = body;
  integrate_symplectic(moved, Vec3::Zero(), t, frame);
  return moved;
}

double sweep_length(const RigidBody& body, double t) {
  if (body.is_static) return 0.0;
  double radius = 0.0;
  for (const Vec3& v : body.shape->vertices()) radius = std::max(radius, v.norm());
  return (body.velocity.norm() + body.angular_velocity.norm() * radius) * t;
}

double travel_bound(const RigidBody& body, double turn_rate, double radius, double t) {
  if (body.is_static) return 0.0;
  // |L| = |I_body R^T w|: a rotation keeps the norm.
  const double momentum =
      (body.inertia_body * (body.orientation.conjugate() * body.angular_velocity)).norm();
  return (body.velocity.norm() + turn_rate * momentum * radius) * t;
}

std::optional<double> time_of_impact(const RigidBody& a, const RigidBody& b, double dt,
                                     DetectorVariant variant, const PrincipalFrame* frame_a,
                                     const PrincipalFrame* frame_b) {
  // One detection cache for every sample (its scratch lists allocated once).
  DetectionCache cache;
  auto touching = [&](double t) {
    const RigidBody ma = advanced(a, t, frame_a), mb = advanced(b, t, frame_b);
    return detect(*a.shape, ma.pose(), *b.shape, mb.pose(), variant, cache).has_value();
  };
  // Samples: the relative sweep over one sample interval stays under a quarter of the thinner
  // thickness, so a body cannot cross the other between two samples. At most 1e6 samples
  // (a sweep of 4e6 thicknesses in one step is no longer a contact problem).
  const double thin = std::min(shape_thickness(*a.shape), shape_thickness(*b.shape));
  const double sweep = sweep_length(a, dt) + sweep_length(b, dt);
  const double samples = std::min(std::ceil(sweep / (0.25 * thin)), 1e6);
  const long n = std::max(1L, static_cast<long>(samples));
  double before = 0.0;
  for (long k = 1; k <= n; ++k) {
    const double t = dt * static_cast<double>(k) / static_cast<double>(n);
    if (!touching(t)) {
      before = t;
      continue;
    }
    // Bisection between the last separated and the first touching time.
    double after = t;
    while (after - before > 1e-12 * dt) {
      const double mid = 0.5 * (before + after);
      (touching(mid) ? after : before) = mid;
    }
    return after;
  }
  return std::nullopt;
}

}  // namespace rbx
