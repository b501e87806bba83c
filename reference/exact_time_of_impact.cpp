// The exact first time of contact of two convex polyhedra in pure translation
// (reference/exact.h, exact_translation_impact; docs/distance.md, "Time of impact").
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
#include <vector>

#include "reference/exact.h"
#include "reference/exact_geometry.h"

namespace rbx {

namespace {

struct Interval {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
};

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

}  // namespace rbx
