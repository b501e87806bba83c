// The exact oracle: separating-axis test over every face normal and every edge-pair cross
// product of two placed convex polyhedra, and the contact manifold by clipping.
//
// Design notes.
// - Faces are the *merged* faces: adjacent coplanar triangles (a box face is two) form one
//   polygonal face, so a box has 6 face axes and a face contact clips against the whole face.
//   Edges between two coplanar triangles (a box face's diagonal) are no edges of the solid.
// - Edge pairs are pruned with the Gauss-map test (Gregorius, GDC 2013): e_a x e_b is a face
//   normal of the Minkowski difference only when the arcs of the two edges' face normals cross.
//   The test is made conservative with a slack, so near-degenerate pairs are kept. Keeping an
//   axis that is no Minkowski face can never lower the minimum below the true penetration (every
//   direction's overlap is an upper bound of it), so the slack costs time, never exactness.
//   The surviving pairs are evaluated once per pair of parallel-edge classes (a box has 3).
//   Candidate pairs come from a sweep over bounding balls of the arcs, and projections from
//   hill climbing along mesh edges (exact on a convex polyhedron), so an icosphere of 5120
//   triangles against another takes ~0.1 s instead of growing with the product of the counts.
// - All projections use world coordinates relative to the midpoint of the two poses, so the
//   round-off scales with the size of the pair, not with the distance from the world origin.
// - Order independence: every tie is broken by a key that belongs to the geometry (face area,
//   outward normal, axis direction), never to the argument slot, and every overlap is computed
//   from the same numbers in either order, so sat_query(B, A) returns the same reference face,
//   the same depth, the exactly flipped normal and the same manifold (up to round-off).
//
// Manifold convention. For a face axis the reference face is the face owning the axis; the
// incident feature is the face of the other shape most anti-parallel to it, chosen among the
// faces around that shape's deepest vertex (so the deepest point is never missed). When several
// faces are equally anti-parallel (a cube edge pressed into a face at 45 degrees) the incident
// feature is what they share, the edge or the vertex, so that the answer keeps the symmetry of
// the configuration instead of picking a side. The incident polygon is clipped against the side
// planes of the reference face (Sutherland-Hodgman) and the points at or below the reference
// plane are kept. Each kept point is reported MIDWAY between the incident surface and the
// reference plane: p - (d / 2) n_ref, d <= 0 its signed distance to the reference plane. For an
// edge-edge axis the one point is the midpoint of the closest points of the two edges. Both
// conventions put the point halfway between the two surfaces, as FCL's box-box does.
#include "reference/exact.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "reference/exact_geometry.h"

