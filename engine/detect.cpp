// Moore & Wilhelms narrow phase: face, vertex and edge tests, as the seed describes them, with
// the corrections of SEED_NOTES (1, 2, 8, 9, 10) marked where they apply.
//
// Design note: every public entry point first places both shapes in the world once (vertices
// and outward planes), then runs the tests on those copies, so `detect` pays one transform per
// shape per call instead of one per test and per order.
#include "engine/detect.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <unordered_map>
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

namespace {

// ---------------------------------------------------------------------------------------------
// The fast detector (DetectorVariant::Fast): the same tests, the same answers, less work.
//
// Design note. The seed's answers depend on order ("the first triangle whose centroid is
// inside", "the first vertex", "the first edge with an inside midpoint") and on exact
// floating-point expressions (the tolerance comparisons, the averaged points). The fast path
// therefore never changes a formula: every value that reaches an answer (a plane distance, a
// centroid, a crossing parameter, a dot product for the depth) is computed by the seed's own
// expression on the seed's own world-frame data, so the results are bit-for-bit the seed's.
// What changes is which of those expressions get evaluated:
//   - Candidates. A point of A can only be inside B if it lies inside every face plane of B
//     (plus the tolerance), so A's triangles, vertices and edges are culled against a few of
//     B's face planes (the one facing A, and the ones extreme along B's axes) using a bounding
//     volume hierarchy over A in its body frame. The survivors are sorted by index, so "the
//     first" is the seed's first.
//   - Point in mesh. The seed checks every face; here a hierarchy over B's triangles bounds
//     the plane distance of a whole cluster of faces at once (a cone of normals and a range of
//     plane offsets), certifying the cluster without visiting it. Only faces whose bound comes
//     within a safety margin of the tolerance are evaluated with the seed's expression.
//   - Depth, closest face, plane crossings and the nearest triangle: branch and bound over the
//     same hierarchies, with exact evaluation at the leaves.
// Every bound is computed in a body frame and carries a safety margin (kMarginScale times the
// coordinate scale of the query, ~10^5 times the round-off of either computation), so a bound
// only ever skips primitives whose exact value is far on the safe side of the comparison.
//
//   - Whole orders. Before the tests, each shape's facing face (its face most along the line to
//     the other's centre) is found; a shape lying wholly outside one face plane of the other
//     skips that order, and every point-in-mesh test tries the facing face first.
//
// The hierarchies depend only on the shape, which is immutable, so they are built once per
// shape and cached per thread, keyed by the shape's address and checked against a fingerprint
// of it (see accel_for). Shapes of at most kSmallTriangles triangles (boxes, low prisms) skip
// the hierarchies: their world vertices and normals are computed once per query into reused
// buffers and the seed's loops run on them, without the seed's allocations; for two such
// shapes a table of every vertex's distance to every distinct face plane of the other culls
// vertices, centroids and edges (see fill_plane_table, candidates). The world asks for the
// three tests of a pair in turn at the same poses, so the last pair's preparation is reused
// when its inputs are identical (see prepare).

namespace fast {

// Shapes with at most this many triangles run plain loops (a box has 12): below that, a
// hierarchy costs more to traverse than the faces it would skip.
constexpr int kSmallTriangles = 32;
// Primitives per leaf of the hierarchies.
constexpr int kLeafSize = 4;
// Safety margin of every bound, relative to the query's coordinate scale (m): the exact and the
// bounding computations each carry a few ulps (~1e-16) of the coordinates; 1e-10 is far above
// both and still far below any distance that decides a test.
constexpr double kMarginScale = 1e-10;
// Cached hierarchies per thread before the cache is emptied and rebuilt on demand.
constexpr std::size_t kCacheCapacity = 4096;

// Node of a bounding volume hierarchy over the primitives of one shape, in its body frame.
struct Node {
  Vec3 center = Vec3::Zero();  // m, centre of the primitives' bounding box
  Vec3 half = Vec3::Zero();    // m, half extents of that box
  int child = -1;              // first child (the second is child + 1); -1 for a leaf
  int begin = 0, end = 0;      // the primitives order[begin, end)
};

// Bounds on the face planes of a node of the triangle hierarchy. For a face f of the node, with
// outward normal n_f and vertex q_f, the seed's plane distance of a point p is
// s_f(p) = n_f . (p - q_f) = n_f . (p - c) - e_f, c the node's box centre and
// e_f = n_f . (q_f - c). The normals lie in a cone (axis, half-angle t), so with w = p - c at an
// angle phi from the axis, n_f . w <= |w| cos(max(0, phi - t)), and e_f is in [e_min, e_max].
struct FaceCone {
  Vec3 axis = Vec3::UnitZ();  // unit, body frame
  double cos_half = -1.0;     // cosine and sine of the half-angle, widened by round-off
  double sin_half = 0.0;
  double e_min = 0.0, e_max = 0.0;  // m, plane offsets from the node centre
};

// A hierarchy: nodes (nodes[0] the root) and the primitive indices grouped by leaf.
struct Tree {
  std::vector<Node> nodes;
  std::vector<int> order;
};

// Identity of a shape, checked on every cache hit: the address of a destroyed shape may be
// reused by a new one, which then has new buffers or new contents.
struct Fingerprint {
  const void* vertices = nullptr;
  const void* triangles = nullptr;
  std::size_t num_vertices = 0, num_triangles = 0, num_edges = 0;
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();
  std::vector<Vec3> vertex_samples;                  // every stride-th vertex
  std::vector<std::array<int, 3>> triangle_samples;  // every stride-th triangle

