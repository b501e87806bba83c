// The seed's Moore & Wilhelms tests (face, vertex, edge; one order and both orders), written once
// as templates over a "shape view", with the corrections of seed corrections 1, 2, 8, 9, 10
// (docs/seed_corrections.md) marked where they apply. Internal to the engine: the public entry
// points are in engine/detect.h.
//
// Design note. The faithful and the accelerated detectors differ only in how a shape answers
// queries, never in the steps of a test, so the steps live here and each detector supplies a
// view (MuJoCo keeps one collider per algorithm family; a faster version of the same test is
// the same template over another view, so the two cannot drift):
//   - FaithfulView (engine/detect_faithful.h) loops over every primitive, as the seed does;
//   - AcceleratedView (engine/detect_accelerated.h) returns culled candidate lists and answers
//     point-in-mesh, support, closest-face and crossing queries through bounding volume trees,
//     with the seed's own floating-point expressions at the leaves, so its answers are the
//     faithful ones bit for bit.
// A view V of shape X, paired with view Y of the other shape, provides:
//   shape (const ConvexPolyhedron*), tol (m, the point-in-mesh tolerance of the pair),
//   vertex(i), normal(f)                 world vertex i, world outward normal of triangle f;
//   may_enter()                          false: no point of X can be inside the other shape;
//   candidates(kind, other, out)         indices of X's primitives that may hold a hit, increasing;
//   inside(p)                            seed correction 1 (point in mesh uses p - q_f)
//   point-in-mesh of a world point; support_max(n), support_min(n)       max / min over X's world
//   vertices of v . n; closest_face(p)                      argmin over faces of |(p - q_f) . n_f|
//   (ties: lowest); crossings(v_i, v_j, out)             the planes of X the segment crosses
//   (crossing_of), by face; nearest_triangle(p)                  argmin of triangle_distance (ties:
//   lowest index); segment_outside(other, v_i, v_j)     true only when no point of the segment is
//   inside X.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "engine/contact.h"
#include "engine/polyhedron.h"

namespace rbx::detail {

/// Which primitives of a shape a test loops over.
enum class Primitive { Triangles, Vertices, Edges };

/// One crossing of an edge of A with the plane of a triangle of B.
struct Crossing {
  double t = 0.0;  // parameter along the edge, 0 at v_i, 1 at v_j
  int face = -1;   // triangle of B
};

/// Reusable lists of one query (owned by a DetectionCache), so warm tests allocate nothing.
struct FeatureScratch {
  std::vector<int> candidates, hits;
  std::vector<Crossing> crossings;
  std::vector<double> ts;
};

/// Penetration along n: max_b (b . n) - min_a (a . n), clamped at 0 (overlap_along in detect.h).
template <typename View>
double overlap(const View& a, const View& b, const Vec3& n) {
  return std::max(0.0, b.support_max(n) - a.support_min(n));
}

/// Distance (m) from p to the segment [s0, s1].
inline double segment_distance(const Vec3& p, const Vec3& s0, const Vec3& s1) {
  const Vec3 d = s1 - s0;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - s0).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (p - (s0 + t * d)).norm();
}

/// Distance (m) from p to triangle f of y: to its plane when p projects inside the triangle,
/// otherwise to the nearest of its three edges.
template <typename View>
double triangle_distance(const View& y, int f, const Vec3& p) {
  const auto& t = y.shape->triangles()[f];
  const Vec3 n = y.normal(f);
  const Vec3 q[3] = {y.vertex(t[0]), y.vertex(t[1]), y.vertex(t[2])};
  bool within = true;
  for (int k = 0; k < 3; ++k)
    if ((q[(k + 1) % 3] - q[k]).cross(p - q[k]).dot(n) < 0.0) within = false;
  if (within) return std::abs((p - q[0]).dot(n));
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) best = std::min(best, segment_distance(p, q[k], q[(k + 1) % 3]));
  return best;
}

