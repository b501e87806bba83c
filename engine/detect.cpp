// Moore & Wilhelms narrow phase: face, vertex and edge tests, as the seed describes them, with
// the corrections of SEED_NOTES (1, 2, 8, 9, 10) marked where they apply.
//
// Design note: every public entry point first places both shapes in the world once (vertices
// and outward planes), then runs the tests on those copies, so `detect` pays one transform per
// shape per call instead of one per test and per order.
#include "engine/detect.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

namespace rbx {

namespace {

// A shape placed in the world: world vertices and world outward planes, triangle for triangle.
struct WorldShape {
  const ConvexPolyhedron* shape = nullptr;
  std::vector<Vec3> vertices;  // m, world
  std::vector<Vec3> normals;   // unit, world, outward; one per triangle
};

WorldShape to_world(const ConvexPolyhedron& shape, const Pose& pose) {
  WorldShape w;
  w.shape = &shape;
  const Mat3 r = pose.rotation();
  w.vertices.reserve(shape.vertices().size());
  for (const Vec3& v : shape.vertices()) w.vertices.push_back(r * v + pose.position);
  w.normals.reserve(shape.planes().size());
  for (const Plane& p : shape.planes()) w.normals.push_back(r * p.normal);
  return w;
}

// SEED_NOTES 1. The seed text says "taking the dot product of the point with every face
// normal" and then gives two contradictory sign rules; p . n_f depends on where the world origin
// is and is no inside test. The half-space test is (p - q_f) . n_f <= tol for every face f,
// q_f a vertex of f (here its first vertex).
bool inside(const WorldShape& mesh, const Vec3& p, double tol) {
  const auto& tris = mesh.shape->triangles();
  for (size_t f = 0; f < tris.size(); ++f)
    if ((p - mesh.vertices[tris[f][0]]).dot(mesh.normals[f]) > tol) return false;
  return true;
}

// max_b (b . n) - min_a (a . n), clamped at 0 (see overlap_along in the header).
double overlap(const WorldShape& a, const WorldShape& b, const Vec3& n) {
  double max_b = -std::numeric_limits<double>::infinity();
  double min_a = std::numeric_limits<double>::infinity();
  for (const Vec3& v : b.vertices) max_b = std::max(max_b, v.dot(n));
  for (const Vec3& v : a.vertices) min_a = std::min(min_a, v.dot(n));
  return std::max(0.0, max_b - min_a);
}

// Distance (m) from p to the segment [s0, s1].
double segment_distance(const Vec3& p, const Vec3& s0, const Vec3& s1) {
  const Vec3 d = s1 - s0;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - s0).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (p - (s0 + t * d)).norm();
}

// Distance (m) from p to triangle f of the mesh: to its plane when p projects inside the
// triangle, otherwise to the nearest of its three edges.
double triangle_distance(const WorldShape& mesh, int f, const Vec3& p) {
  const auto& t = mesh.shape->triangles()[f];
  const Vec3& n = mesh.normals[f];
  const Vec3 q[3] = {mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]};
  bool within = true;
  for (int k = 0; k < 3; ++k)
    if ((q[(k + 1) % 3] - q[k]).cross(p - q[k]).dot(n) < 0.0) within = false;
  if (within) return std::abs((p - q[0]).dot(n));
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) best = std::min(best, segment_distance(p, q[k], q[(k + 1) % 3]));
  return best;
}

// Face test, one order (see face_test in the header).
std::optional<ContactPoint> face_one(const WorldShape& a, const WorldShape& b, double tol) {
  const auto& tris = a.shape->triangles();
  Vec3 sum = Vec3::Zero();
  int hits = 0;
  int first = -1;
  // Centroid of each of A's triangles, tested in B; the hits are averaged (the seed's "better
  // collision point" for faces split into several triangles).
  for (size_t f = 0; f < tris.size(); ++f) {
    const Vec3 c = (a.vertices[tris[f][0]] + a.vertices[tris[f][1]] + a.vertices[tris[f][2]]) / 3.0;
    if (!inside(b, c, tol)) continue;
    if (first < 0) first = static_cast<int>(f);
    sum += c;
    ++hits;
  }
  if (hits == 0) return std::nullopt;
  ContactPoint cp;
  cp.point = sum / hits;
  // SEED_NOTES 9. The seed text takes "the normal of any of the collision triangles" and calls
  // it the normal from B to A; but A's outward triangle normal points from A toward B. The
  // contact normal (from B toward A) is its negation.
  cp.normal = -a.normals[first];
  // The seed defines no depth: we report the overlap of the projections on the normal.
  cp.depth = overlap(a, b, cp.normal);
  cp.feature = "face";
  return cp;
}