  static Fingerprint of(const ConvexPolyhedron& s) {
    Fingerprint f;
    f.vertices = s.vertices().data();
    f.triangles = s.triangles().data();
    f.num_vertices = s.vertices().size();
    f.num_triangles = s.triangles().size();
    f.num_edges = s.edges().size();
    f.min = s.bounds().min;
    f.max = s.bounds().max;
    // 64 samples of each: a constant cost per query, whatever the size of the shape.
    const std::size_t sv = std::max<std::size_t>(1, f.num_vertices / 64);
    for (std::size_t i = 0; i < f.num_vertices; i += sv) f.vertex_samples.push_back(s.vertices()[i]);
    const std::size_t st = std::max<std::size_t>(1, f.num_triangles / 64);
    for (std::size_t i = 0; i < f.num_triangles; i += st)
      f.triangle_samples.push_back(s.triangles()[i]);
    return f;
  }
  bool matches(const ConvexPolyhedron& s) const {
    if (s.vertices().data() != vertices || s.triangles().data() != triangles ||
        s.vertices().size() != num_vertices || s.triangles().size() != num_triangles ||
        s.edges().size() != num_edges || s.bounds().min != min || s.bounds().max != max)
      return false;
    const std::size_t sv = std::max<std::size_t>(1, num_vertices / 64);
    for (std::size_t i = 0, k = 0; i < num_vertices; i += sv, ++k)
      if (s.vertices()[i] != vertex_samples[k]) return false;
    const std::size_t st = std::max<std::size_t>(1, num_triangles / 64);
    for (std::size_t i = 0, k = 0; i < num_triangles; i += st, ++k)
      if (s.triangles()[i] != triangle_samples[k]) return false;
    return true;
  }
};

// Everything the fast path precomputes for one shape, in its body frame.
struct Accel {
  Fingerprint fingerprint;
  Tree triangles;               // over triangles (boxes of their three vertices)
  std::vector<FaceCone> cones;  // one per node of `triangles`
  Tree vertices;                // over vertices
  Tree edges;                   // over edges (boxes of their two ends)
  std::array<int, 6> axis_faces{};  // the face whose normal is most along +x, -x, +y, ... z
};

// Builds a hierarchy over primitives given by their bounding boxes: top-down, splitting each
// node at the median of the primitives' centres along the longest axis of those centres.
Tree build_tree(const std::vector<Vec3>& lo, const std::vector<Vec3>& hi) {
  Tree t;
  const int n = static_cast<int>(lo.size());
  t.order.resize(n);
  for (int i = 0; i < n; ++i) t.order[i] = i;
  t.nodes.reserve(2 * (n / kLeafSize + 1));
  t.nodes.push_back({});
  t.nodes[0].begin = 0;
  t.nodes[0].end = n;
  std::vector<int> work = {0};
  while (!work.empty()) {
    const int k = work.back();
    work.pop_back();
    const int b = t.nodes[k].begin, e = t.nodes[k].end;
    // Bounding box of the primitives, and of their centres.
    Vec3 box_lo = lo[t.order[b]], box_hi = hi[t.order[b]];
    Vec3 c_lo = 0.5 * (box_lo + box_hi), c_hi = c_lo;
    for (int i = b + 1; i < e; ++i) {
      const int p = t.order[i];
      box_lo = box_lo.cwiseMin(lo[p]);
      box_hi = box_hi.cwiseMax(hi[p]);
      const Vec3 c = 0.5 * (lo[p] + hi[p]);
      c_lo = c_lo.cwiseMin(c);
      c_hi = c_hi.cwiseMax(c);
    }
    t.nodes[k].center = 0.5 * (box_lo + box_hi);
    t.nodes[k].half = 0.5 * (box_hi - box_lo);
    if (e - b <= kLeafSize) continue;
    // Median split along the longest axis of the centres.
    int axis = 0;
    (c_hi - c_lo).maxCoeff(&axis);
    const int mid = (b + e) / 2;
    std::nth_element(t.order.begin() + b, t.order.begin() + mid, t.order.begin() + e,
                     [&](int x, int y) {
                       const double cx = lo[x][axis] + hi[x][axis], cy = lo[y][axis] + hi[y][axis];
                       return cx < cy || (cx == cy && x < y);
                     });
    const int child = static_cast<int>(t.nodes.size());
    t.nodes[k].child = child;
    t.nodes.push_back({});
    t.nodes.push_back({});
    t.nodes[child].begin = b;
    t.nodes[child].end = mid;
    t.nodes[child + 1].begin = mid;
    t.nodes[child + 1].end = e;
    work.push_back(child);
    work.push_back(child + 1);
  }
  return t;
}

std::unique_ptr<Accel> build_accel(const ConvexPolyhedron& s) {
  auto acc = std::make_unique<Accel>();
  acc->fingerprint = Fingerprint::of(s);
  const auto& v = s.vertices();
  const auto& tris = s.triangles();
  const auto& planes = s.planes();
  std::vector<Vec3> lo, hi;
  // Triangles, with their normal cones and plane offsets per node.
  for (const auto& t : tris) {
    lo.push_back(v[t[0]].cwiseMin(v[t[1]]).cwiseMin(v[t[2]]));
    hi.push_back(v[t[0]].cwiseMax(v[t[1]]).cwiseMax(v[t[2]]));
  }
  acc->triangles = build_tree(lo, hi);
  acc->cones.resize(acc->triangles.nodes.size());
  for (std::size_t k = 0; k < acc->triangles.nodes.size(); ++k) {
    const Node& node = acc->triangles.nodes[k];
    FaceCone& cone = acc->cones[k];
    Vec3 sum = Vec3::Zero();
    for (int i = node.begin; i < node.end; ++i) sum += planes[acc->triangles.order[i]].normal;
    cone.axis = sum.norm() > 1e-6 ? Vec3(sum.normalized())
                                  : planes[acc->triangles.order[node.begin]].normal;
    double c = 1.0;
    cone.e_min = std::numeric_limits<double>::infinity();
    cone.e_max = -cone.e_min;
    for (int i = node.begin; i < node.end; ++i) {
      const int f = acc->triangles.order[i];
      c = std::min(c, cone.axis.dot(planes[f].normal));
      const double e = planes[f].normal.dot(v[tris[f][0]] - node.center);
      cone.e_min = std::min(cone.e_min, e);
      cone.e_max = std::max(cone.e_max, e);
    }
    // Widen the cone by more than the round-off of the dot products (a cosine of exactly 1 would
    // otherwise hide an angle of up to ~1e-8 rad).
    cone.cos_half = std::max(-1.0, c - 1e-15);
    cone.sin_half = std::min(1.0, std::sqrt(std::max(0.0, 1.0 - cone.cos_half * cone.cos_half)) +
                                      1e-12);
  }
  // Vertices.
  acc->vertices = build_tree(v, v);
  // Edges.
  lo.clear();
  hi.clear();
  for (const Edge& e : s.edges()) {
    lo.push_back(v[e.a].cwiseMin(v[e.b]));
    hi.push_back(v[e.a].cwiseMax(v[e.b]));
  }
  acc->edges = build_tree(lo, hi);
  // The faces most along each axis direction: cull planes that approximate the bounding box.
  for (int k = 0; k < 6; ++k) {
    const Vec3 dir = (k % 2 == 0 ? 1.0 : -1.0) * Vec3::Unit(k / 2);
    double best = -2.0;
    for (std::size_t f = 0; f < planes.size(); ++f) {
      if (planes[f].normal.dot(dir) > best) {
        best = planes[f].normal.dot(dir);
        acc->axis_faces[k] = static_cast<int>(f);
      }
    }
  }
  return acc;
}

// The hierarchies of a shape, from the per-thread cache (built on first use). The shape is
// immutable, so they stay valid as long as the shape lives; a shape destroyed and another built
// at the same address is told apart by the fingerprint (its buffers' addresses, sizes, bounds
// and 64 sampled vertices and triangles).
const Accel& accel_for(const ConvexPolyhedron& s) {
  thread_local std::unordered_map<const ConvexPolyhedron*, std::unique_ptr<Accel>> cache;
  auto it = cache.find(&s);
  if (it != cache.end() && it->second->fingerprint.matches(s)) return *it->second;
  if (cache.size() >= kCacheCapacity) cache.clear();
  auto& slot = cache[&s];
  slot = build_accel(s);
  return *slot;
}

// A shape placed in the world for one query. World vertices and normals are computed with the
// seed's expressions (to_world): r * v + position and r * normal, so they are bit-identical.
struct Placed {
  const ConvexPolyhedron* shape = nullptr;
  const Accel* accel = nullptr;  // null: small shape, plain loops over world copies
  Mat3 r = Mat3::Identity();     // body to world
  Mat3 rt = Mat3::Identity();    // world to body
  Vec3 position = Vec3::Zero();  // m, world
  const Vec3* world_vertices = nullptr;  // small shapes only
  const Vec3* world_normals = nullptr;   // small shapes only
  const unsigned char* distinct = nullptr;  // small shapes: 1 where a face's normal differs
                                            // from the previous face's (a new plane)
  int facing = -1;  // the face most along the direction toward the other shape (see facing_face)
  bool may_enter = true;  // false: no point of this shape can be inside the other (prepare_pair)
  // Two small shapes: the seed's plane distance of each of this shape's vertices from each
  // distinct face plane of the other, vertex-major (prepare_pair); null otherwise.
  const double* plane_table = nullptr;
  int table_planes = 0;  // columns of plane_table

