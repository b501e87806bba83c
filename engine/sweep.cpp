#include "engine/sweep.h"

#include <algorithm>
#include <cmath>

#include "engine/distance.h"

namespace rbx {

namespace {

// Farthest a vertex is from the shape's origin (m): how far its rotation can carry a point per
// radian.
double radius_about_origin(const ConvexPolyhedron& s) {
  double r = 0.0;
  for (const Vec3& v : s.vertices()) r = std::max(r, v.norm());
  return r;
}

}  // namespace

Pose swept_pose(const Sweep& s, double t) {
  const Vec3 turn = s.angular_velocity * t;
  const double angle = turn.norm();
  const Quat q = angle > 0 ? Quat(Eigen::AngleAxisd(angle, turn / angle)) : Quat::Identity();
  return {s.start.position + s.velocity * t, (q * s.start.orientation).normalized()};
}

SweepImpact sweep_time_of_impact(const ConvexPolyhedron& a, const Sweep& sa,
                                 const ConvexPolyhedron& b, const Sweep& sb, double dt,
                                 long max_steps) {
  const double ra = radius_about_origin(a), rb = radius_about_origin(b);
  const double touch = kSweepTouchRel * (ra + rb);
  // How fast any point can turn off its place along a fixed direction: |w| r.
  const double spin = sa.angular_velocity.norm() * ra + sb.angular_velocity.norm() * rb;
  SweepImpact out;
  double t = 0.0;
  for (long step = 0; step < max_steps; ++step) {
    const Separation s = shape_distance(a, swept_pose(sa, t), b, swept_pose(sb, t));
    if (s.overlapping) {
      // Only at the start: each step stops half the touching distance short (below), far above
      // GJK's round-off of a touch (1e-12 of the size).
      out.hit = true;
      out.time = t;
      return out;
    }
    const Vec3 n = (s.point_a - s.point_b) / s.distance;
    if (s.distance <= touch) {
      out.hit = true;
      out.time = t;
      out.point = 0.5 * (s.point_a + s.point_b);
      out.normal = n;
      out.located = true;
      return out;
    }
    // The plane through the gap with normal n separates the shapes while A's points, moving
    // along n no slower than va.n - |wa| ra, and B's, no faster than vb.n + |wb| rb, have not
    // closed the gap: the bound holds at every time, so the step is safe. It stops half the
    // touching distance short, so that it ends apart (located) even where the bound is exact.
    const double closing = (sb.velocity - sa.velocity).dot(n) + spin;
    if (closing <= 0) return out;  // the plane separates them for good
    t += (s.distance - 0.5 * touch) / closing;
    if (t > dt) return out;
  }
  out.certified = false;
  out.time = t;
  return out;
}

}  // namespace rbx