/// Appends the crossing of the segment [v_i, v_j] with the plane of y's triangle f, if any:
/// the signed distances of the ends, d = (v - u_k1) . n, have strictly opposite signs.
template <typename View>
void crossing_of(const View& y, int f, const Vec3& v_i, const Vec3& v_j,
                 std::vector<Crossing>& out) {
  const Vec3 u = y.vertex(y.shape->triangles()[f][0]);
  const Vec3 n = y.normal(f);
  const double d_i = (v_i - u).dot(n);
  const double d_j = (v_j - u).dot(n);
  if (!((d_i < 0.0 && d_j > 0.0) || (d_i > 0.0 && d_j < 0.0))) return;
  // seed correction 2 (edge crossing at v_i + t (v_j - v_i)). The seed prints P = v_i + t (v_i -
  // v_i), which is always v_i; the crossing is P = v_i + t (v_j - v_i) with t = |d_i| / (|d_i| +
  // |d_j|).
  out.push_back({std::abs(d_i) / (std::abs(d_i) + std::abs(d_j)), f});
}

/// Face test, one order: centroids of A's triangles inside B, averaged (the seed's "better
/// collision point" for faces split into several triangles).
template <typename View>
std::optional<ContactPoint> face_one(const View& a, const View& b, FeatureScratch& s) {
  if (!a.may_enter()) return std::nullopt;
  a.candidates(Primitive::Triangles, b, s.candidates);
  const auto& tris = a.shape->triangles();
  Vec3 sum = Vec3::Zero();
  int hits = 0;
  int first = -1;
  for (int f : s.candidates) {
    const Vec3 c = (a.vertex(tris[f][0]) + a.vertex(tris[f][1]) + a.vertex(tris[f][2])) / 3.0;
    if (!b.inside(c)) continue;
    if (first < 0) first = f;
    sum += c;  // in increasing triangle order
    ++hits;
  }
  if (hits == 0) return std::nullopt;
  ContactPoint cp;
  cp.point = sum / hits;
  // seed correction 9 (face normal negated). The seed text takes "the normal of any of the
  // collision triangles" and calls it the normal from B to A; but A's outward triangle normal
  // points from A toward B. The contact normal (from B toward A) is its negation.
  cp.normal = -a.normal(first);
  cp.depth = overlap(a, b, cp.normal);  // the seed defines no depth
  cp.feature = to_string(Feature::Face);
  return cp;
}

/// Vertex test, one order: the first vertex of A inside B, normal = outward normal of B's face
/// closest to it (no sign change: it already points from B toward A).
template <typename View>
std::optional<ContactPoint> vertex_one(const View& a, const View& b, FeatureScratch& s) {
  if (!a.may_enter()) return std::nullopt;
  a.candidates(Primitive::Vertices, b, s.candidates);
  s.hits.clear();
  for (int i : s.candidates)
    if (b.inside(a.vertex(i))) s.hits.push_back(i);
  if (s.hits.empty()) return std::nullopt;
  ContactPoint cp;
  const Vec3 first = a.vertex(s.hits[0]);
  cp.normal = b.normal(b.closest_face(first));
  // Departure from the seed, which returns the first vertex found: every vertex of A inside B
  // whose closest face of B shares that normal is averaged, as the seed's face test averages
  // its hits. With only the first vertex, an edge or face landing flat on a face (both ends
  // touch in the same step) gets its impulse at one end and a spurious spin: the "cubes
  // rotate due to collision vectors being slightly offset" that the seed reports fixing. A
  // single penetrating corner is unchanged.
  Vec3 sum = first;
  int hits = 1;
  for (std::size_t k = 1; k < s.hits.size(); ++k) {
    const Vec3 v = a.vertex(s.hits[k]);
    if (b.normal(b.closest_face(v)).dot(cp.normal) < 1.0 - 1e-9) continue;
    sum += v;
    ++hits;
  }
  cp.point = sum / hits;
  cp.depth = overlap(a, b, cp.normal);  // the seed defines no depth
  cp.feature = to_string(Feature::Vertex);
  return cp;
}