namespace rbx {

namespace {

// Adjacent triangles merge into one face when every vertex of one lies within this fraction of
// the shape's scale from the other's plane: the tolerance ConvexPolyhedron itself accepts for
// convexity, so a mesh the engine accepts as flat-faced is merged as such. Merging moves a face
// plane by at most this much, so the depth is off by at most 1e-9 of the size.
constexpr double kMergeRelative = 1e-9;

// Two unit edge directions are parallel when |d1 x d2| <= sqrt(eps) ~ 1.5e-8. The cross product of
// unit vectors carries an absolute round-off of ~eps, so the axis of a pair at sine s has a
// relative direction error ~eps / s; skipping the pair instead loses a Minkowski face of width
// ~s * size. Both errors are upper bounds of the depth, and sqrt(eps) balances them at ~1.5e-8 of
// the size; exactly parallel edges (s ~ 1e-16 after rotation) are skipped with no error at all.
constexpr double kParallelSine = 1.5e-8;

// Round-off allowance relative to the largest coordinate magnitude L of the pair (measured from
// the query origin): a projection x . n carries a few eps * L, so 1e-12 * L leaves a margin of
// ~1000 over it. Used for "touching", for "inside a side plane" and "at or below the plane".
constexpr double kRoundoffRelative = 1e-12;

// Axis preference: a face axis wins over an edge axis, and two face axes are tied, when their
// overlaps differ by at most 1e-9 * L. This must exceed the round-off of the overlaps (~1e-15 L)
// so that an edge pair spanning a face plane (both edges parallel to it: the cross product IS
// the face normal) reports the face; it stays far below any depth difference a scene can express
// (positions in ~10 significant digits) and below the 1e-6 * size resolution of the tests.
constexpr double kPreferRelative = 1e-9;

// Two face areas are equal for the reference-face tie-break within this relative difference
// (areas are computed from the same vertices in different triangle orders: ~eps round-off).
constexpr double kAreaRelative = 1e-9;

// Incident faces whose cosines with the reference normal differ by at most this are equally
// anti-parallel. Rotated unit normals carry ~1e-16 of round-off; an angle written to break the
// symmetry, say 45.000001 deg (1.7e-8 rad off), moves the two cosines apart by ~2.5e-8, far more
// than 1e-10, and is resolved as the single face it is.
constexpr double kTieCosine = 1e-10;

// Slack on the Gauss-map arc-crossing products (products of unit triple products, round-off
// ~1e-16): generous, since a kept pair costs time only.
constexpr double kMinkowskiSlack = 1e-12;

}  // namespace

// The topology types are named (not file-local) so that SatShape in exact.h can hold one.
namespace exact_detail {

// One merged (polygonal) face of a polyhedron, in the body frame.
struct MergedFace {
  Vec3 normal = Vec3::UnitZ();  // unit, outward
  double area = 0.0;            // m^2
  std::vector<int> loop;        // boundary vertex indices, counter-clockwise seen from outside
  std::vector<int> vertices;    // every vertex of the face, sorted
};

// An edge of the solid: between two different merged faces.
struct FeatureEdge {
  int a = 0, b = 0;          // vertex indices
  int face0 = 0, face1 = 0;  // the merged faces on either side
  int direction = 0;         // index of its class of parallel edges
};

// Faces, edges and parallel-edge classes of a polyhedron.
struct Topology {
  std::vector<MergedFace> faces;
  std::vector<FeatureEdge> edges;
  std::vector<Vec3> directions;                // unit, body frame: one per parallel class
  std::vector<std::vector<int>> vertex_faces;  // faces touching each vertex
  std::vector<std::vector<int>> neighbours;    // vertices joined to each vertex by a mesh edge
};

}  // namespace exact_detail

namespace {

using exact_detail::FeatureEdge;
using exact_detail::MergedFace;
using exact_detail::Topology;

// Directed edge -> the triangle that uses it (closed, consistently oriented mesh).
using EdgeOwners = std::map<std::pair<int, int>, int>;

EdgeOwners edge_owners(const ConvexPolyhedron& p) {
  const auto& tri = p.triangles();
  EdgeOwners owner;
  for (int t = 0; t < static_cast<int>(tri.size()); ++t)
    for (int k = 0; k < 3; ++k) owner[{tri[t][k], tri[t][(k + 1) % 3]}] = t;
  return owner;
}

// The triangles coplanar with `seed` and joined to it (flood fill across edges, coplanarity
// measured against the seed plane, so no drift); marks them face `id` in face_of.
std::vector<int> coplanar_region(const ConvexPolyhedron& p, const EdgeOwners& owner, int seed,
                                 int id, double merge_tol, std::vector<int>& face_of) {
  const auto& v = p.vertices();
  const auto& tri = p.triangles();
  const auto& planes = p.planes();
  std::vector<int> members{seed};
  face_of[seed] = id;
  for (size_t q = 0; q < members.size(); ++q) {
    const int t = members[q];
    for (int k = 0; k < 3; ++k) {
      const int nb = owner.at({tri[t][(k + 1) % 3], tri[t][k]});
      if (face_of[nb] >= 0 || planes[nb].normal.dot(planes[seed].normal) <= 0) continue;
      bool coplanar = true;
      for (int w : tri[nb])
        coplanar = coplanar && std::abs(planes[seed].distance(v[w])) <= merge_tol;
      if (!coplanar) continue;
      face_of[nb] = id;
      members.push_back(nb);
    }
  }
  return members;
}

// Face `id` of the triangles `members`: area-weighted normal, area, vertex set and boundary
// loop (the directed edges whose reverse belongs to another face, chained).
MergedFace merged_face(const ConvexPolyhedron& p, const EdgeOwners& owner,
                       const std::vector<int>& members, int id, const std::vector<int>& face_of) {
  const auto& v = p.vertices();
  const auto& tri = p.triangles();
  MergedFace face;
  Vec3 area_vector = Vec3::Zero();
  for (int t : members) {
    area_vector += (v[tri[t][1]] - v[tri[t][0]]).cross(v[tri[t][2]] - v[tri[t][0]]);
    face.vertices.insert(face.vertices.end(), tri[t].begin(), tri[t].end());
  }
  face.normal = area_vector.normalized();
  face.area = 0.5 * area_vector.norm();
  std::sort(face.vertices.begin(), face.vertices.end());
  face.vertices.erase(std::unique(face.vertices.begin(), face.vertices.end()), face.vertices.end());
  std::map<int, int> next;
  for (int t : members)
    for (int k = 0; k < 3; ++k) {
      const int u = tri[t][k], w = tri[t][(k + 1) % 3];
      if (face_of[owner.at({w, u})] == id) continue;
      if (!next.emplace(u, w).second)
        throw GeometryError("exact: merged face " + std::to_string(id) +
                            " is not a simple polygon");
    }
  int at = next.begin()->first;
  for (size_t steps = 0; steps < next.size(); ++steps) {
    face.loop.push_back(at);
    at = next.at(at);
  }
  if (at != face.loop.front())
    throw GeometryError("exact: boundary of merged face " + std::to_string(id) +
                        " is not one loop");
  return face;
}

// Edges of the solid (between two merged faces), grouped into classes of parallel directions.
// Classes are found through a grid of cells of 1e-5 on the unit direction (>> kParallelSine):
// a parallel direction, +d or -d, lies in one of the 27 cells around it, so the search is exact
// and O(edges).
void classify_edges(const ConvexPolyhedron& p, const EdgeOwners& owner,
                    const std::vector<int>& face_of, Topology& topo) {
  const auto& v = p.vertices();
  constexpr double kCell = 1e-5;
  std::unordered_map<long long, std::vector<int>> grid;
  auto cell_of = [&](const Vec3& d) {
    return Eigen::Vector3i(static_cast<int>(std::floor(d.x() / kCell)),
                           static_cast<int>(std::floor(d.y() / kCell)),
                           static_cast<int>(std::floor(d.z() / kCell)));
  };
  auto key = [](const Eigen::Vector3i& c) {
    const long long bias = 1 << 17;  // cells span [-1e5 - 1, 1e5 + 1]: 18 bits each
    return ((c.x() + bias) << 36) | ((c.y() + bias) << 18) | (c.z() + bias);
  };
  for (const Edge& e : p.edges()) {
    const int f0 = face_of[owner.at({e.a, e.b})], f1 = face_of[owner.at({e.b, e.a})];
    if (f0 == f1) continue;  // a diagonal inside a merged face
    const Vec3 d = (v[e.b] - v[e.a]).normalized();
    int cls = -1;
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3i c = cell_of(sign * d);
      for (int i = -1; i <= 1 && cls < 0; ++i)
        for (int j = -1; j <= 1 && cls < 0; ++j)
          for (int k = -1; k <= 1 && cls < 0; ++k) {
            const auto it = grid.find(key(c + Eigen::Vector3i(i, j, k)));
            if (it == grid.end()) continue;
            for (int cand : it->second)
              if (cls < 0 && d.cross(topo.directions[cand]).norm() <= kParallelSine) cls = cand;
          }
    }
    if (cls < 0) {
      cls = static_cast<int>(topo.directions.size());
      topo.directions.push_back(d);
      grid[key(cell_of(d))].push_back(cls);
    }
    topo.edges.push_back({e.a, e.b, f0, f1, cls});
  }
}

// Merges coplanar triangles into polygonal faces and lists the edges of the solid.
Topology build_topology(const ConvexPolyhedron& p) {
  const EdgeOwners owner = edge_owners(p);
  // Same scale as ConvexPolyhedron's convexity tolerance.
  const Aabb& box = p.bounds();
  const double scale = std::max((box.max - box.min).maxCoeff(),
                                box.max.cwiseAbs().cwiseMax(box.min.cwiseAbs()).maxCoeff());
  const double merge_tol = kMergeRelative * scale;

  // Faces: each triangle not yet merged seeds one.
  Topology topo;
  const int nt = static_cast<int>(p.triangles().size());
  std::vector<int> face_of(nt, -1);
  for (int seed = 0; seed < nt; ++seed) {
    if (face_of[seed] >= 0) continue;
    const int id = static_cast<int>(topo.faces.size());
    const std::vector<int> members = coplanar_region(p, owner, seed, id, merge_tol, face_of);
    topo.faces.push_back(merged_face(p, owner, members, id, face_of));
  }
  classify_edges(p, owner, face_of, topo);

  // Adjacency: each vertex's mesh neighbours and the faces touching it.
  const size_t nv = p.vertices().size();
  topo.neighbours.assign(nv, {});
  for (const Edge& e : p.edges()) {
    topo.neighbours[e.a].push_back(e.b);
    topo.neighbours[e.b].push_back(e.a);
  }
  topo.vertex_faces.assign(nv, {});
  for (size_t f = 0; f < topo.faces.size(); ++f)
    for (int w : topo.faces[f].vertices) topo.vertex_faces[w].push_back(static_cast<int>(f));
  return topo;
}

// A polyhedron placed in the world, coordinates relative to the query origin.
struct Placed {
  const Topology* topo = nullptr;  // the shape's, from its SatShape
  std::vector<Vec3> x;             // m, vertices relative to the query origin
  std::vector<Vec3> face_normals;  // unit, world, outward
  std::vector<Vec3> directions;    // unit, world, one per parallel-edge class
};

Placed place(const SatShape& shape, const Pose& pose, const Vec3& origin) {
  const ConvexPolyhedron& p = shape.shape();
  Placed s;
  s.topo = &shape.topology();
  const Mat3 r = pose.rotation();
  const Vec3 offset = pose.position - origin;
  for (const Vec3& v : p.vertices()) s.x.push_back(r * v + offset);
  for (const MergedFace& f : s.topo->faces) s.face_normals.push_back(r * f.normal);
  for (const Vec3& d : s.topo->directions) s.directions.push_back(r * d);
  return s;
}

// Support value max x . dir over the vertices, by hill climbing along mesh edges from `start`
// (updated to the vertex found). On a convex polyhedron a vertex with no strictly better
// neighbour is a global maximum (from any other vertex some edge of the polytope climbs), so
// this is exact, at a cost of the few steps from a nearby start instead of all vertices; on a
// plateau (a face orthogonal to dir) it stops at a vertex of it, equal up to round-off. A mesh
// accepted as convex within ConvexPolyhedron's 1e-9 tolerance can stop at most that far short.
double support(const Placed& s, const Vec3& dir, int& start) {
  int at = start;
  double best = s.x[at].dot(dir);
  for (bool moved = true; moved;) {
    moved = false;
    for (int nb : s.topo->neighbours[at]) {
      const double h = s.x[nb].dot(dir);
      if (h > best) {
        best = h;
        at = nb;
        moved = true;
      }
    }
  }
  start = at;
  return best;
}

// Lexicographic a > b (exact).
bool lex_greater(const Vec3& a, const Vec3& b) {
  for (int i = 0; i < 3; ++i)
    if (a[i] != b[i]) return a[i] > b[i];
  return false;
}

// The axis with its sign fixed (first non-zero component positive): the same for n and -n.
Vec3 canonical(const Vec3& n) {
  for (int i = 0; i < 3; ++i)
    if (n[i] != 0.0) return n[i] > 0 ? n : Vec3(-n);
  return n;
}

// A candidate axis with its overlap (how far A must move along `normal` to separate).
struct Axis {
  double overlap = std::numeric_limits<double>::infinity();  // m
  Vec3 normal = Vec3::UnitZ();                               // unit, world, from B toward A
  int owner = -1;                  // face axis: 0 (A) or 1 (B); -1 for an edge pair
  int face = -1;                   // face axis: the owner's merged face
  double area = 0.0;               // face axis: its area (tie-break)
  Vec3 outward = Vec3::Zero();     // face axis: the owner's outward normal (tie-break)
  int class_a = -1, class_b = -1;  // edge pair: the parallel classes of A and B
};

// Face axes of `owner` (slot o): overlap = owner's extent along u minus the other's minimum.
void face_axes(const Placed& owner, const Placed& other, int o, std::vector<Axis>& out) {
  int deepest = 0;  // warm start: consecutive faces have nearby supports
  for (size_t f = 0; f < owner.topo->faces.size(); ++f) {
    const Vec3& u = owner.face_normals[f];
    double hi = -std::numeric_limits<double>::infinity();
    for (int w : owner.topo->faces[f].vertices) hi = std::max(hi, owner.x[w].dot(u));
    const double lo = -support(other, -u, deepest);
    Axis ax;
    ax.overlap = hi - lo;
    ax.normal = o == 1 ? u : Vec3(-u);  // B's face pushes A along u; A's face pulls A back
    ax.owner = o;
    ax.face = static_cast<int>(f);
    ax.area = owner.topo->faces[f].area;
    ax.outward = u;
    out.push_back(ax);
  }
}

// Face-vs-face order, independent of the argument slot: larger area, then larger outward normal.
bool better_reference(const Axis& x, const Axis& y) {
  const double scale = std::max(x.area, y.area);
  if (std::abs(x.area - y.area) > kAreaRelative * scale) return x.area > y.area;
  if (x.outward != y.outward) return lex_greater(x.outward, y.outward);
  return x.overlap < y.overlap;
}

// Bounding ball of a Gauss-map arc (an edge's two face normals): every point of an arc shorter
// than pi is no farther from its middle direction than the endpoints are.
struct ArcBall {
  Vec3 mid = Vec3::UnitZ();
  double radius = 0.0;
  int edge = 0;
};

ArcBall arc_ball(const Vec3& p, const Vec3& q, int edge) {
  ArcBall ball;
  ball.edge = edge;
  const Vec3 sum = p + q;
  // Round-off slack 1e-9 on unit vectors; nearly opposite normals (a sliver edge): everything.
  if (sum.norm() < 1e-6) {
    ball.radius = 3.0;
    return ball;
  }
  ball.mid = sum.normalized();
  ball.radius = std::max((p - ball.mid).norm(), (q - ball.mid).norm()) + 1e-9;
  return ball;
}

// Edge pairs whose Gauss-map arcs cross (conservatively), by parallel class. Candidate pairs come
// from a sweep over the arcs' bounding balls sorted along x, so the cost grows with the number of
// nearby arcs, not with the product of the edge counts.
std::vector<Axis> edge_axes(const Placed& a, const Placed& b) {
  const long long nb = static_cast<long long>(b.topo->directions.size());
  // Arcs of B negated (Minkowski difference A - B); b x a for A's arcs, d x c for B's.
  std::vector<Vec3> bxa, dxc;
  for (const FeatureEdge& e : a.topo->edges)
    bxa.push_back(a.face_normals[e.face1].cross(a.face_normals[e.face0]));
  for (const FeatureEdge& e : b.topo->edges)
    dxc.push_back((-b.face_normals[e.face1]).cross(-b.face_normals[e.face0]));
  std::vector<ArcBall> balls_b;
  double max_radius_b = 0.0;
  for (size_t j = 0; j < b.topo->edges.size(); ++j) {
    const FeatureEdge& e = b.topo->edges[j];
    balls_b.push_back(
        arc_ball(-b.face_normals[e.face0], -b.face_normals[e.face1], static_cast<int>(j)));
    max_radius_b = std::max(max_radius_b, balls_b.back().radius);
  }
  std::sort(balls_b.begin(), balls_b.end(),
            [](const ArcBall& x, const ArcBall& y) { return x.mid.x() < y.mid.x(); });

  // Class pairs, as ca * nb + cb, each with one edge pair of that class pair.
  std::vector<std::pair<long long, std::pair<int, int>>> needed;
  for (size_t i = 0; i < a.topo->edges.size(); ++i) {
    const FeatureEdge& ea = a.topo->edges[i];
    const Vec3& na = a.face_normals[ea.face0];
    const Vec3& nb_ = a.face_normals[ea.face1];
    const ArcBall ball = arc_ball(na, nb_, static_cast<int>(i));
    // B's balls whose centres are within reach along x, then the ball test, then the arcs.
    const double reach = ball.radius + max_radius_b;
    auto it = std::lower_bound(balls_b.begin(), balls_b.end(), ball.mid.x() - reach,
                               [](const ArcBall& x, double v) { return x.mid.x() < v; });
    for (; it != balls_b.end() && it->mid.x() <= ball.mid.x() + reach; ++it) {
      if ((it->mid - ball.mid).norm() > ball.radius + it->radius) continue;
      const FeatureEdge& eb = b.topo->edges[it->edge];
      const Vec3 c = -b.face_normals[eb.face0];
      const Vec3 d = -b.face_normals[eb.face1];
      const double cba = c.dot(bxa[i]), dba = d.dot(bxa[i]);
      const double adc = na.dot(dxc[it->edge]), bdc = nb_.dot(dxc[it->edge]);
      if (cba * dba < kMinkowskiSlack && adc * bdc < kMinkowskiSlack &&
          cba * bdc > -kMinkowskiSlack)
        needed.push_back({ea.direction * nb + eb.direction, {static_cast<int>(i), it->edge}});
    }
  }
  std::sort(needed.begin(), needed.end());
  needed.erase(std::unique(needed.begin(), needed.end(),
                           [](const auto& x, const auto& y) { return x.first == y.first; }),
               needed.end());

  // One axis per needed class pair, oriented by the shorter way out.
  std::vector<Axis> out;
  for (const auto& [pair, edges] : needed) {
    const int ca = static_cast<int>(pair / nb), cb = static_cast<int>(pair % nb);
    Vec3 m = a.directions[ca].cross(b.directions[cb]);
    const double s = m.norm();
    if (s <= kParallelSine) continue;
    m /= s;
    // Supports climbed from the pair's own edges, where a true Minkowski face has them.
    int sa_hi = a.topo->edges[edges.first].a, sa_lo = sa_hi;
    int sb_hi = b.topo->edges[edges.second].a, sb_lo = sb_hi;
    const double hi_a = support(a, m, sa_hi), lo_a = -support(a, -m, sa_lo);
    const double hi_b = support(b, m, sb_hi), lo_b = -support(b, -m, sb_lo);
    const double plus = hi_b - lo_a;   // move A along +m
    const double minus = hi_a - lo_b;  // move A along -m
    Axis ax;
    ax.overlap = plus <= minus ? plus : minus;
    ax.normal = plus <= minus ? m : Vec3(-m);
    ax.class_a = ca;
    ax.class_b = cb;
    out.push_back(ax);
  }
  return out;
}

// Sutherland-Hodgman: keeps the part of `poly` with s . x - offset <= tol. Also clips a segment
// (2 points) or a point (1 point).
std::vector<Vec3> clip(const std::vector<Vec3>& poly, const Vec3& s, double offset, double tol) {
  std::vector<Vec3> out;
  const size_t n = poly.size();
  auto cut = [&](const Vec3& p, double dp, const Vec3& q, double dq) {
    return Vec3(p + (dp / (dp - dq)) * (q - p));
  };
  if (n == 1) {
    if (s.dot(poly[0]) - offset <= tol) out.push_back(poly[0]);
    return out;
  }
  if (n == 2) {
    const double d0 = s.dot(poly[0]) - offset, d1 = s.dot(poly[1]) - offset;
    if (d0 > tol && d1 > tol) return out;
    out.push_back(d0 <= tol ? poly[0] : cut(poly[0], d0, poly[1], d1));
    out.push_back(d1 <= tol ? poly[1] : cut(poly[1], d1, poly[0], d0));
    return out;
  }
  for (size_t k = 0; k < n; ++k) {
    const Vec3& prev = poly[(k + n - 1) % n];
    const Vec3& cur = poly[k];
    const double dp = s.dot(prev) - offset, dc = s.dot(cur) - offset;
    if (dc <= tol) {
      if (dp > tol) out.push_back(cut(prev, dp, cur, dc));
      out.push_back(cur);
    } else if (dp <= tol) {
      out.push_back(cut(prev, dp, cur, dc));
    }
  }
  return out;
}

// Face-axis manifold: reference face `face` of `ref`, incident feature of `inc`.
std::vector<Vec3> face_manifold(const Placed& ref, int face, const Placed& inc, double tol) {
  const Vec3& n = ref.face_normals[face];
  const MergedFace& rf = ref.topo->faces[face];
  double plane = -std::numeric_limits<double>::infinity();
  for (int w : rf.vertices) plane = std::max(plane, ref.x[w].dot(n));

  // Deepest vertex of the incident shape, and the faces around it most anti-parallel to n.
  int deepest = 0;
  for (size_t i = 1; i < inc.x.size(); ++i)
    if (inc.x[i].dot(n) < inc.x[deepest].dot(n)) deepest = static_cast<int>(i);
  const std::vector<int>& around = inc.topo->vertex_faces[deepest];
  double best = std::numeric_limits<double>::infinity();
  for (int f : around) best = std::min(best, inc.face_normals[f].dot(n));
  std::vector<int> tied;
  for (int f : around)
    if (inc.face_normals[f].dot(n) <= best + kTieCosine) tied.push_back(f);

  // Incident polygon: one face's loop, or the feature the tied faces share (edge or vertex).
  std::vector<Vec3> poly;
  if (tied.size() == 1) {
    for (int w : inc.topo->faces[tied[0]].loop) poly.push_back(inc.x[w]);
  } else {
    std::vector<int> common = inc.topo->faces[tied[0]].vertices;
    for (size_t k = 1; k < tied.size(); ++k) {
      std::vector<int> both;
      const auto& fv = inc.topo->faces[tied[k]].vertices;
      std::set_intersection(common.begin(), common.end(), fv.begin(), fv.end(),
                            std::back_inserter(both));
      common = std::move(both);
    }
    if (common.size() <= 1) {
      poly.push_back(inc.x[deepest]);
    } else {
      // Collinear shared vertices: the segment between the two farthest apart.
      size_t i0 = 0, i1 = 1;
      for (size_t i = 0; i < common.size(); ++i)
        for (size_t j = i + 1; j < common.size(); ++j)
          if ((inc.x[common[i]] - inc.x[common[j]]).squaredNorm() >
              (inc.x[common[i0]] - inc.x[common[i1]]).squaredNorm()) {
            i0 = i;
            i1 = j;
          }
      poly = {inc.x[common[i0]], inc.x[common[i1]]};
    }
  }

  // Clip against the side planes of the reference face (outward in-plane normals e x n).
  const size_t m = rf.loop.size();
  for (size_t k = 0; k < m && !poly.empty(); ++k) {
    const Vec3& p0 = ref.x[rf.loop[k]];
    const Vec3& p1 = ref.x[rf.loop[(k + 1) % m]];
    const Vec3 side = (p1 - p0).cross(n).normalized();
    poly = clip(poly, side, side.dot(p0), tol);
  }

  // Keep the points at or below the reference plane, moved midway to it.
  std::vector<Vec3> out;
  for (const Vec3& p : poly) {
    const double d = p.dot(n) - plane;
    if (d > tol) continue;
    const Vec3 q = p - (0.5 * d) * n;
    bool duplicate = false;
    for (const Vec3& o : out) duplicate = duplicate || (o - q).norm() <= tol;
    if (!duplicate) out.push_back(q);
  }
  // Nothing survived (a face chosen over a marginally better edge pair): the deepest vertex.
  if (out.empty()) {
    const Vec3& p = inc.x[deepest];
    out.push_back(p - (0.5 * (p.dot(n) - plane)) * n);
  }
  return out;
}

// Edge-pair manifold: midpoint of the closest points of the supporting edges.
Vec3 edge_manifold(const Placed& a, int class_a, const Placed& b, int class_b, const Vec3& n) {
  // A's edge of the class deepest along -n, B's deepest along +n (ties: lowest index).
  auto supporting = [](const Placed& s, int cls, const Vec3& dir) {
    int best = -1;
    double best_s = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < s.topo->edges.size(); ++i) {
      const FeatureEdge& e = s.topo->edges[i];
      if (e.direction != cls) continue;
      const double h = (s.x[e.a] + s.x[e.b]).dot(dir);
      if (h < best_s) {
        best_s = h;
        best = static_cast<int>(i);
      }
    }
    return s.topo->edges[best];
  };
  const FeatureEdge ea = supporting(a, class_a, n);
  const FeatureEdge eb = supporting(b, class_b, -n);
  Vec3 ca, cb;
  exact_detail::closest_of_segments(a.x[ea.a], a.x[ea.b], b.x[eb.a], b.x[eb.b], ca, cb);
  return 0.5 * (ca + cb);
}