  int num_triangles() const { return static_cast<int>(shape->triangles().size()); }
  __attribute__((always_inline)) Vec3 vertex(int i) const {
    if (world_vertices) return world_vertices[i];
    return r * shape->vertices()[i] + position;
  }
  __attribute__((always_inline)) Vec3 normal(int f) const {
    if (world_normals) return world_normals[f];
    return r * shape->planes()[f].normal;
  }
  Vec3 to_local(const Vec3& p) const { return rt * (p - position); }
};

// Per-thread buffers for the world copies of small shapes (two shapes per query).
struct SmallBuffers {
  std::vector<Vec3> vertices[2], normals[2];
  std::vector<unsigned char> distinct[2];
};

Placed place(const ConvexPolyhedron& shape, const Pose& pose, int slot) {
  Placed p;
  p.shape = &shape;
  p.r = pose.rotation();
  p.rt = p.r.transpose();
  p.position = pose.position;
  if (static_cast<int>(shape.triangles().size()) > kSmallTriangles) {
    p.accel = &accel_for(shape);
    return p;
  }
  thread_local SmallBuffers buffers;
  std::vector<Vec3>& wv = buffers.vertices[slot];
  std::vector<Vec3>& wn = buffers.normals[slot];
  // The seed's to_world, into reused buffers.
  wv.resize(shape.vertices().size());
  for (std::size_t i = 0; i < wv.size(); ++i) wv[i] = p.r * shape.vertices()[i] + pose.position;
  wn.resize(shape.planes().size());
  // Coplanar triangles (a box face is two) share their normal bit for bit; the same input
  // gives the same product, so it is computed once.
  const auto& planes = shape.planes();
  std::vector<unsigned char>& distinct = buffers.distinct[slot];
  distinct.resize(wn.size());
  for (std::size_t f = 0; f < wn.size(); ++f) {
    distinct[f] = f == 0 || planes[f].normal != planes[f - 1].normal;
    wn[f] = distinct[f] ? Vec3(p.r * planes[f].normal) : wn[f - 1];
  }
  p.world_vertices = wv.data();
  p.world_normals = wn.data();
  p.distinct = distinct.data();
  return p;
}

// The constants of one query: the tolerance of the seed and the safety margin of the bounds.
struct Limits {
  double tol = 0.0;     // m, point-in-mesh tolerance (point_in_mesh_tolerance)
  double margin = 0.0;  // m, safety margin of every bound
};

// (p - q) . n, written out in the order Eigen's dot product of 3-vectors adds the terms,
// ((x + y) + z): bit-identical to the seed's Eigen expression (the fast path's tests compare
// the two exactly), in fewer instructions than Eigen's shuffles of unaligned 3-vectors.
__attribute__((always_inline)) inline double plane_dist(const Vec3& p, const Vec3& q,
                                                        const Vec3& n) {
  return ((p.x() - q.x()) * n.x() + (p.y() - q.y()) * n.y()) + (p.z() - q.z()) * n.z();
}
// v . n in the same order as Eigen's dot.
__attribute__((always_inline)) inline double dot3(const Vec3& v, const Vec3& n) {
  return (v.x() * n.x() + v.y() * n.y()) + v.z() * n.z();
}

// The seed's plane distance of p from face f of y: (p - q_f) . n_f, q_f its first vertex.
__attribute__((always_inline)) inline double plane_distance(const Placed& y, int f, const Vec3& p) {
  if (y.world_vertices)
    return plane_dist(p, y.world_vertices[y.shape->triangles()[f][0]], y.world_normals[f]);
  return plane_dist(p, y.vertex(y.shape->triangles()[f][0]), y.normal(f));
}

// Bounds [lo, hi] (m) on the plane distances s_f(p) of every face of node k of y's triangle
// hierarchy, p given in y's body frame (see FaceCone).
void plane_bounds(const Accel& acc, int k, const Vec3& p_local, double& lo, double& hi) {
  const Node& node = acc.triangles.nodes[k];
  const FaceCone& cone = acc.cones[k];
  const Vec3 w = p_local - node.center;
  const double len = w.norm();
  const double along = cone.axis.dot(w);              // |w| cos(phi)
  const double across = cone.axis.cross(w).norm();    // |w| sin(phi), accurate for small phi
  // max over the cone of n . w: |w| if w is inside the cone, else |w| cos(phi - t).
  const double n_max = along >= len * cone.cos_half ? len : along * cone.cos_half + across * cone.sin_half;
  // min over the cone of n . w: -|w| if -w is inside the cone, else |w| cos(phi + t).
  const double n_min = -along >= len * cone.cos_half ? -len : along * cone.cos_half - across * cone.sin_half;
  hi = n_max - cone.e_min;
  lo = n_min - cone.e_max;
}

// Small explicit stack for the traversals (a hierarchy over 2^31 primitives is < 64 deep; the
// traversals push at most two entries per level).
template <typename T>
struct Stack {
  T items[256];
  int size = 0;
  void push(const T& t) { items[size++] = t; }
  T pop() { return items[--size]; }
  bool empty() const { return size == 0; }
};

// SEED_NOTES 1 point in mesh, the seed's predicate exactly: (p - q_f) . n_f <= tol for every
// face. Small shapes: the seed's loop. Others: clusters of faces whose bound is at most
// tol - margin are certified without evaluating them; the rest are evaluated exactly, and the
// first face found outside ends the search (the answer is an AND, so order does not matter).
bool inside(const Placed& y, const Vec3& p, const Limits& lim) {
  // The face toward the other shape first: most points of the other shape are outside it.
  if (y.facing >= 0 && plane_distance(y, y.facing, p) > lim.tol) return false;
  if (!y.accel) {
    // The seed's loop on the world copies.
    const auto& tris = y.shape->triangles();
    const Vec3* wv = y.world_vertices;
    const Vec3* wn = y.world_normals;
    const int n = y.num_triangles();
    for (int f = 0; f < n; ++f)
      if (plane_dist(p, wv[tris[f][0]], wn[f]) > lim.tol) return false;
    return true;
  }
  const Accel& acc = *y.accel;
  const Vec3 pl = y.to_local(p);
  const double certified = lim.tol - lim.margin;
  auto bound = [&](int k) {
    double lo, hi;
    plane_bounds(acc, k, pl, lo, hi);
    return hi;
  };
  Stack<std::pair<int, double>> stack;
  stack.push({0, bound(0)});
  while (!stack.empty()) {
    const auto [k, hi] = stack.pop();
    if (hi <= certified) continue;
    const Node& node = acc.triangles.nodes[k];
    if (node.child < 0) {
      for (int i = node.begin; i < node.end; ++i)
        if (plane_distance(y, acc.triangles.order[i], p) > lim.tol) return false;
      continue;
    }
    // Visit the child more likely to hold an outside face first (the larger bound).
    const double hi0 = bound(node.child), hi1 = bound(node.child + 1);
    if (hi0 > hi1) {
      stack.push({node.child + 1, hi1});
      stack.push({node.child, hi0});
    } else {
      stack.push({node.child, hi0});
      stack.push({node.child + 1, hi1});
    }
  }
  return true;
}

// max over y's vertices of (world vertex) . n, the seed's expression (overlap()).
double support_max(const Placed& y, const Vec3& n, const Limits& lim) {
  double best = -std::numeric_limits<double>::infinity();
  const int nv = static_cast<int>(y.shape->vertices().size());
  if (!y.accel) {
    for (int i = 0; i < nv; ++i) best = std::max(best, dot3(y.world_vertices[i], n));
    return best;
  }
  // Branch and bound: a node's bound is the max of n . x over its box, in world terms.
  const Tree& tree = y.accel->vertices;
  const Vec3 nl = y.rt * n;
  const double offset = y.position.dot(n);
  auto bound = [&](int k) {
    const Node& node = tree.nodes[k];
    return node.center.dot(nl) + node.half.dot(nl.cwiseAbs()) + offset;
  };
  Stack<std::pair<int, double>> stack;
  stack.push({0, bound(0)});
  while (!stack.empty()) {
    const auto [k, b] = stack.pop();
    if (b + lim.margin < best) continue;
    const Node& node = tree.nodes[k];
    if (node.child < 0) {
      for (int i = node.begin; i < node.end; ++i)
        best = std::max(best, y.vertex(tree.order[i]).dot(n));
      continue;
    }
    const double b0 = bound(node.child), b1 = bound(node.child + 1);
    if (b0 > b1) {
      stack.push({node.child + 1, b1});
      stack.push({node.child, b0});
    } else {
      stack.push({node.child, b0});
      stack.push({node.child + 1, b1});
    }
  }
  return best;
}

// min over x's vertices of (world vertex) . n. Negating n negates every product and sum
// exactly, so this is exactly minus the max along -n.
double support_min(const Placed& x, const Vec3& n, const Limits& lim) {
  return -support_max(x, -n, lim);
}

// The seed's overlap(): max_b (b . n) - min_a (a . n), clamped at 0.
double overlap(const Placed& a, const Placed& b, const Vec3& n, const Limits& lim) {
  return std::max(0.0, support_max(b, n, lim) - support_min(a, n, lim));
}

// The seed's closest_face(): argmin over faces of |s_f(v)|, ties to the lowest index.
int closest_face(const Placed& y, const Vec3& v, const Limits& lim) {
  int closest = 0;
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](int f) {
    const double d = std::abs(plane_distance(y, f, v));
    if (d < best || (d == best && f < closest)) {
      best = d;
      closest = f;
    }
  };
  if (!y.accel) {
    for (int f = 0; f < y.num_triangles(); ++f) consider(f);
    return closest;
  }
  const Accel& acc = *y.accel;
  const Vec3 vl = y.to_local(v);
  // Lower bound of |s_f| over a node from the bounds on s_f.
  auto bound = [&](int k) {
    double lo, hi;
    plane_bounds(acc, k, vl, lo, hi);
    return lo > 0.0 ? lo : (hi < 0.0 ? -hi : 0.0);
  };
  Stack<std::pair<int, double>> stack;
  stack.push({0, bound(0)});
  while (!stack.empty()) {
    const auto [k, b] = stack.pop();
    if (b - lim.margin > best) continue;  // cannot reach (or tie) the best
    const Node& node = acc.triangles.nodes[k];
    if (node.child < 0) {
      for (int i = node.begin; i < node.end; ++i) consider(acc.triangles.order[i]);
      continue;
    }
    const double b0 = bound(node.child), b1 = bound(node.child + 1);
    if (b0 < b1) {
      stack.push({node.child + 1, b1});
      stack.push({node.child, b0});
    } else {
      stack.push({node.child, b0});
      stack.push({node.child + 1, b1});
    }
  }
  return closest;
}

// The seed's crossings of the segment [v_i, v_j] with the planes of y's triangles: planes
// where the two signed distances have strictly opposite signs, t = |d_i| / (|d_i| + |d_j|), in
// face order. Clusters whose two ends are certainly on the same side of every plane are skipped.
void crossings(const Placed& y, const Vec3& v_i, const Vec3& v_j, const Limits& lim,
               std::vector<Crossing>& out) {
  out.clear();
  const auto& tris = y.shape->triangles();
  auto consider = [&](int f) {
    const Vec3 u = y.vertex(tris[f][0]);
    const Vec3 n = y.normal(f);
    const double d_i = (v_i - u).dot(n);
    const double d_j = (v_j - u).dot(n);
    if (!((d_i < 0.0 && d_j > 0.0) || (d_i > 0.0 && d_j < 0.0))) return;
    out.push_back({std::abs(d_i) / (std::abs(d_i) + std::abs(d_j)), f});
  };
  if (!y.accel) {
    for (int f = 0; f < y.num_triangles(); ++f) consider(f);
    return;
  }
  const Accel& acc = *y.accel;
  const Vec3 pi = y.to_local(v_i), pj = y.to_local(v_j);
  Stack<int> stack;
  stack.push(0);
  while (!stack.empty()) {
    const int k = stack.pop();
    double lo_i, hi_i, lo_j, hi_j;
    plane_bounds(acc, k, pi, lo_i, hi_i);
    plane_bounds(acc, k, pj, lo_j, hi_j);
    // Both ends strictly inside every plane of the cluster, or both strictly outside.
    if (hi_i + lim.margin < 0.0 && hi_j + lim.margin < 0.0) continue;
    if (lo_i - lim.margin > 0.0 && lo_j - lim.margin > 0.0) continue;
    const Node& node = acc.triangles.nodes[k];
    if (node.child < 0) {
      for (int i = node.begin; i < node.end; ++i) consider(acc.triangles.order[i]);
      continue;
    }
    stack.push(node.child);
    stack.push(node.child + 1);
  }
  std::sort(out.begin(), out.end(), [](const Crossing& x, const Crossing& z) { return x.face < z.face; });
}

// The seed's triangle_distance() on a placed shape (same expressions).
double triangle_distance(const Placed& y, int f, const Vec3& p) {
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

// The triangle of y nearest p (the seed's fallback in edge_normal): argmin of
// triangle_distance, ties to the lowest index. Branch and bound on the distance to node boxes.
int nearest_triangle(const Placed& y, const Vec3& p, const Limits& lim) {
  int face = -1;
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](int f) {
    const double d = triangle_distance(y, f, p);
    if (face < 0 || d < best || (d == best && f < face)) {
      best = d;
      face = f;
    }
  };
  if (!y.accel) {
    for (int f = 0; f < y.num_triangles(); ++f) consider(f);
    return face;
  }
  const Accel& acc = *y.accel;
  const Vec3 pl = y.to_local(p);
  auto bound = [&](int k) {
    const Node& node = acc.triangles.nodes[k];
    return ((pl - node.center).cwiseAbs() - node.half).cwiseMax(0.0).norm();
  };
  Stack<std::pair<int, double>> stack;
  stack.push({0, bound(0)});
  while (!stack.empty()) {
    const auto [k, b] = stack.pop();
    if (b - lim.margin > best) continue;
    const Node& node = acc.triangles.nodes[k];
    if (node.child < 0) {
      for (int i = node.begin; i < node.end; ++i) consider(acc.triangles.order[i]);
      continue;
    }
    const double b0 = bound(node.child), b1 = bound(node.child + 1);
    if (b0 < b1) {
      stack.push({node.child + 1, b1});
      stack.push({node.child, b0});
    } else {
      stack.push({node.child, b0});
      stack.push({node.child + 1, b1});
    }
  }
  return face;
}

// A face plane of y used to cull x's primitives: every point p of a hit must have
// s(p) = (p - q) . n <= tol for it (the seed's inside() checks every face). Precomputed for x's
// body frame: s(x.r c + x.position) = c . m + c0, with m = x.rt n and c0 = (x.position - q) . n.
struct CullPlane {
  Vec3 m = Vec3::Zero();
  Vec3 m_abs = Vec3::Zero();
  double c0 = 0.0;
  Vec3 normal = Vec3::Zero();  // world, the seed's n_f
  Vec3 point = Vec3::Zero();   // m, world, the seed's q_f
  /// The seed's plane distance (p - q_f) . n_f of a world point.
  double distance(const Vec3& p) const { return (p - point).dot(normal); }
};

// Which primitives of x a test looks at.
enum class Kind { Triangles, Vertices, Edges };

// The face of y whose outward normal is most along the direction from y's centre (of its
// bounding box) to x's: for shapes in contact, the face plane most likely to have x's points
// outside it. -1 when the centres coincide.
int facing_face(const Placed& y, const Placed& x) {
  const Vec3 cy = y.r * y.shape->bounds().center() + y.position;
  const Vec3 cx = x.r * x.shape->bounds().center() + x.position;
  const Vec3 d = cx - cy;
  if (!(d.norm() > 0.0)) return -1;
  const Vec3 dl = y.rt * d.normalized();
  const auto& pl = y.shape->planes();
  if (!y.accel) {
    int best = 0;
    for (int f = 1; f < y.num_triangles(); ++f)
      if (pl[f].normal.dot(dl) > pl[best].normal.dot(dl)) best = f;
    return best;
  }
  const Accel& acc = *y.accel;
  auto reach = [&](int k) {
    const FaceCone& c = acc.cones[k];
    const double along = c.axis.dot(dl), across = c.axis.cross(dl).norm();
    return along >= c.cos_half ? 1.0 : along * c.cos_half + across * c.sin_half;
  };
  // Branch and bound on the cone bounds: the exact best face, ties to the first found.
  int best = acc.triangles.order[0];
  double best_dot = -2.0;
  Stack<int> stack;
  stack.push(0);
  while (!stack.empty()) {
    const int k = stack.pop();
    if (reach(k) <= best_dot) continue;
    const Node& node = acc.triangles.nodes[k];
    if (node.child < 0) {
      for (int i = node.begin; i < node.end; ++i) {
        const int f = acc.triangles.order[i];
        if (pl[f].normal.dot(dl) > best_dot) {
          best_dot = pl[f].normal.dot(dl);
          best = f;
        }
      }
      continue;
    }
    // The child reaching further is searched first.
    const bool first = reach(node.child) >= reach(node.child + 1);
    stack.push(first ? node.child + 1 : node.child);
    stack.push(first ? node.child : node.child + 1);
  }
  return best;
}

// False when no point of x can be inside y: x lies wholly outside one face plane of y (by
// more than tol + margin), tried on y's facing face, then on every distinct face plane of a
// small y or the axis faces of a larger one. Every point a test derives from x (a centroid, a
// vertex, a point on an edge) is a convex combination of x's vertices, so its plane distance
// exceeds the smallest of theirs less round-off, which the margin covers; x's vertices are
// tested one by one (small x) or through its bounding box (larger x).
bool may_enter(const Placed& x, const Placed& y, const Limits& lim) {
  const double limit = lim.tol + lim.margin;
  const auto& tris = y.shape->triangles();
  auto separates = [&](int f) {
    const Vec3 n = y.normal(f);
    const Vec3 q = y.vertex(tris[f][0]);
    if (!x.accel) {
      const int nv = static_cast<int>(x.shape->vertices().size());
      for (int i = 0; i < nv; ++i)
        if ((x.vertex(i) - q).dot(n) <= limit) return false;
      return true;
    }
    const Node& root = x.accel->vertices.nodes[0];
    const Vec3 m = x.rt * n;
    return root.center.dot(m) + (x.position - q).dot(n) - root.half.dot(m.cwiseAbs()) > limit;
  };
  if (y.facing >= 0 && separates(y.facing)) return false;
  if (!y.accel) {
    for (int f = 0; f < y.num_triangles(); ++f)
      if (y.distinct[f] && f != y.facing && separates(f)) return false;
    return true;
  }
  for (int f : y.accel->axis_faces)
    if (separates(f)) return false;
  return true;
}

// Per-pair preparation: each shape's facing face, and whether its points can enter the other.
// Two small shapes: fills x's plane table against y (see Placed::plane_table) and decides
// may_enter from it (the same rule as may_enter(), on every distinct plane of y).
void fill_plane_table(Placed& x, const Placed& y, const Limits& lim, std::vector<double>& table) {
  const int nv = static_cast<int>(x.shape->vertices().size());
  const auto& tris = y.shape->triangles();
  int planes[kSmallTriangles];
  int count = 0;
  for (int f = 0; f < y.num_triangles(); ++f)
    if (y.distinct[f]) planes[count++] = f;
  table.resize(static_cast<std::size_t>(nv) * count);
  const double limit = lim.tol + lim.margin;
  bool separated[kSmallTriangles];
  for (int k = 0; k < count; ++k) separated[k] = true;
  for (int i = 0; i < nv; ++i)
    for (int k = 0; k < count; ++k) {
      const int f = planes[k];
      const double d = plane_dist(x.world_vertices[i], y.world_vertices[tris[f][0]],
                                  y.world_normals[f]);
      table[static_cast<std::size_t>(i) * count + k] = d;
      if (d <= limit) separated[k] = false;
    }
  x.plane_table = table.data();
  x.table_planes = count;
  x.may_enter = true;
  for (int k = 0; k < count; ++k)
    if (separated[k]) x.may_enter = false;
}

// Per-pair preparation: each shape's facing face, and whether its points can enter the other.
void prepare_pair(Placed& a, Placed& b, const Limits& lim) {
  a.facing = facing_face(a, b);
  b.facing = facing_face(b, a);
  if (!a.accel && !b.accel) {
    thread_local std::vector<double> tables[2];
    fill_plane_table(a, b, lim, tables[0]);
    fill_plane_table(b, a, lim, tables[1]);
    return;
  }
  a.may_enter = may_enter(a, b, lim);
  b.may_enter = may_enter(b, a, lim);
}

// The cull planes of y against x: y's facing face, and the faces most along y's body axes (for
// a box, its faces).
int cull_planes(const Placed& x, const Placed& y, CullPlane* planes) {
  const auto& tris = y.shape->triangles();
  int faces[7];
  int count = 0;
  if (y.facing >= 0) faces[count++] = y.facing;
  // The faces most along the body axes.
  if (y.accel) {
    for (int f : y.accel->axis_faces) faces[count++] = f;
  } else {
    const auto& pl = y.shape->planes();
    for (int k = 0; k < 6; ++k) {
      const Vec3 dir = (k % 2 == 0 ? 1.0 : -1.0) * Vec3::Unit(k / 2);
      int best = 0;
      for (int f = 1; f < y.num_triangles(); ++f)
        if (pl[f].normal.dot(dir) > pl[best].normal.dot(dir)) best = f;
      faces[count++] = best;
    }
  }
  for (int i = 0; i < count; ++i) {
    const Vec3 n = y.normal(faces[i]);
    const Vec3 q = y.vertex(tris[faces[i]][0]);
    planes[i].m = x.rt * n;
    planes[i].m_abs = planes[i].m.cwiseAbs();
    planes[i].c0 = (x.position - q).dot(n);
    planes[i].normal = n;
    planes[i].point = q;
  }
  return count;
}

// True when every point of the box (x's body frame) is outside one of the planes by more than
// tol + margin, so no point of it can be inside y.
bool culled(const CullPlane* planes, int count, const Vec3& center, const Vec3& half,
            double limit) {
  for (int i = 0; i < count; ++i)
    if (center.dot(planes[i].m) + planes[i].c0 - half.dot(planes[i].m_abs) > limit) return true;
  return false;
}

// True when the points a test derives from primitive i of x all lie outside one of the planes
// (by more than the tolerance), so none of them can be inside y. Vertices and triangle
// centroids are tested with the seed's exact expressions (a point outside one face plane is
// outside y for the seed's inside() too); an edge needs both ends beyond the same plane by
// tol + margin, which keeps every point between them beyond tol.
bool primitive_culled(const Placed& x, Kind kind, int i, const CullPlane* planes, int count,
                      const Limits& lim) {
  if (kind == Kind::Edges) {
    const Edge& e = x.shape->edges()[i];
    const Vec3 v_i = x.vertex(e.a), v_j = x.vertex(e.b);
    const double limit = lim.tol + lim.margin;
    for (int k = 0; k < count; ++k)
      if (planes[k].distance(v_i) > limit && planes[k].distance(v_j) > limit) return true;
    return false;
  }
  Vec3 p;
  if (kind == Kind::Vertices) {
    p = x.vertex(i);
  } else {
    const auto& t = x.shape->triangles()[i];
    p = (x.vertex(t[0]) + x.vertex(t[1]) + x.vertex(t[2])) / 3.0;  // the seed's centroid
  }
  for (int k = 0; k < count; ++k)
    if (planes[k].distance(p) > lim.tol) return true;
  return false;
}

// Indices of x's primitives of `kind` that may lie (in part) inside y, in increasing order.
// Every point a test derives from a primitive (a centroid, a vertex, a point on an edge) lies
// in the primitive's box, so a box outside one of y's face planes holds no hit; the primitives
// of the remaining leaves are then culled one by one (primitive_culled).
void candidates(const Placed& x, const Placed& y, Kind kind, const Limits& lim,
                std::vector<int>& out) {
  out.clear();
  if (!x.accel) {
    const int n = kind == Kind::Triangles ? x.num_triangles()
                  : kind == Kind::Vertices ? static_cast<int>(x.shape->vertices().size())
                                           : static_cast<int>(x.shape->edges().size());
    // Two small shapes: culled on the plane table. A vertex outside one plane by more than
    // tol is outside y for the seed's inside() (the table holds the seed's own value for that
    // face). Plane distances are affine along a triangle or an edge, so a centroid's is the
    // mean of its vertices' (to round-off), and the part of an edge within tol + margin of
    // every plane is an interval of its parameter clipped plane by plane (Cyrus-Beck); a
    // centroid beyond one plane by tol + margin, or an edge whose interval is empty, holds no
    // point inside y.
    if (x.plane_table) {
      const int m = x.table_planes;
      const double limit = lim.tol + lim.margin;
      auto row = [&](int v) { return x.plane_table + static_cast<std::size_t>(v) * m; };
      for (int i = 0; i < n; ++i) {
        bool out_of_y = false;
        if (kind == Kind::Vertices) {
          const double* r = row(i);
          for (int k = 0; k < m && !out_of_y; ++k) out_of_y = r[k] > lim.tol;
        } else if (kind == Kind::Triangles) {
          const auto& t = x.shape->triangles()[i];
          const double *r0 = row(t[0]), *r1 = row(t[1]), *r2 = row(t[2]);
          for (int k = 0; k < m && !out_of_y; ++k) out_of_y = (r0[k] + r1[k] + r2[k]) / 3.0 > limit;
        } else {
          const Edge& e = x.shape->edges()[i];
          const double *r0 = row(e.a), *r1 = row(e.b);
          double lo = 0.0, hi = 1.0;  // the parameters t in [0, 1] still possibly inside
          for (int k = 0; k < m && !out_of_y; ++k) {
            const double s0 = r0[k] - limit, s1 = r1[k] - limit;
            if (s0 > 0.0 && s1 > 0.0) {
              out_of_y = true;
            } else if (s0 > 0.0) {
              lo = std::max(lo, s0 / (s0 - s1));  // no cancellation: s0 > 0 >= s1
            } else if (s1 > 0.0) {
              hi = std::min(hi, s0 / (s0 - s1));
            }
          }
          // The parameters carry a few ulps; 1e-9 is far above them.
          out_of_y = out_of_y || lo > hi + 1e-9;
        }
        if (!out_of_y) out.push_back(i);
      }
      return;
    }
    CullPlane planes[7];
    const int count = cull_planes(x, y, planes);
    for (int i = 0; i < n; ++i)
      if (!primitive_culled(x, kind, i, planes, count, lim)) out.push_back(i);
    return;
  }
  CullPlane planes[7];
  const int count = cull_planes(x, y, planes);
  const double limit = lim.tol + lim.margin;
  const Tree& tree = kind == Kind::Triangles ? x.accel->triangles
                     : kind == Kind::Vertices ? x.accel->vertices
                                              : x.accel->edges;
  Stack<int> stack;
  stack.push(0);
  while (!stack.empty()) {
    const Node& node = tree.nodes[stack.pop()];
    if (culled(planes, count, node.center, node.half, limit)) continue;
    if (node.child < 0) {
      for (int i = node.begin; i < node.end; ++i)
        if (!primitive_culled(x, kind, tree.order[i], planes, count, lim))
          out.push_back(tree.order[i]);
      continue;
    }
    stack.push(node.child);
    stack.push(node.child + 1);
  }
  std::sort(out.begin(), out.end());
}

// True when one face plane of y has both ends of the segment [v_i, v_j] beyond tol + margin:
// then no point of the segment is inside y, and the edge can have no hit whatever its plane
// crossings. A search for such a face, clusters first where both ends may be far outside.
bool segment_outside(const Placed& y, const Vec3& v_i, const Vec3& v_j, const Limits& lim) {
  const double limit = lim.tol + lim.margin;
  if (y.facing >= 0 && plane_distance(y, y.facing, v_i) > limit &&
      plane_distance(y, y.facing, v_j) > limit)
    return true;
  if (!y.accel) {
    // Small shapes: every distinct face plane (coplanar triangles share one).
    for (int f = 0; f < y.num_triangles(); ++f)
      if (y.distinct[f] && f != y.facing && plane_distance(y, f, v_i) > limit &&
          plane_distance(y, f, v_j) > limit)
        return true;
    return false;
  }
  const Accel& acc = *y.accel;
  const Vec3 pi = y.to_local(v_i), pj = y.to_local(v_j);
  // Upper bound on min(s_f(v_i), s_f(v_j)) over a cluster.
  auto bound = [&](int k) {
    double lo, hi_i, hi_j;
    plane_bounds(acc, k, pi, lo, hi_i);
    plane_bounds(acc, k, pj, lo, hi_j);
    return std::min(hi_i, hi_j);
  };
  Stack<std::pair<int, double>> stack;
  stack.push({0, bound(0)});
  while (!stack.empty()) {
    const auto [k, b] = stack.pop();
    if (b <= limit) continue;
    const Node& node = acc.triangles.nodes[k];
    if (node.child < 0) {
      for (int i = node.begin; i < node.end; ++i) {
        const int f = acc.triangles.order[i];
        if (plane_distance(y, f, v_i) > limit && plane_distance(y, f, v_j) > limit) return true;
      }
      continue;
    }
    const double b0 = bound(node.child), b1 = bound(node.child + 1);
    if (b0 > b1) {
      stack.push({node.child + 1, b1});
      stack.push({node.child, b0});
    } else {
      stack.push({node.child, b0});
      stack.push({node.child + 1, b1});
    }
  }
  return false;
}

// Per-thread scratch lists, so that the tests allocate nothing once warm.
struct Scratch {
  std::vector<int> candidates, hits;
  std::vector<Crossing> crossings;
  std::vector<double> ts;
};
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

// Face test, one order: the seed's face_one on the candidates.
std::optional<ContactPoint> face_one(const Placed& a, const Placed& b, const Limits& lim) {
  if (!a.may_enter) return std::nullopt;
  Scratch& s = scratch();
  candidates(a, b, Kind::Triangles, lim, s.candidates);
  const auto& tris = a.shape->triangles();
  Vec3 sum = Vec3::Zero();
  int hits = 0;
  int first = -1;
  for (int f : s.candidates) {
    const Vec3 c = (a.vertex(tris[f][0]) + a.vertex(tris[f][1]) + a.vertex(tris[f][2])) / 3.0;
    if (!inside(b, c, lim)) continue;
    if (first < 0) first = f;
    sum += c;  // in increasing triangle order, as the seed sums
    ++hits;
  }
  if (hits == 0) return std::nullopt;
  ContactPoint cp;
  cp.point = sum / hits;
  cp.normal = -a.normal(first);  // SEED_NOTES 9, as in the seed
  cp.depth = overlap(a, b, cp.normal, lim);
  cp.feature = "face";
  return cp;
}

// Vertex test, one order: the seed's vertex_one on the candidates.
std::optional<ContactPoint> vertex_one(const Placed& a, const Placed& b, const Limits& lim) {
  if (!a.may_enter) return std::nullopt;
  Scratch& s = scratch();
  candidates(a, b, Kind::Vertices, lim, s.candidates);
  s.hits.clear();
  for (int i : s.candidates)
    if (inside(b, a.vertex(i), lim)) s.hits.push_back(i);
  if (s.hits.empty()) return std::nullopt;
  ContactPoint cp;
  const Vec3 first = a.vertex(s.hits[0]);
  cp.normal = b.normal(closest_face(b, first, lim));
  // The seed's average over the inside vertices that share the first one's closest normal.
  Vec3 sum = first;
  int hits = 1;
  for (std::size_t k = 1; k < s.hits.size(); ++k) {
    const Vec3 v = a.vertex(s.hits[k]);
    if (b.normal(closest_face(b, v, lim)).dot(cp.normal) < 1.0 - 1e-9) continue;
    sum += v;
    ++hits;
  }
  cp.point = sum / hits;
  cp.depth = overlap(a, b, cp.normal, lim);
  cp.feature = "vertex";
  return cp;
}

// The seed's edge_normal() on placed shapes (same steps, fast queries).
Vec3 edge_normal(const Placed& a, const Placed& b, const Vec3& v_i, const Vec3& e_a,
                 const Vec3& p, const std::vector<Crossing>& crossings, const Limits& lim) {
  const double tol = lim.tol;
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
  if (face < 0) face = nearest_triangle(b, p, lim);
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
  const Vec3 n_face = b.normal(face);
  Vec3 n = e_a.cross(e_b);
  if (n.norm() <= 1e-9 * e_a.norm() * e_b.norm()) return n_face;
  n.normalize();
  const double plus = overlap(a, b, n, lim), minus = overlap(a, b, -n, lim);
  if (minus < plus - tol || (std::abs(minus - plus) <= tol && n.dot(n_face) < 0.0)) n = -n;
  if (overlap(a, b, n_face, lim) < std::min(plus, minus) - tol) return n_face;
  return n;
}

// Edge test, one order: the seed's edge_one on the candidates.
std::optional<ContactPoint> edge_one(const Placed& a, const Placed& b, const Limits& lim) {
  if (!a.may_enter) return std::nullopt;
  Scratch& s = scratch();
  candidates(a, b, Kind::Edges, lim, s.candidates);
  const double tol = lim.tol;
  for (int idx : s.candidates) {
    const Edge& e = a.shape->edges()[idx];
    const Vec3 v_i = a.vertex(e.a);
    const Vec3 v_j = a.vertex(e.b);
    const Vec3 e_a = v_j - v_i;
    // No midpoint can be inside (two small shapes: already culled on the plane table).
    if (!a.plane_table && segment_outside(b, v_i, v_j, lim)) continue;
    crossings(b, v_i, v_j, lim, s.crossings);
    // The seed's sorted, merged crossing parameters.
    std::vector<double>& ts = s.ts;
    ts.assign({0.0, 1.0});
    for (const Crossing& c : s.crossings) ts.push_back(c.t);
    // Insertion sort: a few values (sorting gives the same sequence whatever the algorithm).
    for (std::size_t k = 1; k < ts.size(); ++k)
      for (std::size_t m = k; m > 0 && ts[m] < ts[m - 1]; --m) std::swap(ts[m], ts[m - 1]);
    const double merge = tol / std::max(e_a.norm(), std::numeric_limits<double>::min());
    ts.erase(std::unique(ts.begin(), ts.end(),
                         [merge](double x, double y) { return y - x <= merge; }),
             ts.end());
    if (ts.back() < 1.0) ts.back() = 1.0;
    for (std::size_t k = 0; k + 1 < ts.size(); ++k) {
      const Vec3 p = v_i + 0.5 * (ts[k] + ts[k + 1]) * e_a;
      if (!inside(b, p, lim)) continue;
      ContactPoint cp;
      cp.point = p;
      cp.normal = edge_normal(a, b, v_i, e_a, p, s.crossings, lim);
      cp.depth = overlap(a, b, cp.normal, lim);
      cp.feature = "edge";
      return cp;
    }
  }
  return std::nullopt;
}

using OneOrder = std::optional<ContactPoint> (*)(const Placed&, const Placed&, const Limits&);

// SEED_NOTES 8, as both_orders() in the seed.
std::optional<ContactPoint> both_orders(OneOrder test, const Placed& a, const Placed& b,
                                        const Limits& lim) {
  if (auto hit = test(a, b, lim)) return hit;
  if (auto hit = test(b, a, lim)) {
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

// The query's constants: the seed's tolerance, and the margin scaled by the coordinates.
Limits limits_of(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                 const Pose& pb) {
  Limits lim;
  lim.tol = point_in_mesh_tolerance(a, b);
  const double scale = pa.position.norm() + pb.position.norm() + 2.0 * shape_size(a) +
                       2.0 * shape_size(b);
  lim.margin = kMarginScale * scale;
  return lim;
}

// A pair ready for the tests: both shapes placed, facing faces, plane tables.
struct Prepared {
  Placed a, b;
  Limits lim;
};

// Exact copy of a small shape's geometry, to recognise it on the next query.
struct ShapeCopy {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  std::vector<Plane> planes;
  bool same(const ConvexPolyhedron& s) const {
    auto equal = [](const auto& x, const auto& y) {
      return x.size() == y.size() &&
             std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
    };
    return equal(vertices, s.vertices()) && equal(triangles, s.triangles()) &&
           equal(planes, s.planes());
  }
  void assign(const ConvexPolyhedron& s) {
    vertices = s.vertices();
    triangles = s.triangles();
    planes = s.planes();
  }
};

bool same_pose(const Pose& x, const Pose& y) {
  return std::memcmp(x.position.data(), y.position.data(), 3 * sizeof(double)) == 0 &&
         std::memcmp(x.orientation.coeffs().data(), y.orientation.coeffs().data(),
                     4 * sizeof(double)) == 0;
}

// Places and prepares a pair. The world asks for the face, vertex and edge tests of a pair one
// after the other with the same poses (responses change velocities only), so for two small
// shapes the last preparation is kept and reused when the poses (bit for bit) and both shapes'
// geometry (compared in full) are the same: the world data would be recomputed identically.
const Prepared& prepare(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                        const Pose& pb) {
  thread_local Prepared last;
  thread_local bool reusable = false;
  thread_local ShapeCopy copy_a, copy_b;
  thread_local Pose pose_a, pose_b;
  const bool small = static_cast<int>(a.triangles().size()) <= kSmallTriangles &&
                     static_cast<int>(b.triangles().size()) <= kSmallTriangles;
  if (small && reusable && same_pose(pa, pose_a) && same_pose(pb, pose_b) && copy_a.same(a) &&
      copy_b.same(b)) {
    // Equal geometry, but maybe another object (the last one may be gone): point at these.
    last.a.shape = &a;
    last.b.shape = &b;
    return last;
  }
  last.lim = limits_of(a, pa, b, pb);
  last.a = place(a, pa, 0);
  last.b = place(b, pb, 1);
  prepare_pair(last.a, last.b, last.lim);
  reusable = small;
  if (small) {
    copy_a.assign(a);
    copy_b.assign(b);
    pose_a = pa;
    pose_b = pb;
  }
  return last;
}

}  // namespace fast

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
  if (variant == DetectorVariant::Fast) {
    const fast::OneOrder test = fast::feature_test(feature);
    const fast::Prepared& p = fast::prepare(a, pa, b, pb);
    return fast::both_orders(test, p.a, p.b, p.lim);
  }
  const OneOrder test = feature_test(feature);
  return both_orders(test, to_world(a, pa), to_world(b, pb), point_in_mesh_tolerance(a, b));
}

std::optional<ContactPoint> detect(const ConvexPolyhedron& a, const Pose& pa,
                                   const ConvexPolyhedron& b, const Pose& pb,
                                   DetectorVariant variant) {
  if (variant == DetectorVariant::Fast) {
    // The same tests in the same order, on the fast queries (see the design note of fast::).
    const fast::Prepared& p = fast::prepare(a, pa, b, pb);
    for (fast::OneOrder test : {&fast::face_one, &fast::vertex_one, &fast::edge_one})
      if (auto hit = fast::both_orders(test, p.a, p.b, p.lim)) return hit;
    return std::nullopt;
  }
  // Both shapes go to the world once; the six tests share the copies.
  const WorldShape wa = to_world(a, pa), wb = to_world(b, pb);
  const double tol = point_in_mesh_tolerance(a, b);
  // The seed's order: face, vertex, edge; each in both orders (SEED_NOTES 8).
  for (OneOrder test : {&face_one, &vertex_one, &edge_one})
    if (auto hit = both_orders(test, wa, wb, tol)) return hit;
  return std::nullopt;
}

}  // namespace rbx
