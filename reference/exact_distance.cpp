// The exact separation distance of two placed convex polyhedra and its closest feature pair
// (reference/exact.h, exact_distance; docs/distance.md).
//
// Design notes.
// - The closest points of two disjoint convex polyhedra lie on a pair of boundary features, and
//   every such pair is a vertex against a triangle or an edge against an edge (a vertex-edge or
//   vertex-vertex pair is the boundary case of both). The minimum over every vertex of each
//   shape against every triangle of the other, and every edge of one against every edge of the
//   other, is therefore the distance, each candidate computed in closed form (the closest point
//   of a triangle by projection on its plane or the nearest edge, of two segments by clamped
//   parameters; Ericson, "Real-Time Collision Detection", 5.1.9). No iteration: exact to
//   round-off.
// - The cost is the product of the counts (vertices times triangles, edges times edges): the
//   oracle is for checking, not for speed.
// - All coordinates are relative to the midpoint of the two poses, as in the separating-axis
//   oracle, so round-off scales with the pair's size, not with the distance from the origin.
// - Ties (parallel faces, parallel edges: a set of closest pairs) keep the first pair found in
//   a fixed order: vertices of A against B's triangles, then B's against A's, then edge pairs.
// - Overlap is the separating-axis oracle's verdict where it is sure (apart, or overlapping by
//   more than its own error bound) and, in between, a vertex inside the other shape or an edge
//   through one of its triangles.
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

// The closest point to p of segment ab (clamped projection: round-off of |p - a| eps only).
Vec3 closest_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  return len2 > 0 ? Vec3(a + std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) * ab) : a;
}

// The closest point to p of triangle abc: p's projection on the plane when it falls inside,
// else the nearest of the three edges' closest points. Not Ericson's Voronoi-region form
// (5.1.5), whose weights lose |ab|^2 |ac|^2 / area^2 eps to cancellation: on a sliver's
// triangle 1.26 long it put the point 1e-11 off along the face and the distance 8 % long at a
// gap of 2.4e-11. The plane is taken from the two edges at the vertex opposite the longest edge
// (its angle the largest, so their cross product loses least), the projection is p less its
// height along that normal, and the inside test's weights move the point only along the face.
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v[3] = {a, b, c};
  const double l0 = (c - b).squaredNorm(), l1 = (a - c).squaredNorm(), l2 = (b - a).squaredNorm();
  const int k = l0 >= l1 && l0 >= l2 ? 0 : l1 >= l2 ? 1 : 2;
  const Vec3 &o = v[k], e1 = v[(k + 1) % 3] - o, e2 = v[(k + 2) % 3] - o;
  const Vec3 n = e1.cross(e2);
  const double nn = n.squaredNorm();
  if (nn > 0) {
    const Vec3 d = p - o;
    const double u1 = d.cross(e2).dot(n) / nn, u2 = e1.cross(d).dot(n) / nn;
    if (u1 >= 0 && u2 >= 0 && u1 + u2 <= 1) return p - n * (n.dot(d) / nn);
  }
  Vec3 best = closest_on_segment(p, a, b);
  for (const Vec3& q : {closest_on_segment(p, b, c), closest_on_segment(p, c, a)})
    if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
  return best;
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

// True when a vertex of `s` lies inside `t` or an edge of `s` passes through a triangle of `t`,
// each by more than `tol` (both placed: `vs`, `vt`; `pt` turns t's planes).
bool crosses(const ConvexPolyhedron& s, const std::vector<Vec3>& vs, const ConvexPolyhedron& t,
             const std::vector<Vec3>& vt, const Pose& pt, double tol) {
  const auto& tris = t.triangles();
  std::vector<Vec3> normals;
  normals.reserve(tris.size());
  for (size_t i = 0; i < tris.size(); ++i) normals.push_back(pt.rotation() * t.planes()[i].normal);
  for (const Vec3& x : vs) {
    bool inside = true;
    for (size_t i = 0; i < tris.size() && inside; ++i)
      inside = normals[i].dot(x - vt[tris[i][0]]) < -tol;
    if (inside) return true;
  }
  for (const Edge& e : s.edges()) {
    const Vec3 &p = vs[e.a], &q = vs[e.b];
    for (size_t i = 0; i < tris.size(); ++i) {
      const Vec3 &a = vt[tris[i][0]], &b = vt[tris[i][1]], &c = vt[tris[i][2]];
      const Vec3& n = normals[i];
      const double hp = n.dot(p - a), hq = n.dot(q - a);
      if (!((hp > tol && hq < -tol) || (hp < -tol && hq > tol))) continue;
      const Vec3 x = p + (hp / (hp - hq)) * (q - p);
      if ((b - a).cross(x - a).dot(n) > tol * (b - a).norm() &&
          (c - b).cross(x - b).dot(n) > tol * (c - b).norm() &&
          (a - c).cross(x - c).dot(n) > tol * (a - c).norm())
        return true;
    }
  }
  return false;
}

}  // namespace

ExactDistance exact_distance(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                             const Pose& pb) {
  ExactDistance out;
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
  // Round-off of a point's height over a plane: unit-scale coordinates relative to the pair's
  // midpoint and a few operations (1e-12 of the pair's extent leaves a wide margin).
  double extent = 0.0;
  for (const auto* vs : {&va, &vb})
    for (const Vec3& v : *vs) extent = std::max(extent, v.cwiseAbs().maxCoeff());
  const double tol = 1e-12 * std::max(extent, 1e-300);
  // Overlap. The separating-axis oracle's depth is an upper bound, off by up to 1.5e-8 of the
  // size where it skips a nearly parallel edge pair (exact.cpp, kParallelSine): it called two
  // slivers 7.6e-11 apart overlapping by 1.1e-13. So it decides apart (depth within round-off)
  // and overlap beyond 1e-7 of the extent; between the two, the shapes overlap when a vertex of
  // one lies inside the other or an edge of one passes through a triangle of the other, each by
  // more than round-off.
  const SatResult sat = sat_query(a, pa, b, pb);
  if (sat.touching && sat.depth > tol) {
    out.overlapping =
        sat.depth > 1e5 * tol || crosses(a, va, b, vb, pb, tol) || crosses(b, vb, a, va, pa, tol);
  }
  if (out.overlapping) return out;
  out.distance = std::sqrt(best);
  out.point_a = wa + origin;
  out.point_b = wb + origin;
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