/// The contact normal of an edge hit, and the overlap along it when it was computed on the way
/// (NaN otherwise).
struct EdgeNormal {
  Vec3 normal = Vec3::Zero();
  double overlap = std::numeric_limits<double>::quiet_NaN();
};

/// seed correction 10 (edge normal e_a x e_b): the contact normal of an edge hit at p on A's edge
/// v_i + t e_a, given the planes of B the edge crosses.
template <typename View>
EdgeNormal edge_normal(const View& a, const View& b, const Vec3& v_i, const Vec3& e_a,
                       const Vec3& p, const std::vector<Crossing>& crossings) {
  const double tol = a.tol;
  // B's crossed triangle: a triangle whose plane the edge crosses at a point on the triangle
  // itself (the seed's sign test only proves the plane is crossed). The one nearest p wins;
  // if the edge crosses none (it lies wholly inside B), every triangle of B is a candidate.
  int face = -1;
  double best = std::numeric_limits<double>::infinity();
  for (const Crossing& c : crossings) {
    if (triangle_distance(b, c.face, v_i + c.t * e_a) > tol) continue;
    const double d = triangle_distance(b, c.face, p);
    if (d < best) {
      best = d;
      face = c.face;
    }
  }
  if (face < 0) face = b.nearest_triangle(p);
  // e_b: the edge of that triangle nearest p (ties: first in the triangle's order).
  const auto& t = b.shape->triangles()[face];
  Vec3 e_b = Vec3::Zero();
  best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const Vec3 s0 = b.vertex(t[k]);
    const Vec3 s1 = b.vertex(t[(k + 1) % 3]);
    const double d = segment_distance(p, s0, s1);
    if (d < best) {
      best = d;
      e_b = s1 - s0;
    }
  }
  // seed correction 10 (edge normal e_a x e_b). The seed text uses "the cross product of the edge
  // with the plane it is intersecting": e_a x n_plane lies in the plane (and is zero when the edge
  // runs along the plane normal), so it is no contact normal. The edge-edge normal is e_a x e_b.
  const Vec3 n_face = b.normal(face);
  Vec3 n = e_a.cross(e_b);
  // Parallel edges (sin of their angle below 1e-9, far above the ~1e-16 round-off of the
  // world directions) define no plane: fall back to the crossed triangle's outward normal.
  if (n.norm() <= 1e-9 * e_a.norm() * e_b.norm()) return {n_face};
  n.normalize();
  // Orientation from B toward A: of +n and -n, the one along which A overlaps B less is the
  // way out (the other sign measures nearly the sum of the extents). Ties: agree with the
  // crossed triangle's outward normal.
  const double plus = overlap(a, b, n), minus = overlap(a, b, Vec3(-n));
  const bool flip = minus < plus - tol || (std::abs(minus - plus) <= tol && n.dot(n_face) < 0.0);
  if (flip) n = -n;
  // Departure: e_a x e_b is the normal of an edge-EDGE contact. When A's edge pierces the
  // interior of B's face (an edge-face contact, e.g. a box edge crossing a wall after a face
  // hit), e_a x e_b lies in the wall and is no way out; e_b may even be the diagonal that
  // splits a square face in two, which is no edge of the solid. Of the two candidates, the one
  // that separates the bodies with the smaller translation is the contact normal (the rule a
  // separating-axis test applies to all axes, here to the two the seed's test produces).
  const double along_face = overlap(a, b, n_face);
  if (along_face < std::min(plus, minus) - tol) return {n_face, along_face};
  return {n, flip ? minus : plus};
}

