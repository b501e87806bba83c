// GJK for the separation distance (engine/distance.h, docs/distance.md).
#include "engine/distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

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

// The closest point of segment pq to x.
Vec3 closest_on_segment(const Vec3& x, const Vec3& p, const Vec3& q) {
  const Vec3 pq = q - p;
  const double len2 = pq.squaredNorm();
  return len2 > 0 ? Vec3(p + std::clamp((x - p).dot(pq) / len2, 0.0, 1.0) * pq) : p;
}

// The closest point of triangle abc to x: x's projection on the plane when it falls inside, else
// the nearest edge's closest point. The plane from the two edges at the vertex opposite the
// longest (the largest angle, whose cross product loses least): on a sliver's long thin
// triangle, Voronoi-region weights (closest_on_feature) put the point 1e-11 off along the face.
Vec3 closest_on_triangle(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v[3] = {a, b, c};
  const double l0 = (c - b).squaredNorm(), l1 = (a - c).squaredNorm(), l2 = (b - a).squaredNorm();
  const int k = l0 >= l1 && l0 >= l2 ? 0 : l1 >= l2 ? 1 : 2;
  const Vec3 &o = v[k], e1 = v[(k + 1) % 3] - o, e2 = v[(k + 2) % 3] - o;
  const Vec3 n = e1.cross(e2);
  const double nn = n.squaredNorm();
  if (nn > 0) {
    const Vec3 d = x - o;
    const double u1 = d.cross(e2).dot(n) / nn, u2 = e1.cross(d).dot(n) / nn;
    if (u1 >= 0 && u2 >= 0 && u1 + u2 <= 1) return x - n * (n.dot(d) / nn);
  }
  Vec3 best = closest_on_segment(x, a, b);
  for (const Vec3& q : {closest_on_segment(x, b, c), closest_on_segment(x, c, a)})
    if ((q - x).squaredNorm() < (best - x).squaredNorm()) best = q;
  return best;
}

// The closest points of segments p0p1 and q0q1 (Ericson 5.1.9, clamped parameters).
void closest_of_segments(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, Vec3& on_p,
                         Vec3& on_q) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 0 && e <= 0) {
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
  on_p = p0 + s * d1;
  on_q = q0 + t * d2;
}

// One shape's neighbourhood of some of its vertices, placed relative to a world point `o`: the
// triangles that use any of them (corners as local indices into `points`), the points, and
// the triangles' edges.
struct Patch {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::pair<int, int>> edges;
};

Patch patch_around(const plane_detail::Side& side, const std::vector<int>& around, const Vec3& o) {
  Patch out;
  std::vector<int> local(side.shape->vertices().size(), -1);
  // The pose's translation less o first, so that the points carry round-off of their distance
  // from o, not of their distance from the world origin.
  const Vec3 shift = side.p - o;
  auto point = [&](int v) {
    if (local[v] < 0) {
      local[v] = static_cast<int>(out.points.size());
      out.points.push_back(side.r * side.shape->vertices()[v] + shift);
    }
    return local[v];
  };
  for (const auto& t : side.shape->triangles()) {
    if (std::none_of(t.begin(), t.end(), [&](int v) {
          return std::find(around.begin(), around.end(), v) != around.end();
        }))
      continue;
    const std::array<int, 3> c = {point(t[0]), point(t[1]), point(t[2])};
    out.triangles.push_back(c);
    for (int k = 0; k < 3; ++k) out.edges.push_back({c[k], c[(k + 1) % 3]});
  }
  return out;
}

// The closest pair between two patches by every vertex-triangle and edge-edge pair (the
// oracle's enumeration, on the neighbourhoods only): each candidate a pair of points on the
// shapes, so the nearest is an upper bound on the distance whatever the patches hold.
void closest_between(const Patch& pa, const Patch& pb, double& best2, Vec3& on_a, Vec3& on_b) {
  auto take = [&](const Vec3& x, const Vec3& y) {
    const double d2 = (x - y).squaredNorm();
    if (d2 < best2) {
      best2 = d2;
      on_a = x;
      on_b = y;
    }
  };
  for (const Vec3& x : pa.points)
    for (const auto& t : pb.triangles)
      take(x, closest_on_triangle(x, pb.points[t[0]], pb.points[t[1]], pb.points[t[2]]));
  for (const Vec3& y : pb.points)
    for (const auto& t : pa.triangles)
      take(closest_on_triangle(y, pa.points[t[0]], pa.points[t[1]], pa.points[t[2]]), y);
  for (const auto& ea : pa.edges)
    for (const auto& eb : pb.edges) {
      Vec3 x, y;
      closest_of_segments(pa.points[ea.first], pa.points[ea.second], pb.points[eb.first],
                          pb.points[eb.second], x, y);
      take(x, y);
    }
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
  // D's last support and its vertices: where the search stopped looking.
  Vec3 last_support = Vec3::Zero();
  int last_ia = -1, last_ib = -1;
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
    last_support = w.w;
    last_ia = ia;
    last_ib = ib;
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
  // Certified when D's support along -v reaches within a relative 1e-9 of |v| (v . w / |v| is a
  // lower bound on the distance, |v| an upper one). A search that stopped short of that (a
  // repeated support or a step that did not shrink |v|: the simplex's round-off, at gaps of
  // 1e-9 of the size and on slivers, tilts v so that the next support stays in the simplex) is
  // finished on the neighbourhoods of the supports it reached, pair by pair in closed form and
  // relative to its own point on A: every candidate is a pair of points of the shapes, an upper
  // bound on the distance as |v| is, so the nearer answer is kept.
  const double lower = n > 0 ? v.dot(last_support) / v.norm() : 0.0;
  if (lower < (1.0 - 1e-9) * out.distance) {
    std::vector<int> around_a, around_b;
    for (int i = 0; i < n; ++i) {
      around_a.push_back(s[i].ia);
      around_b.push_back(s[i].ib);
    }
    around_a.push_back(last_ia);
    around_b.push_back(last_ib);
    const Vec3 o = out.point_a;
    double best2 = std::numeric_limits<double>::infinity();
    Vec3 on_a = Vec3::Zero(), on_b = Vec3::Zero();
    closest_between(patch_around(sa, around_a, o), patch_around(sb, around_b, o), best2, on_a,
                    on_b);
    // Its points lie on the features they were computed on, where the stalled simplex's mix
    // can stray off its body by its round-off: at the same distance to round-off of the
    // coordinates (1e-15 of the size), the closed form's pair is kept.
    if (std::sqrt(best2) <= out.distance + 1e-15 * size) {
      out.point_a = on_a + o;
      out.point_b = on_b + o;
      out.distance = std::sqrt(best2);
    }
  }
  return out;
}

}  // namespace rbx