// Contact-patch centre: area centroid of the polygon (mean for fewer than 3 points or no area).
Vec3 centroid(const std::vector<Vec3>& pts, const Vec3& normal) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  if (pts.size() < 3) return mean;
  double area = 0.0;
  Vec3 moment = Vec3::Zero();
  for (size_t k = 0; k < pts.size(); ++k) {
    const Vec3& p = pts[k];
    const Vec3& q = pts[(k + 1) % pts.size()];
    const double w = (p - mean).cross(q - mean).dot(normal);  // twice the signed fan area
    area += w;
    moment += w * (mean + p + q) / 3.0;
  }
  return std::abs(area) > 0 ? Vec3(moment / area) : mean;
}

}  // namespace

SatShape::SatShape(const ConvexPolyhedron& shape)
    : shape_(&shape), topology_(std::make_shared<const Topology>(build_topology(shape))) {}

SatResult sat_query(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                    const Pose& pb) {
  return sat_query(SatShape(a), pa, SatShape(b), pb);
}

namespace {

// Both shapes placed about the midpoint of their poses (symmetric in the arguments), with the
// query's tolerances from the pair's largest coordinate.
struct PlacedPair {
  Vec3 origin;
  Placed a, b;
  double roundoff = 0.0;  // m: round-off of a support difference
  double prefer = 0.0;    // m: how much better an edge pair must be than the best face
};

PlacedPair place_pair(const SatShape& a, const Pose& pa, const SatShape& b, const Pose& pb) {
  PlacedPair q;
  q.origin = 0.5 * (pa.position + pb.position);
  q.a = place(a, pa, q.origin);
  q.b = place(b, pb, q.origin);
  double length = 0.0;  // m: largest coordinate magnitude of the pair
  for (const Vec3& p : q.a.x) length = std::max(length, p.norm());
  for (const Vec3& p : q.b.x) length = std::max(length, p.norm());
  q.roundoff = kRoundoffRelative * length;
  q.prefer = kPreferRelative * length;
  return q;
}

// The patch of a face axis: the incident face clipped to the reference face, in the world.
std::vector<Vec3> face_patch(const PlacedPair& q, const Axis& face) {
  const Placed& ref = face.owner == 0 ? q.a : q.b;
  const Placed& inc = face.owner == 0 ? q.b : q.a;
  std::vector<Vec3> patch = face_manifold(ref, face.face, inc, q.roundoff);
  for (Vec3& p : patch) p += q.origin;
  return patch;
}

}  // namespace