/// The crossing parameters of an edge of length `length` (m), sorted with 0 and 1. Coplanar
/// triangles (a box face is two) give the same t; a pair of equal values would "average" to a
/// point on B's surface, so values closer than tol along the edge are merged and each pair
/// bounds a real interval.
inline void merged_parameters(const std::vector<Crossing>& crossings, double length, double tol,
                              std::vector<double>& ts) {
  ts.assign({0.0, 1.0});
  for (const Crossing& c : crossings) ts.push_back(c.t);
  // Insertion sort: a few values (any sort gives the same sequence).
  for (std::size_t k = 1; k < ts.size(); ++k)
    for (std::size_t m = k; m > 0 && ts[m] < ts[m - 1]; --m) std::swap(ts[m], ts[m - 1]);
  const double merge = tol / std::max(length, std::numeric_limits<double>::min());
  ts.erase(
      std::unique(ts.begin(), ts.end(), [merge](double x, double y) { return y - x <= merge; }),
      ts.end());
  if (ts.back() < 1.0) ts.back() = 1.0;  // merging may have swallowed the end
}

/// Edge test, one order: each edge of A is cut where it crosses the planes of B's triangles,
/// and the midpoint of each consecutive pair of merged parameters is tested in B; the first
/// inside is the point.
template <typename View>
std::optional<ContactPoint> edge_one(const View& a, const View& b, FeatureScratch& s) {
  if (!a.may_enter()) return std::nullopt;
  a.candidates(Primitive::Edges, b, s.candidates);
  for (int idx : s.candidates) {
    const Edge& e = a.shape->edges()[idx];
    const Vec3 v_i = a.vertex(e.a);
    const Vec3 v_j = a.vertex(e.b);
    const Vec3 e_a = v_j - v_i;
    if (b.segment_outside(a, v_i, v_j)) continue;  // no midpoint can be inside
    b.crossings(v_i, v_j, s.crossings);
    merged_parameters(s.crossings, e_a.norm(), a.tol, s.ts);
    // The midpoint of each consecutive pair, tested in B: the first inside is the point.
    for (std::size_t k = 0; k + 1 < s.ts.size(); ++k) {
      const Vec3 p = v_i + 0.5 * (s.ts[k] + s.ts[k + 1]) * e_a;
      if (!b.inside(p)) continue;
      ContactPoint cp;
      cp.point = p;
      const EdgeNormal en = edge_normal(a, b, v_i, e_a, p, s.crossings);
      cp.normal = en.normal;
      // The seed defines no depth: the overlap along the normal (edge_normal's when it has it,
      // the same expression on the same normal).
      cp.depth = std::isnan(en.overlap) ? overlap(a, b, cp.normal) : en.overlap;
      cp.feature = to_string(Feature::Edge);
      return cp;
    }
  }
  return std::nullopt;
}

/// One test, one order: A's features of that kind against B.
template <typename View>
std::optional<ContactPoint> one_order(Feature feature, const View& a, const View& b,
                                      FeatureScratch& s) {
  switch (feature) {
    case Feature::Face:
      return face_one(a, b, s);
    case Feature::Vertex:
      return vertex_one(a, b, s);
    case Feature::Edge:
      return edge_one(a, b, s);
  }
  return std::nullopt;
}

/// seed correction 8 (both orders, normal flipped). The seed loops A's features against B only, so
/// a vertex (or face, or edge) of B striking A goes unseen. Run (A, B), then (B, A) with the normal
/// flipped back to "from B toward A". The point is unchanged and the depth symmetric: max_a(a . -n)
/// - min_b(b . -n) = max_b(b . n) - min_a(a . n).
template <typename View>
std::optional<ContactPoint> both_orders(Feature feature, const View& a, const View& b,
                                        FeatureScratch& s) {
  if (auto hit = one_order(feature, a, b, s)) return hit;
  if (auto hit = one_order(feature, b, a, s)) {
    hit->normal = -hit->normal;
    return hit;
  }
  return std::nullopt;
}

/// The full detector in the seed's order: face, vertex, edge; each in both orders.
template <typename View>
std::optional<ContactPoint> all_features(const View& a, const View& b, FeatureScratch& s) {
  for (Feature feature : {Feature::Face, Feature::Vertex, Feature::Edge})
    if (auto hit = both_orders(feature, a, b, s)) return hit;
  return std::nullopt;
}

}  // namespace rbx::detail