// Vertex test, one order (see vertex_test in the header).
// B's face closest to a point inside B: for a point inside a convex body the nearest boundary
// point lies on the nearest face plane, so plane distance suffices (ties: lowest index).
int closest_face(const WorldShape& b, const Vec3& v) {
  const auto& tris = b.shape->triangles();
  int closest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (size_t f = 0; f < tris.size(); ++f) {
    const double d = std::abs((v - b.vertices[tris[f][0]]).dot(b.normals[f]));
    if (d < best) {
      best = d;
      closest = static_cast<int>(f);
    }
  }
  return closest;
}

std::optional<ContactPoint> vertex_one(const WorldShape& a, const WorldShape& b, double tol) {
  for (size_t i = 0; i < a.vertices.size(); ++i) {
    if (!inside(b, a.vertices[i], tol)) continue;
    ContactPoint cp;
    // B's outward normal already points from B toward A: no sign change.
    cp.normal = b.normals[closest_face(b, a.vertices[i])];
    // Departure from the seed, which returns the first vertex found: every vertex of A inside B
    // whose closest face of B shares that normal is averaged, as the seed's face test averages
    // its hits. With only the first vertex, an edge or face landing flat on a face (both ends
    // touch in the same step) gets its impulse at one end and a spurious spin: the "cubes
    // rotate due to collision vectors being slightly offset" that the seed reports fixing. A
    // single penetrating corner is unchanged.
    Vec3 sum = a.vertices[i];
    int hits = 1;
    for (size_t k = i + 1; k < a.vertices.size(); ++k) {
      if (!inside(b, a.vertices[k], tol)) continue;
      if (b.normals[closest_face(b, a.vertices[k])].dot(cp.normal) < 1.0 - 1e-9) continue;
      sum += a.vertices[k];
      ++hits;
    }
    cp.point = sum / hits;
    cp.depth = overlap(a, b, cp.normal);  // the seed defines no depth
    cp.feature = "vertex";
    return cp;
  }
  return std::nullopt;
}

// One crossing of an edge of A with the plane of a triangle of B.
struct Crossing {
  double t = 0.0;  // parameter along the edge, 0 at v_i, 1 at v_j
  int face = -1;   // triangle of B
};

// SEED_NOTES 10: the contact normal of an edge hit at `p` on A's edge direction `e_a`.
Vec3 edge_normal(const WorldShape& a, const WorldShape& b, const Vec3& v_i, const Vec3& e_a,
                 const Vec3& p, const std::vector<Crossing>& crossings, double tol) {
  const auto& tris = b.shape->triangles();
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
  if (face < 0) {
    for (size_t f = 0; f < tris.size(); ++f) {
      const double d = triangle_distance(b, static_cast<int>(f), p);
      if (d < best) {
        best = d;
        face = static_cast<int>(f);
      }
    }
  }
  // e_b: the edge of that triangle nearest p (ties: first in the triangle's order).
  const auto& t = tris[face];
  Vec3 e_b = Vec3::Zero();
  best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const Vec3& s0 = b.vertices[t[k]];
    const Vec3& s1 = b.vertices[t[(k + 1) % 3]];
    const double d = segment_distance(p, s0, s1);
    if (d < best) {
      best = d;
      e_b = s1 - s0;
    }
  }
  // SEED_NOTES 10. The seed text uses "the cross product of the edge with the plane it is
  // intersecting": e_a x n_plane lies in the plane (and is zero when the edge runs along the
  // plane normal), so it is no contact normal. The edge-edge normal is e_a x e_b.
  const Vec3& n_face = b.normals[face];
  Vec3 n = e_a.cross(e_b);
  // Parallel edges (sin of their angle below 1e-9, far above the ~1e-16 round-off of the
  // world directions) define no plane: fall back to the crossed triangle's outward normal.
  if (n.norm() <= 1e-9 * e_a.norm() * e_b.norm()) return n_face;
  n.normalize();
  // Orientation from B toward A: of +n and -n, the one along which A overlaps B less is the
  // way out (the other sign measures nearly the sum of the extents). Ties: agree with the
  // crossed triangle's outward normal.
  const double plus = overlap(a, b, n), minus = overlap(a, b, -n);
  if (minus < plus - tol || (std::abs(minus - plus) <= tol && n.dot(n_face) < 0.0)) n = -n;
  // Departure: e_a x e_b is the normal of an edge-EDGE contact. When A's edge pierces the
  // interior of B's face (an edge-face contact, e.g. a box edge crossing a wall after a face
  // hit), e_a x e_b lies in the wall and is no way out; e_b may even be the diagonal that
  // splits a square face in two, which is no edge of the solid. Of the two candidates, the one
  // that separates the bodies with the smaller translation is the contact normal (the rule a
  // separating-axis test applies to all axes, here to the two the seed's test produces).
  if (overlap(a, b, n_face) < std::min(plus, minus) - tol) return n_face;
  return n;
}

