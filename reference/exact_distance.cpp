// The exact separation distance of two placed convex polyhedra and its closest feature pair
// (reference/exact.h, exact_distance; docs/distance.md).
//
// Design notes.
// - The closest points of two disjoint convex polyhedra lie on a pair of boundary features, and
//   every such pair is a vertex against a triangle or an edge against an edge (a vertex-edge or
//   vertex-vertex pair is the boundary case of both). The minimum over every vertex of each
//   shape against every triangle of the other, and every edge of one against every edge of the
//   other, is therefore the distance, each candidate computed in closed form (the closest point
//   of a triangle by its Voronoi regions, of two segments by clamped parameters; Ericson,
//   "Real-Time Collision Detection", 5.1.5 and 5.1.9). No iteration: exact to round-off.
// - The cost is the product of the counts (vertices times triangles, edges times edges): the
//   oracle is for checking, not for speed.
// - All coordinates are relative to the midpoint of the two poses, as in the separating-axis
//   oracle, so round-off scales with the pair's size, not with the distance from the origin.
// - Ties (parallel faces, parallel edges: a set of closest pairs) keep the first pair found in
//   a fixed order: vertices of A against B's triangles, then B's against A's, then edge pairs.
// - The features named are those the witness points lie on, of the merged faces (a point on a
//   box face's diagonal is on the face): on no plane of the shape's faces but one, a face; on
//   two, an edge; on three or more, a vertex.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "reference/exact.h"
#include "reference/exact_geometry.h"

namespace rbx {

namespace {

// The closest point to p of triangle abc (Ericson 5.1.5: the Voronoi region of p, then the
// projection onto that feature).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// The kind of feature of `s` (placed as `v`, its planes turned by `r`) that point x lies on:
// how many of its distinct face planes pass within `tol` of x.
const char* feature_at(const ConvexPolyhedron& s, const std::vector<Vec3>& v, const Mat3& r,
                       const Vec3& x, double tol) {
  std::vector<Vec3> normals;  // distinct planes through x (coplanar triangles are one face)
  const auto& tris = s.triangles();
  for (size_t i = 0; i < tris.size(); ++i) {
    const Vec3 n = r * s.planes()[i].normal;
    if (std::abs(n.dot(x - v[tris[i][0]])) > tol) continue;
    if (std::none_of(normals.begin(), normals.end(),
                     [&](const Vec3& m) { return (m - n).norm() <= 1e-9; }))
      normals.push_back(n);
  }
  return normals.size() >= 3 ? "vertex" : normals.size() == 2 ? "edge" : "face";
}

}  // namespace

ExactDistance exact_distance(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                             const Pose& pb) {
  ExactDistance out;
  const SatResult sat = sat_query(a, pa, b, pb);
  if (sat.touching && sat.depth > 0) {
    out.overlapping = true;
    return out;
  }
  const Vec3 origin = 0.5 * (pa.position + pb.position);
  const std::vector<Vec3> va = exact_detail::placed_vertices(a, pa, origin),
                          vb = exact_detail::placed_vertices(b, pb, origin);
  double best = std::numeric_limits<double>::infinity();
  Vec3 wa = Vec3::Zero(), wb = Vec3::Zero();
  auto take = [&](const Vec3& on_a, const Vec3& on_b) {
    const double d2 = (on_a - on_b).squaredNorm();
    if (d2 < best) {
      best = d2;
      wa = on_a;
      wb = on_b;
    }
  };
  for (const Vec3& p : va)
    for (const auto& t : b.triangles())
      take(p, closest_on_triangle(p, vb[t[0]], vb[t[1]], vb[t[2]]));
  for (const Vec3& p : vb)
    for (const auto& t : a.triangles())
      take(closest_on_triangle(p, va[t[0]], va[t[1]], va[t[2]]), p);
  for (const Edge& ea : a.edges())
    for (const Edge& eb : b.edges()) {
      Vec3 ca, cb;
      exact_detail::closest_of_segments(va[ea.a], va[ea.b], vb[eb.a], vb[eb.b], ca, cb);
      take(ca, cb);
    }
  out.distance = std::sqrt(best);
  out.point_a = wa + origin;
  out.point_b = wb + origin;
  // Round-off of a point's height over a plane: unit-scale coordinates relative to the pair's
  // midpoint and a few operations (1e-12 of the pair's extent leaves a wide margin).
  double extent = 0.0;
  for (const auto* vs : {&va, &vb})
    for (const Vec3& v : *vs) extent = std::max(extent, v.cwiseAbs().maxCoeff());
  const double tol = 1e-12 * std::max(extent, 1e-300);
  out.feature_a = feature_at(a, va, pa.rotation(), wa, tol);
  out.feature_b = feature_at(b, vb, pb.rotation(), wb, tol);
  return out;
}

double exact_point_distance(const ConvexPolyhedron& s, const Pose& p, const Vec3& x) {
  // In the body frame, where the hull's own coordinates are exact.
  const Vec3 local = p.rotation().transpose() * (x - p.position);
  const auto& tris = s.triangles();
  const auto& v = s.vertices();
  bool inside = true;
  for (size_t i = 0; i < tris.size() && inside; ++i)
    inside = s.planes()[i].normal.dot(local - v[tris[i][0]]) <= 0.0;
  if (inside) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : tris)
    best = std::min(best, (local - closest_on_triangle(local, v[t[0]], v[t[1]], v[t[2]])).norm());
  return best;
}

}  // namespace rbx
