#include "engine/sweep.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "engine/distance.h"
#include "engine/separation.h"

namespace rbx {

namespace {

// Farthest a vertex is from the shape's origin (m): how far its rotation can carry a point per
// radian.
double radius_about_origin(const ConvexPolyhedron& s) {
  double r = 0.0;
  for (const Vec3& v : s.vertices()) r = std::max(r, v.norm());
  return r;
}

// The axes a touch's features name, from B toward A: the face of B at B's closest point most
// facing n, the face of A at A's closest point most facing -n, and the cross product of the
// edges nearest the two points. Each is computed from the shapes' own coordinates, so its
// direction stays exact to round-off however small the gap, where the direction between the
// closest points does not (its round-off over a gap of 1e-9 of the size tilts it by 1e-7).
std::vector<Vec3> feature_axes(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                               const Pose& pb, const Separation& s, const Vec3& n) {
  std::vector<Vec3> axes;
  auto best_face = [](const ConvexPolyhedron& shape, const Pose& pose, const Vec3& point,
                      const Vec3& outward) {
    const Vec3 local = pose.inverse_apply(point), dir = pose.orientation.conjugate() * outward;
    double best = -2;
    Vec3 axis = Vec3::Zero();
    for (const Plane& p : shape.planes())
      if (std::abs(p.distance(local)) <= 1e-9 * std::max(1.0, std::abs(p.offset)) &&
          p.normal.dot(dir) > best) {
        best = p.normal.dot(dir);
        axis = pose.orientation * p.normal;
      }
    return axis;
  };
  auto nearest_edge = [](const ConvexPolyhedron& shape, const Pose& pose, const Vec3& point) {
    const Vec3 local = pose.inverse_apply(point);
    double best = std::numeric_limits<double>::infinity();
    Vec3 dir = Vec3::Zero();
    for (const Edge& e : shape.edges()) {
      const Vec3 p = shape.vertices()[e.a], q = shape.vertices()[e.b];
      const double t = std::clamp((local - p).dot(q - p) / (q - p).squaredNorm(), 0.0, 1.0);
      const double d = (p + t * (q - p) - local).norm();
      if (d < best) {
        best = d;
        dir = pose.orientation * (q - p);
      }
    }
    return dir;
  };
  const Vec3 face_b = best_face(b, pb, s.point_b, n), face_a = best_face(a, pa, s.point_a, -n);
  if (!face_b.isZero()) axes.push_back(face_b);
  if (!face_a.isZero()) axes.push_back(-face_a);
  const Vec3 cross = nearest_edge(a, pa, s.point_a).cross(nearest_edge(b, pb, s.point_b));
  if (cross.norm() > 0)
    axes.push_back(cross.dot(n) >= 0 ? cross.normalized() : -cross.normalized());
  return axes;
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
  for (long k = 0; k < max_steps; ++k) {
    const Pose pa = swept_pose(sa, t), pb = swept_pose(sb, t);
    const Separation s = shape_distance(a, pa, b, pb);
    if (s.overlapping) {
      // Only at the start: each step stops half the touching distance short (below), far above
      // GJK's round-off of a touch (1e-12 of the size).
      out.hit = true;
      out.time = t;
      return out;
    }
    const Vec3 n = (s.point_a - s.point_b) / s.distance;
    // A plane with unit normal u across a gap g along it (gap_along: the shapes' own supports)
    // separates the shapes while A's points, moving along u no slower than va.u - |wa| ra, and
    // B's, no faster than vb.u + |wb| rb, have not closed it: the bound holds at every time, so a
    // step of g over it is safe, and a plane the bound never closes separates them for good. The
    // closest points' direction gives the distance's own plane; where round-off has tilted it
    // (a gap along it under half the distance), the axes the touching features name, and the
    // distance over the fastest any point moves, are tried too: the longest safe step is taken.
    std::vector<Vec3> axes = {n};
    const double gap_n = gap_along(a, pa, b, pb, n);
    if (gap_n < 0.5 * s.distance) {
      const std::vector<Vec3> more = feature_axes(a, pa, b, pb, s, n);
      axes.insert(axes.end(), more.begin(), more.end());
    }
    // The longest safe step that stops `short_by` short of closing the gap (infinite: a plane
    // the bound never closes).
    auto safe_step = [&](double short_by) {
      double step = (s.distance - short_by) / ((sb.velocity - sa.velocity).norm() + spin);
      for (const Vec3& u : axes) {
        const double gap = u == n ? gap_n : gap_along(a, pa, b, pb, u);
        if (gap <= short_by) continue;
        const double closing = (sb.velocity - sa.velocity).dot(u) + spin;
        if (closing <= 0) return std::numeric_limits<double>::infinity();
        step = std::max(step, (gap - short_by) / closing);
      }
      return step;
    };
    if (s.distance <= touch) {
      // Within the touching distance: located here, apart, where the closest points still give
      // the normal. The time takes one more safe step, to the touch itself, so that it is not
      // early by the tolerance over a slow approach (a touch 1e-11 of the size short, closing at
      // 1e-9 of the size per second, is 0.01 s early); a step no point can cross the touching
      // distance in, so that a pair that only grazes (its plane closing slowly while its
      // features slide apart) is still within it, and never past the interval.
      const double reach = touch / ((sb.velocity - sa.velocity).norm() + spin);
      out.hit = true;
      out.time = t + std::clamp(std::min(safe_step(0.0), reach), 0.0, dt - t);
      out.point = 0.5 * (s.point_a + s.point_b);
      out.normal = n;
      out.located = true;
      return out;
    }
    // Each step stops half the touching distance short, so that the sweep ends apart (located).
    const double step = safe_step(0.5 * touch);
    if (!std::isfinite(step)) return out;  // a plane that separates them for good
    t += step;
    if (t > dt) return out;
  }
  out.certified = false;
  out.time = t;
  return out;
}

}  // namespace rbx
