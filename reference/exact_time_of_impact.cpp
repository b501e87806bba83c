// The oracle's first time of contact of two convex polyhedra: in pure translation exact from the
// separating axes (exact_translation_impact); with rotation, conservative advancement on the
// exact distance (exact_toi). reference/exact.h; docs/time_of_impact.md.
//
// Design notes.
// - Under translation the separating axes do not turn: the face normals of both shapes and the
//   cross products of an edge of each are the only candidates (the separating-axis theorem for
//   convex polyhedra), at every time alike. Along an axis L the two shapes' projections are
//   intervals, and B's moves at the constant rate (v_b - v_a) . L, so the times at which they
//   overlap along L form one interval [enter_L, exit_L] (all times, or none, when the rate is 0).
// - The shapes touch exactly when they overlap along every axis, so at the times common to every
//   axis's interval: the first contact is the largest enter_L, if it is no later than the least
//   exit_L. Each bound is a quotient of projections, so the time is exact to round-off. The axis
//   whose interval opens last is the contact's normal.
// - Every candidate axis is taken, with no pruning: the oracle is for checking, not for speed.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "reference/exact.h"
#include "reference/exact_geometry.h"

namespace rbx {

namespace {

struct Interval {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
};

// The pose of a body, time t after the start, moving by the stated motion: the centre at its
// velocity, the orientation turning at its angular velocity (world) about the centre. Written
// here apart from the engine's (engine/sweep.h), which it checks.
Pose moved(const RigidBody& body, double t) {
  const Vec3 turn = body.angular_velocity * t;
  const double angle = turn.norm();
  const Quat q = angle > 0 ? Quat(Eigen::AngleAxisd(angle, turn / angle)) : Quat::Identity();
  return {body.position + body.velocity * t, (q * body.orientation).normalized()};
}

double radius_about_origin(const ConvexPolyhedron& s) {
  double r = 0.0;
  for (const Vec3& v : s.vertices()) r = std::max(r, v.norm());
  return r;
}

// The touch at time t of a pair known to touch then: the exact closest points' midpoint and
// direction, when the pair is apart by round-off rather than overlapping by it.
void locate(ToiResult& r, const RigidBody& a, const RigidBody& b, double t) {
  const ExactDistance e = exact_distance(*a.shape, moved(a, t), *b.shape, moved(b, t));
  if (e.overlapping || e.distance <= 0) return;
  r.located = true;
  r.point = 0.5 * (e.point_a + e.point_b);
  r.normal = (e.point_a - e.point_b) / e.distance;
}

// The gap between A and B along the unit axis u from B toward A: the least of A's vertices
// along u less the greatest of B's.
double support_gap(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                   const Pose& pb, const Vec3& u) {
  double lo_a = std::numeric_limits<double>::infinity();
  double hi_b = -std::numeric_limits<double>::infinity();
  for (const Vec3& v : a.vertices()) lo_a = std::min(lo_a, u.dot(pa.apply(v)));
  for (const Vec3& v : b.vertices()) hi_b = std::max(hi_b, u.dot(pb.apply(v)));
  return lo_a - hi_b;
}

Interval project(const std::vector<Vec3>& v, const Vec3& axis) {
  Interval out;
  for (const Vec3& x : v) {
    const double h = x.dot(axis);
    out.lo = std::min(out.lo, h);
    out.hi = std::max(out.hi, h);
  }
  return out;
}

}  // namespace

ExactImpact exact_translation_impact(const ConvexPolyhedron& a, const Pose& pa, const Vec3& va,
                                     const ConvexPolyhedron& b, const Pose& pb, const Vec3& vb,
                                     double dt) {
  const Vec3 origin = 0.5 * (pa.position + pb.position);
  const std::vector<Vec3> xa = exact_detail::placed_vertices(a, pa, origin),
                          xb = exact_detail::placed_vertices(b, pb, origin);
  const Mat3 ra = pa.rotation(), rb = pb.rotation();
  std::vector<Vec3> axes;
  for (const Plane& p : a.planes()) axes.push_back(ra * p.normal);
  for (const Plane& p : b.planes()) axes.push_back(rb * p.normal);
  for (const Edge& ea : a.edges())
    for (const Edge& eb : b.edges()) {
      const Vec3 c = (xa[ea.b] - xa[ea.a]).cross(xb[eb.b] - xb[eb.a]);
      // Parallel edges give no axis of their own (their plane's normals are among the faces').
      const double scale = (xa[ea.b] - xa[ea.a]).norm() * (xb[eb.b] - xb[eb.a]).norm();
      if (c.norm() > 1e-12 * scale) axes.push_back(c.normalized());
    }
  const Vec3 rate = vb - va;  // B's motion relative to A
  ExactImpact out;
  double enter = -std::numeric_limits<double>::infinity();
  double exit = std::numeric_limits<double>::infinity();
  for (const Vec3& axis : axes) {
    const Interval ia = project(xa, axis), ib = project(xb, axis);
    const double s = rate.dot(axis);
    // Overlap along the axis at time t: ib.hi + s t >= ia.lo and ib.lo + s t <= ia.hi.
    double lo, hi;
    if (s > 0) {
      lo = (ia.lo - ib.hi) / s;
      hi = (ia.hi - ib.lo) / s;
    } else if (s < 0) {
      lo = (ia.hi - ib.lo) / s;
      hi = (ia.lo - ib.hi) / s;
    } else if (ib.hi >= ia.lo && ib.lo <= ia.hi) {
      continue;  // overlapping along it at every time
    } else {
      return out;  // apart along it at every time
    }
    if (lo > enter) {
      enter = lo;
      // The axis that opens last, from B toward A: B rising along it (s > 0) meets A from
      // below, so A is pushed along +axis; falling, along -axis.
      out.normal = s > 0 ? axis : Vec3(-axis);
    }
    exit = std::min(exit, hi);
  }
  if (enter > exit || enter > dt || exit < 0) return out;
  out.time = std::max(enter, 0.0);
  return out;
}

ToiResult exact_toi(const RigidBody& a, const RigidBody& b, double dt, long max_steps) {
  ToiResult r;
  if (a.angular_velocity.isZero(0) && b.angular_velocity.isZero(0)) {
    const ExactImpact e = exact_translation_impact(*a.shape, a.pose(), a.velocity, *b.shape,
                                                   b.pose(), b.velocity, dt);
    if (!e.time) return r;
    r.hit = true;
    r.fraction = *e.time / dt;
    // The separating axis that closed last is the normal; the point is where the closest
    // points meet (a touch at round-off's distance; none when overlapping at the start).
    locate(r, a, b, *e.time);
    const double closing = (b.velocity - a.velocity).norm();
    if (!r.located && *e.time > 0 && closing > 0) {
      // Overlapping by round-off at the exact time: the touch a round-off earlier.
      const double size = radius_about_origin(*a.shape) + radius_about_origin(*b.shape);
      locate(r, a, b, std::max(0.0, *e.time - kExactToiTouchRel * size / closing));
    }
    if (r.located) r.normal = e.normal;
    r.message = "pure translation: the separating axes' closed form";
    return r;
  }
  const double ra = radius_about_origin(*a.shape), rb = radius_about_origin(*b.shape);
  const double touch = kExactToiTouchRel * (ra + rb);
  const double spin = a.angular_velocity.norm() * ra + b.angular_velocity.norm() * rb;
  r.message = "rotating: conservative advancement on the exact distance";
  double t = 0.0;
  for (long k = 0; k < max_steps; ++k) {
    const ExactDistance e = exact_distance(*a.shape, moved(a, t), *b.shape, moved(b, t));
    if (e.overlapping || e.distance <= touch) {
      r.hit = true;
      r.fraction = t / dt;
      if (!e.overlapping && e.distance > 0) {
        r.located = true;
        r.point = 0.5 * (e.point_a + e.point_b);
        r.normal = (e.point_a - e.point_b) / e.distance;
      }
      return r;
    }
    // A plane with unit normal u across a gap g along it (the shapes' own supports) separates
    // them while its gap, closing at most at the centres' approach along u plus the fastest any
    // point can turn (Mirtich 1996), lasts: a step of g over that rate is safe, and a plane it
    // never closes separates them for good. The closest points' direction, when round-off has
    // not tilted it (a gap along it over half the distance), else the separating-axis test's
    // best axis (its direction from the shapes' own coordinates), and always the distance over
    // the fastest any point moves: the longest safe step is taken, half the touch short.
    const Pose now_a = moved(a, t), now_b = moved(b, t);
    const Vec3 n = (e.point_a - e.point_b) / e.distance;
    std::vector<std::pair<Vec3, double>> planes = {
        {n, support_gap(*a.shape, now_a, *b.shape, now_b, n)}};
    if (planes[0].second < 0.5 * e.distance) {
      const SatResult sat = sat_query(*a.shape, now_a, *b.shape, now_b);
      if (!sat.touching) planes.push_back({sat.normal, -sat.depth});
    }
    double step = (e.distance - 0.5 * touch) / ((b.velocity - a.velocity).norm() + spin);
    for (const auto& [u, gap] : planes) {
      if (gap <= 0.5 * touch) continue;
      const double closing = (b.velocity - a.velocity).dot(u) + spin;
      if (closing <= 0) return r;
      step = std::max(step, (gap - 0.5 * touch) / closing);
    }
    t += step;
    if (t > dt) return r;
  }
  r.status = Status::Error;
  r.message = "conservative advancement did not reach a touch or the interval's end in " +
              std::to_string(max_steps) + " steps";
  return r;
}

}  // namespace rbx
