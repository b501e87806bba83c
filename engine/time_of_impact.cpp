#include "engine/time_of_impact.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/integrate.h"
#include "engine/separation.h"

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

Pose advanced_pose(const RigidBody& body, double t, const PrincipalFrame* frame) {
  if (body.is_static) return body.pose();
  // What advanced() computes of the pose, without copying the body: no gravity, so the centre
  // moves by v t, and the free rotation under the body's world angular momentum.
  return {body.position + body.velocity * t, free_rotation(body, world_momentum(body), t, frame)};
}

double sweep_length(const RigidBody& body, double radius, double t) {
  if (body.is_static) return 0.0;
  return (body.velocity.norm() + body.angular_velocity.norm() * radius) * t;
}

double travel_bound(const RigidBody& body, double turn_rate, double radius, double t) {
  if (body.is_static) return 0.0;
  // |L| = |I_body R^T w|: a rotation keeps the norm.
  const double momentum =
      (body.inertia_body * (body.orientation.conjugate() * body.angular_velocity)).norm();
  return (body.velocity.norm() + turn_rate * momentum * radius) * t;
}

TimeOfImpact time_of_impact(const RigidBody& a, const RigidBody& b, double dt,
                            DetectorVariant variant, long max_samples,
                            const PrincipalFrame* frame_a, const PrincipalFrame* frame_b) {
  // One detection cache for every sample (its scratch lists allocated once).
  DetectionCache cache;
  const auto pose_at = [&](const RigidBody& body, double t, const PrincipalFrame* frame) {
    return advanced_pose(body, t, frame);
  };
  auto touching = [&](double t) {
    return detect(*a.shape, pose_at(a, t, frame_a), *b.shape, pose_at(b, t, frame_b), variant,
                  cache)
        .has_value();
  };
  auto first_touch = [&](double before, double after) {
    while (after - before > 1e-12 * dt) {
      const double mid = 0.5 * (before + after);
      (touching(mid) ? after : before) = mid;
    }
    return TimeOfImpact{after, true};
  };
  // The pair's travel rate (m/s): no point of either body moves faster under advanced().
  const auto rate_of = [](const RigidBody& body, const PrincipalFrame* frame) {
    double radius = 0.0;
    for (const Vec3& v : body.shape->vertices()) radius = std::max(radius, v.norm());
    const PrincipalFrame own = frame ? *frame : principal_frame(body.inertia_body);
    return travel_bound(body, free_turn_rate(own), radius, 1.0);
  };
  const double rate = rate_of(a, frame_a) + rate_of(b, frame_b);
  if (!(rate > 0.0)) return {};  // apart at the start and neither moves
  const double thin = std::min(shape_thickness(*a.shape), shape_thickness(*b.shape));
  const double grid = std::ceil(rate * dt / (0.25 * thin));
  if (grid <= static_cast<double>(max_samples)) {
    const long n = std::max(1L, static_cast<long>(grid));
    double before = 0.0;
    for (long k = 1; k <= n; ++k) {
      const double t = dt * static_cast<double>(k) / static_cast<double>(n);
      if (touching(t)) return first_touch(before, t);
      before = t;
    }
    return {};
  }
  // Too many samples for a grid: each step at least the grid's, longer while a separating axis
  // shows room (a fall from afar takes one step to the touch).
  const double least = 0.25 * thin / rate;
  double t = 0.0;
  for (long k = 0; k < max_samples; ++k) {
    const Pose pa = pose_at(a, t, frame_a), pb = pose_at(b, t, frame_b);
    const Vec3 axis = find_separating_axis(*a.shape, pa, *b.shape, pb, 0.0);
    const double gap = axis == Vec3::Zero() ? 0.0 : gap_along(*a.shape, pa, *b.shape, pb, axis);
    const double next = std::min(dt, t + std::max(least, gap / rate));
    if (touching(next)) return first_touch(t, next);
    if (next >= dt) return {};
    t = next;
  }
  return {std::nullopt, false};
}

}  // namespace rbx