// Edge test, one order (see edge_test in the header).
std::optional<ContactPoint> edge_one(const WorldShape& a, const WorldShape& b, double tol) {
  const auto& tris = b.shape->triangles();
  std::vector<Crossing> crossings;
  std::vector<double> ts;
  for (const Edge& e : a.shape->edges()) {
    const Vec3& v_i = a.vertices[e.a];
    const Vec3& v_j = a.vertices[e.b];
    const Vec3 e_a = v_j - v_i;
    // Signed distances of the ends from each triangle plane of B, d = (v - u_k1) . n; the
    // plane is crossed where the signs differ.
    crossings.clear();
    for (size_t f = 0; f < tris.size(); ++f) {
      const Vec3& u = b.vertices[tris[f][0]];
      const double d_i = (v_i - u).dot(b.normals[f]);
      const double d_j = (v_j - u).dot(b.normals[f]);
      if (!((d_i < 0.0 && d_j > 0.0) || (d_i > 0.0 && d_j < 0.0))) continue;
      // SEED_NOTES 2. The seed prints P = v_i + t (v_i - v_i), which is always v_i; the
      // crossing is P = v_i + t (v_j - v_i) with t = |d_i| / (|d_i| + |d_j|).
      crossings.push_back({std::abs(d_i) / (std::abs(d_i) + std::abs(d_j)), static_cast<int>(f)});
    }
    // The crossing parameters, sorted with 0 and 1. Coplanar triangles (a box face is two)
    // give the same t; a pair of equal values would "average" to a point on B's surface, so
    // values closer than tol along the edge are merged and each pair bounds a real interval.
    ts.assign({0.0, 1.0});
    for (const Crossing& c : crossings) ts.push_back(c.t);
    std::sort(ts.begin(), ts.end());
    const double merge = tol / std::max(e_a.norm(), std::numeric_limits<double>::min());
    ts.erase(std::unique(ts.begin(), ts.end(),
                         [merge](double x, double y) { return y - x <= merge; }),
             ts.end());
    if (ts.back() < 1.0) ts.back() = 1.0;  // merging may have swallowed the end
    // The midpoint of each consecutive pair, tested in B: the first inside is the point.
    for (size_t k = 0; k + 1 < ts.size(); ++k) {
      const Vec3 p = v_i + 0.5 * (ts[k] + ts[k + 1]) * e_a;
      if (!inside(b, p, tol)) continue;
      ContactPoint cp;
      cp.point = p;
      cp.normal = edge_normal(a, b, v_i, e_a, p, crossings, tol);
      cp.depth = overlap(a, b, cp.normal);  // the seed defines no depth
      cp.feature = "edge";
      return cp;
    }
  }
  return std::nullopt;
}

using OneOrder = std::optional<ContactPoint> (*)(const WorldShape&, const WorldShape&, double);