SatResult sat_query(const SatShape& a, const Pose& pa, const SatShape& b, const Pose& pb) {
  const PlacedPair q = place_pair(a, pa, b, pb);
  const Placed &sa = q.a, &sb = q.b;
  const double roundoff = q.roundoff, prefer = q.prefer;

  // Face axes: the tied set within `prefer` of the minimum, then the slot-free reference order.
  std::vector<Axis> faces;
  face_axes(sa, sb, 0, faces);
  face_axes(sb, sa, 1, faces);
  double min_face = std::numeric_limits<double>::infinity();
  for (const Axis& ax : faces) min_face = std::min(min_face, ax.overlap);
  const Axis* best_face = nullptr;
  for (const Axis& ax : faces)
    if (ax.overlap <= min_face + prefer && (!best_face || better_reference(ax, *best_face)))
      best_face = &ax;

  // Edge axes: minimum overlap, exact ties broken by the unsigned axis direction.
  const std::vector<Axis> edges = edge_axes(sa, sb);
  const Axis* best_edge = nullptr;
  for (const Axis& ax : edges)
    if (!best_edge || ax.overlap < best_edge->overlap ||
        (ax.overlap == best_edge->overlap &&
         lex_greater(canonical(ax.normal), canonical(best_edge->normal))))
      best_edge = &ax;

  // A face axis wins unless an edge pair is better by more than the preference tolerance.
  const bool use_edge = best_edge && best_edge->overlap < best_face->overlap - prefer;
  const Axis& best = use_edge ? *best_edge : *best_face;

  SatResult r;
  r.normal = best.normal;
  r.touching = best.overlap >= -roundoff;
  r.depth = r.touching ? std::max(best.overlap, 0.0) : best.overlap;
  r.axis_kind = use_edge ? "edge_edge" : (best.owner == 0 ? "face_a" : "face_b");
  if (!r.touching) return r;

  if (use_edge) {
    r.manifold.push_back(edge_manifold(sa, best.class_a, sb, best.class_b, best.normal) + q.origin);
  } else {
    r.manifold = face_patch(q, best);
  }
  return r;
}

