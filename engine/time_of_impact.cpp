#include "engine/time_of_impact.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/detect.h"
#include "engine/distance.h"
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

TimeOfImpact time_of_impact(const RigidBody& a, const RigidBody& b, double dt, Detector detector,
                            long max_samples, const PrincipalFrame* frame_a,
                            const PrincipalFrame* frame_b) {
  // One detection cache for every sample (its scratch lists allocated once).
  DetectionCache cache;
  const auto pose_at = [&](const RigidBody& body, double t, const PrincipalFrame* frame) {
    return advanced_pose(body, t, frame);
  };
  auto touching = [&](double t) {
    return detect(*a.shape, pose_at(a, t, frame_a), *b.shape, pose_at(b, t, frame_b), detector,
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
    // Two samples apart do not prove the time between them apart: bodies skimming past each
    // other can overlap briefly between them (a corner clipping another's). Certified from the
    // distance (engine/distance.h): along the direction n from A's closest point to B's, the
    // gap d between the shapes shrinks no faster than the approach along n, -(v_b - v_a) . n,
    // plus what the turns can bring (the spin part of the travel rate), so nothing touches for
    // d over that rate after a time the pair is apart, nor that long before (the rate of
    // opening, backward). A touch between samples at t0 and t1 needs both spans to fit in
    // between; where they do not, nothing touched. Else the interval is walked by those steps
    // (conservative advancement), each at least the detector's tolerance of travel (an overlap
    // shallower than that is touching to the detector anyway).
    const double least_step = point_in_mesh_tolerance(*a.shape, *b.shape) / rate;
    const auto spin_of = [&](const RigidBody& body, const PrincipalFrame* frame) {
      return body.is_static ? 0.0 : rate_of(body, frame) - body.velocity.norm();
    };
    const double spin = spin_of(a, frame_a) + spin_of(b, frame_b);
    // B's velocity seen from A (a static body does not move, whatever its velocity says).
    const Vec3 v_rel =
        (b.is_static ? Vec3::Zero() : b.velocity) - (a.is_static ? Vec3::Zero() : a.velocity);
    // How long after (forward) and before (backward) time t the pair is sure to stay apart.
    struct Room {
      double forward = 0.0, backward = 0.0;
    };
    auto room = [&](double t) {
      const Separation sep =
          shape_distance(*a.shape, pose_at(a, t, frame_a), *b.shape, pose_at(b, t, frame_b));
      if (sep.overlapping || !(sep.distance > 0)) return Room{};
      const Vec3 n = (sep.point_b - sep.point_a) / sep.distance;
      const double approach = -v_rel.dot(n);
      auto span = [&](double closing) {
        return closing > 0 ? sep.distance / closing : std::numeric_limits<double>::infinity();
      };
      return Room{span(std::max(0.0, approach) + spin), span(std::max(0.0, -approach) + spin)};
    };
    long walked = 0;
    double before = 0.0;
    Room at_before = room(0.0);
    for (long k = 1; k <= n; ++k) {
      const double t = dt * static_cast<double>(k) / static_cast<double>(n);
      if (touching(t)) return first_touch(before, t);
      const Room at_t = room(t);
      if (!(at_before.forward + at_t.backward > t - before)) {
        // The walk asks the distance at each step, and the detector only where the distance
        // finds the pair touching (the cheaper query first).
        double clear = before, span = at_before.forward;
        for (;;) {
          const double next = clear + std::max(span, least_step);
          if (next >= t) break;
          span = room(next).forward;
          if (!(span > 0) && touching(next)) return first_touch(clear, next);
          clear = next;
          if (++walked >= max_samples) return {std::nullopt, false};
        }
      }
      before = t;
      at_before = at_t;
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