// SEED_NOTES 8. The seed loops A's features against B only, so a vertex (or face, or edge) of
// B striking A goes unseen. Run (A, B), then (B, A) with the normal flipped back to "from B
// toward A". The point is unchanged and the depth symmetric:
// max_a(a . -n) - min_b(b . -n) = max_b(b . n) - min_a(a . n).
std::optional<ContactPoint> both_orders(OneOrder test, const WorldShape& a, const WorldShape& b,
                                        double tol) {
  if (auto hit = test(a, b, tol)) return hit;
  if (auto hit = test(b, a, tol)) {
    hit->normal = -hit->normal;
    return hit;
  }
  return std::nullopt;
}

OneOrder feature_test(const std::string& feature) {
  if (feature == "face") return &face_one;
  if (feature == "vertex") return &vertex_one;
  if (feature == "edge") return &edge_one;
  throw std::invalid_argument("unknown contact feature '" + feature +
                              "' (expected face, vertex or edge)");
}

// Size (m) of a shape: the diagonal of its local bounding box.
double shape_size(const ConvexPolyhedron& s) { return (s.bounds().max - s.bounds().min).norm(); }

}  // namespace

double point_in_mesh_tolerance(const ConvexPolyhedron& a, const ConvexPolyhedron& b) {
  // Placing a shape in the world and evaluating (p - q_f) . n_f costs a few ulps of the
  // coordinates, ~1e-15 of the size for shapes near the origin. 1e-9 of the larger size is
  // ~10^6 times that (room for poses up to ~10^6 sizes from the origin) and still far below any
  // penetration a time step produces, so it only changes the verdict for touching bodies. It is
  // also the convexity tolerance the polyhedron validation uses.
  return 1e-9 * std::max(shape_size(a), shape_size(b));
}

bool point_in_mesh(const ConvexPolyhedron& mesh, const Pose& pose, const Vec3& p_world,
                   double tol) {
  // SEED_NOTES 1: (p - q_f) . n_f <= tol for every face (see inside() above).
  return inside(to_world(mesh, pose), p_world, tol);
}

double overlap_along(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                     const Pose& pb, const Vec3& n) {
  return overlap(to_world(a, pa), to_world(b, pb), n);
}

std::optional<ContactPoint> face_test(const ConvexPolyhedron& a, const Pose& pa,
                                      const ConvexPolyhedron& b, const Pose& pb) {
  return face_one(to_world(a, pa), to_world(b, pb), point_in_mesh_tolerance(a, b));
}

std::optional<ContactPoint> vertex_test(const ConvexPolyhedron& a, const Pose& pa,
                                        const ConvexPolyhedron& b, const Pose& pb) {
  return vertex_one(to_world(a, pa), to_world(b, pb), point_in_mesh_tolerance(a, b));
}

std::optional<ContactPoint> edge_test(const ConvexPolyhedron& a, const Pose& pa,
                                      const ConvexPolyhedron& b, const Pose& pb) {
  return edge_one(to_world(a, pa), to_world(b, pb), point_in_mesh_tolerance(a, b));
}

std::optional<ContactPoint> detect_feature(const std::string& feature, const ConvexPolyhedron& a,
                                           const Pose& pa, const ConvexPolyhedron& b,
                                           const Pose& pb, DetectorVariant variant) {
  // DetectorVariant::Fast runs the seed loops for now; a later task adds the fast path and
  // tests it against Seed.
  (void)variant;
  const OneOrder test = feature_test(feature);
  return both_orders(test, to_world(a, pa), to_world(b, pb), point_in_mesh_tolerance(a, b));
}

std::optional<ContactPoint> detect(const ConvexPolyhedron& a, const Pose& pa,
                                   const ConvexPolyhedron& b, const Pose& pb,
                                   DetectorVariant variant) {
  // DetectorVariant::Fast runs the seed loops for now (see detect_feature).
  (void)variant;
  // Both shapes go to the world once; the six tests share the copies.
  const WorldShape wa = to_world(a, pa), wb = to_world(b, pb);
  const double tol = point_in_mesh_tolerance(a, b);
  // The seed's order: face, vertex, edge; each in both orders (SEED_NOTES 8).
  for (OneOrder test : {&face_one, &vertex_one, &edge_one})
    if (auto hit = both_orders(test, wa, wb, tol)) return hit;
  return std::nullopt;
}

}  // namespace rbx