std::optional<SatPatch> sat_patch_along(const ConvexPolyhedron& a, const Pose& pa,
                                        const ConvexPolyhedron& b, const Pose& pb,
                                        const Vec3& normal) {
  const SatShape shape_a(a), shape_b(b);  // the placed shapes point into their topologies
  const PlacedPair q = place_pair(shape_a, pa, shape_b, pb);
  std::vector<Axis> faces;
  face_axes(q.a, q.b, 0, faces);
  face_axes(q.b, q.a, 1, faces);
  double least = std::numeric_limits<double>::infinity();
  for (const Axis& ax : faces) least = std::min(least, ax.overlap);
  for (const Axis& ax : edge_axes(q.a, q.b)) least = std::min(least, ax.overlap);
  if (!(least >= -q.roundoff)) return std::nullopt;
  // The tied face axis nearest the direction, within 1 degree of it (a normal further off is
  // wrong, not another tied axis).
  const Vec3 n = normal.normalized();
  const Axis* nearest = nullptr;
  double most = std::cos(M_PI / 180.0);
  for (const Axis& ax : faces) {
    if (!(ax.overlap <= least + q.prefer)) continue;
    const double along = ax.normal.dot(n);
    // Two faces on one axis (a face resting on a face): sat_query's reference order.
    const bool same = nearest && std::abs(along - most) <= 1e-12;
    if (same ? better_reference(ax, *nearest) : along > most) {
      nearest = &ax;
      most = std::max(most, along);
    }
  }
  if (!nearest) return std::nullopt;
  return SatPatch{nearest->normal, face_patch(q, *nearest)};
}

