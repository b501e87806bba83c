// GJK for the separation distance (engine/distance.h, docs/distance.md).
#include "engine/distance.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "engine/contact_plane_detail.h"

namespace rbx {

namespace {

// A point of D = A - B: A's vertex ia less B's vertex ib (world).
struct Vertex {
  Vec3 w;
  int ia, ib;
};

using Simplex = std::array<Vertex, 4>;
using Weights = std::array<double, 4>;

// Keeps the simplex's points `keep` (indices, in order) with their weights.
void reduce(Simplex& s, int& n, Weights& l, std::initializer_list<std::pair<int, double>> keep) {
  Simplex kept;
  Weights weights{};
  int k = 0;
  for (const auto& [i, weight] : keep) {
    kept[k] = s[i];
    weights[k++] = weight;
  }
  s = kept;
  l = weights;
  n = k;
}

// The closest point to the origin of a segment or a triangle (s[0..n)), by the Voronoi region
// of the origin (Ericson, "Real-Time Collision Detection", 5.1.2 and 5.1.5): the simplex reduced
// to the feature that holds it, with its weights.
void closest_on_feature(Simplex& s, int& n, Weights& l) {
  if (n == 1) {
    l = {1.0, 0.0, 0.0, 0.0};
    return;
  }
  const Vec3 a = s[0].w, b = s[1].w;
  const Vec3 ab = b - a;
  if (n == 2) {
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0 ? std::clamp(-a.dot(ab) / len2, 0.0, 1.0) : 0.0;
    if (t <= 0) return reduce(s, n, l, {{0, 1.0}});
    if (t >= 1) return reduce(s, n, l, {{1, 1.0}});
    return reduce(s, n, l, {{0, 1.0 - t}, {1, t}});
  }
  const Vec3 c = s[2].w, ac = c - a;
  const double d1 = -ab.dot(a), d2 = -ac.dot(a);
  if (d1 <= 0 && d2 <= 0) return reduce(s, n, l, {{0, 1.0}});
  const double d3 = -ab.dot(b), d4 = -ac.dot(b);
  if (d3 >= 0 && d4 <= d3) return reduce(s, n, l, {{1, 1.0}});
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    return reduce(s, n, l, {{0, 1.0 - t}, {1, t}});
  }
  const double d5 = -ab.dot(c), d6 = -ac.dot(c);
  if (d6 >= 0 && d5 <= d6) return reduce(s, n, l, {{2, 1.0}});
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    return reduce(s, n, l, {{0, 1.0 - t}, {2, t}});
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return reduce(s, n, l, {{1, 1.0 - t}, {2, t}});
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  l = {1.0 - v - w, v, w, 0.0};
}

Vec3 mix(const Simplex& s, int n, const Weights& l) {
  Vec3 v = Vec3::Zero();
  for (int i = 0; i < n; ++i) v += l[i] * s[i].w;
  return v;
}

// The closest point to the origin of the simplex (1 to 4 points): the simplex reduced to the
// feature holding it, its weights in `l`; false when a tetrahedron holds the origin (overlap).
// A tetrahedron whose fourth point lies within `flat` (m) of a face's plane is flat (the new
// point on the same face of D as the others): it holds no volume, and round-off would give its
// faces' sides at random.
bool closest(Simplex& s, int& n, Weights& l, double flat) {
  if (n < 4) {
    closest_on_feature(s, n, l);
    return true;
  }
  // A tetrahedron: the faces whose plane has the origin on the other side from the fourth point
  // are the candidates (every face, when it is flat); none: the origin is inside.
  static constexpr std::array<std::array<int, 4>, 4> kFaces = {
      {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}}};
  bool flat_tetrahedron = false;
  for (const auto& f : kFaces) {
    const Vec3 &p = s[f[0]].w, &q = s[f[1]].w, &r = s[f[2]].w;
    const Vec3 normal = (q - p).cross(r - p);
    flat_tetrahedron |= !(std::abs(normal.dot(s[f[3]].w - p)) > flat * normal.norm());
  }
  double best = -1.0;
  Simplex best_s{};
  Weights best_l{};
  int best_n = 0;
  for (const auto& f : kFaces) {
    const Vec3 &p = s[f[0]].w, &q = s[f[1]].w, &r = s[f[2]].w;
    const Vec3 normal = (q - p).cross(r - p);
    const double origin_side = -normal.dot(p), opposite_side = normal.dot(s[f[3]].w - p);
    if (!flat_tetrahedron && origin_side * opposite_side > 0) continue;
    Simplex t = {s[f[0]], s[f[1]], s[f[2]], s[f[3]]};
    int m = 3;
    Weights w{};
    closest_on_feature(t, m, w);
    const double d2 = mix(t, m, w).squaredNorm();
    if (best < 0 || d2 < best) {
      best = d2;
      best_s = t;
      best_l = w;
      best_n = m;
    }
  }
  if (best < 0) return false;
  s = best_s;
  l = best_l;
  n = best_n;
  return true;
}

}  // namespace

