// Closed-form geometry the exact oracles share (reference/exact.cpp, exact_distance.cpp,
// exact_time_of_impact.cpp): nothing here iterates or has a tolerance.
#pragma once

#include <algorithm>
#include <vector>

#include "engine/polyhedron.h"

namespace rbx::exact_detail {

/// The closest points c1 on segment [p1, q1] and c2 on [p2, q2] (Ericson, "Real-Time Collision
/// Detection", 5.1.9): the two lines' closest parameters clamped to the segments. A segment of
/// zero length is its point; parallel segments take the start of the first, then clamp (a pair
/// as close as any).
inline void closest_of_segments(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2,
                                Vec3& c1, Vec3& c2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 0 && e <= 0) {
    // two points
  } else if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  c1 = p1 + s * d1;
  c2 = p2 + t * d2;
}

/// A shape's vertices placed at pose `p`, relative to `origin` (the oracles work about the
/// midpoint of a pair's poses, so that round-off follows the pair's size, not its distance from
/// the world's origin).
inline std::vector<Vec3> placed_vertices(const ConvexPolyhedron& s, const Pose& p,
                                         const Vec3& origin) {
  std::vector<Vec3> out;
  out.reserve(s.vertices().size());
  const Mat3 r = p.rotation();
  const Vec3 t = p.position - origin;
  for (const Vec3& v : s.vertices()) out.push_back(r * v + t);
  return out;
}

}  // namespace rbx::exact_detail