ContactResult exact_contact(const RigidBody& a, const RigidBody& b) {
  ContactResult r;
  try {
    if (!a.shape || !b.shape) throw std::invalid_argument("exact: body without a shape");
    const SatResult sat = sat_query(*a.shape, a.pose(), *b.shape, b.pose());
    if (!sat.touching) return r;
    const std::string feature = sat.axis_kind == "edge_edge" ? "edge" : "face";
    // First the patch centroid, then every manifold point, all with the SAT normal and depth.
    r.contacts.push_back({centroid(sat.manifold, sat.normal), sat.normal, sat.depth, feature});
    for (const Vec3& p : sat.manifold) r.contacts.push_back({p, sat.normal, sat.depth, feature});
  } catch (const std::exception& e) {
    r.status = Status::Error;
    r.message = e.what();
    r.contacts.clear();
  }
  return r;
}

namespace {

// The oracle's distance (exact_distance.cpp) as a backend's answer.
DistanceResult exact_distance_query(const RigidBody& a, const RigidBody& b) {
  const ExactDistance e = exact_distance(*a.shape, a.pose(), *b.shape, b.pose());
  DistanceResult r;
  r.overlapping = e.overlapping;
  r.distance = e.distance;
  r.point_a = e.point_a;
  r.point_b = e.point_b;
  if (!e.overlapping)
    r.message = "closest features: " + e.feature_a + " of A, " + e.feature_b + " of B";
  return r;
}

}  // namespace

const Adapter& exact_adapter() {
  // Our own code, not isolated (library = false).
  static const Adapter adapter = {
      {Backend{"exact",
               "rbx oracle: separating-axis test over faces and edge pairs, clipped manifold",
               exact_contact, nullptr, nullptr, false}
           .measuring(exact_distance_query)
           .sweeping([](const RigidBody& a, const RigidBody& b, double dt) {
             return exact_toi(a, b, dt);
           })
           .drawn("#000000", "*")
           .timed(2048, 512)},
      {}};
  return adapter;
}

}  // namespace rbx