Separation shape_distance(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                          const Pose& pb) {
  plane_detail::Side sa, sb;
  sa.set(a, pa);
  sb.set(b, pb);
  const double size = std::max(shape_size(a), shape_size(b));
  // The origin within this of D: touching to round-off of unit-scale world coordinates.
  const double touch2 = (1e-12 * size) * (1e-12 * size);
  // Converged when the support along -v gains less than this on |v|^2: a relative 1e-12 of the
  // distance, or round-off of the coordinates for a distance near zero.
  const double gain_floor = (1e-15 * size) * (1e-15 * size);
  Separation out;
  Simplex s{};
  Weights l{};
  int n = 0, ia = -1, ib = -1;
  // A point of D to start from: the difference of the bodies' origins (their centres of mass,
  // inside them).
  Vec3 v = pa.position - pb.position;
  if (!(v.squaredNorm() > 0)) v = Vec3::UnitX();
  // GJK on a polytope ends in finitely many steps; the cap guards against round-off cycling.
  for (int it = 0; it < 128; ++it) {
    const Vec3 d = -v;
    sa.support(d, ia);
    sb.support(-d, ib);
    const Vertex w{sa.world(ia) - sb.world(ib), ia, ib};
    if (n > 0) {
      const double vv = v.squaredNorm();
      if (vv - v.dot(w.w) <= 1e-12 * vv + gain_floor) break;
      if (std::any_of(s.begin(), s.begin() + n,
                      [&](const Vertex& x) { return x.ia == w.ia && x.ib == w.ib; }))
        break;
    }
    // GJK brings v nearer the origin at every step in exact arithmetic. Where round-off of a
    // nearly flat simplex would take it further (a wrong face of a flat tetrahedron), the last
    // simplex is the answer: it is within that round-off of the distance.
    const Simplex before = s;
    const Weights before_l = l;
    const int before_n = n;
    s[n++] = w;
    if (!closest(s, n, l, 1e-12 * size)) {
      // A tetrahedron holding the origin means overlap, unless D's support along -v stays on
      // v's side of the origin (v . w > 0: the plane through the origin normal to v separates
      // the origin from D, so the shapes are apart): then the verdict is round-off of a nearly
      // flat tetrahedron, and the last simplex is the answer.
      if (before_n > 0 && v.dot(w.w) > 0) {
        s = before;
        l = before_l;
        n = before_n;
        break;
      }
      out.overlapping = true;
      return out;
    }
    const Vec3 next = mix(s, n, l);
    if (before_n > 0 && !(next.squaredNorm() < v.squaredNorm())) {
      s = before;
      l = before_l;
      n = before_n;
      break;
    }
    v = next;
    if (v.squaredNorm() <= touch2) {
      out.overlapping = true;
      return out;
    }
  }
  for (int i = 0; i < n; ++i) {
    out.point_a += l[i] * sa.world(s[i].ia);
    out.point_b += l[i] * sb.world(s[i].ib);
  }
  out.distance = (out.point_a - out.point_b).norm();
  return out;
}

}  // namespace rbx
