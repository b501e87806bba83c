// The direction of least overlap of two convex polyhedra: face axes with a lower bound that skips
// faces which cannot win, edge-pair axes with the Gauss-map test, projections by climbing the
// vertex graph (exact on a convex polyhedron) or by a scan for the small shapes.
#include "engine/contact_plane.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "engine/shape_hierarchy.h"

namespace rbx {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A shape placed in the world for one query.
struct Placed {
  const ConvexPolyhedron* shape = nullptr;
  Mat3 r = Mat3::Identity();
  std::vector<Vec3> v;  // m, world vertices (the seed's r v + position)
  Vec3 centre = Vec3::Zero();
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // world bounds of v

  // The furthest projection of the shape along d, and in `at` a vertex that reaches it. With a
  // hierarchy, climbs the vertex graph from `at` (a vertex with no higher neighbour is highest
  // on a convex polyhedron); otherwise scans every vertex.
  double max_along(const Vec3& d, int& at) const {
    const ShapeHierarchy* h = shape->hierarchy();
    if (!h) {
      double best = -kInf;
      for (int i = 0; i < static_cast<int>(v.size()); ++i) {
        const double s = v[i].dot(d);
        if (s > best) {
          best = s;
          at = i;
        }
      }
      return best;
    }
    double best = v[at].dot(d);
    for (bool moved = true; moved;) {
      moved = false;
      for (int k = h->edge_start[at]; k < h->edge_start[at + 1]; ++k) {
        const Edge& e = shape->edges()[h->vertex_edges[k]];
        const int o = e.a == at ? e.b : e.a;
        const double s = v[o].dot(d);
        if (s > best) {
          best = s;
          at = o;
          moved = true;
        }
      }
    }
    return best;
  }
};

void place(const ConvexPolyhedron& s, const Pose& p, Placed& out) {
  out.shape = &s;
  out.r = p.rotation();
  out.v.clear();
  out.v.reserve(s.vertices().size());
  out.lo = Vec3::Constant(kInf);
  out.hi = Vec3::Constant(-kInf);
  Vec3 sum = Vec3::Zero();
  for (const Vec3& c : s.vertices()) {
    out.v.push_back(p.apply(c));
    sum += out.v.back();
    out.lo = out.lo.cwiseMin(out.v.back());
    out.hi = out.hi.cwiseMax(out.v.back());
  }
  out.centre = sum / static_cast<double>(s.vertices().size());
}

// The sign-free form of an axis: the one of +-n whose first nonzero component is positive, so
// that an axis found from either body order compares equal.
Vec3 canonical(const Vec3& n) {
  const bool flip = n.x() < 0 || (n.x() == 0 && (n.y() < 0 || (n.y() == 0 && n.z() < 0)));
  return flip ? Vec3(-n) : n;
}

bool lex_less(const Vec3& p, const Vec3& q) {
  if (p.x() != q.x()) return p.x() < q.x();
  if (p.y() != q.y()) return p.y() < q.y();
  return p.z() < q.z();
}

// One candidate axis: its overlap, the kind (faces before edge pairs on a tie: a face contact
// is the stable one), its sign-free form and the normal from B toward A.
struct Candidate {
  double overlap = kInf;
  int kind = 0;  // 0 face, 1 edge pair
  Vec3 axis = Vec3::Zero();
  Vec3 normal = Vec3::Zero();
  PlaneAxis source = PlaneAxis::FaceOfB;
};

// The state of one query: both shapes placed, the least overlap so far, the candidates kept.
struct Query {
  Placed a, b;
  double best = kInf;  // m, least overlap so far
  double tie = 0.0;    // m, overlaps closer than this are equal (round-off)
  std::vector<Candidate> kept;
  std::vector<std::pair<double, int>> bounds;  // scratch: (lower bound, face)
  std::vector<int> edges_a, edges_b;           // scratch: solid edges near the other shape

  void keep(const Candidate& c) {
    best = std::min(best, c.overlap);
    kept.push_back(c);
  }
};

// The face axes of x: pushing y out of x along each face normal costs the face's height minus
// y's lowest projection. The lower bound (the face's height minus the projection of y's centre,
// a point of y) skips a face without a projection when it exceeds the least overlap so far plus
// the tie margin, so no face that could win or tie is ever skipped.
void face_axes(Query& q, const Placed& x, const Placed& y, bool x_is_a) {
  const ConvexPolyhedron& s = *x.shape;
  const auto& tris = s.triangles();
  q.bounds.clear();
  for (int f = 0; f < static_cast<int>(tris.size()); ++f) {
    if (!s.new_plane()[f]) continue;  // the same plane as the triangle before it
    const Vec3 n = x.r * s.planes()[f].normal;
    q.bounds.push_back({n.dot(x.v[tris[f][0]]) - n.dot(y.centre), f});
  }
  // The most promising face first, so the bound skips most of the others.
  const auto first = std::min_element(q.bounds.begin(), q.bounds.end());
  std::iter_swap(q.bounds.begin(), first);
  int at = 0;
  for (const auto& [bound, f] : q.bounds) {
    if (bound > q.best + q.tie) continue;
    const Vec3 n = x.r * s.planes()[f].normal;
    const double height = n.dot(x.v[tris[f][0]]);
    const double low = -y.max_along(-n, at);
    Candidate c;
    c.overlap = height - low;
    c.kind = 0;
    c.axis = canonical(n);
    // y is pushed along n: the normal from B toward A is n when y is A, -n when y is B.
    c.normal = x_is_a ? Vec3(-n) : n;
    c.source = x_is_a ? PlaneAxis::FaceOfA : PlaneAxis::FaceOfB;
    q.keep(c);
  }
}

// The solid edges of x (not a flat face's diagonal) whose bounds come within `reach` of the
// other shape's bounds: an edge pair can only give an overlap d when its two edges pass within
// d of each other, so within d of the other shape.
void near_edges(const Placed& x, const Placed& other, double reach, std::vector<int>& out) {
  const ConvexPolyhedron& s = *x.shape;
  out.clear();
  const Vec3 lo = other.lo - Vec3::Constant(reach), hi = other.hi + Vec3::Constant(reach);
  for (int i = 0; i < static_cast<int>(s.edges().size()); ++i) {
    const Edge& e = s.edges()[i];
    const Vec3 &p = x.v[e.a], &r = x.v[e.b];
    if ((p.cwiseMax(r).array() < lo.array()).any() || (p.cwiseMin(r).array() > hi.array()).any())
      continue;
    const auto& f = s.edge_faces()[i];
    // 1 - cos(angle) below 1e-12: the same plane to the validation's convexity tolerance.
    if (s.planes()[f[0]].normal.dot(s.planes()[f[1]].normal) > 1.0 - 1e-12) continue;
    out.push_back(i);
  }
}

// Whether the Gauss-map arcs p0-p1 (A's two face normals) and q0-q1 (B's, negated: the faces of
// the Minkowski difference A - B) cross, so that the edges' cross product is a face normal of
// A - B. Conservative: a pair within round-off of crossing passes (its overlap is then measured
// by projections, which can only overestimate, never undercut, the least overlap).
bool arcs_cross(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  constexpr double kSlack = 1e-12;
  const Vec3 pn = p1.cross(p0), qn = q1.cross(q0);
  const double q0p = q0.dot(pn), q1p = q1.dot(pn), p0q = p0.dot(qn), p1q = p1.dot(qn);
  return q0p * q1p <= kSlack && p0q * p1q <= kSlack && q0p * p1q >= -kSlack;
}

// The edge-pair axes: each solid edge of A near B against each of B near A.
void edge_axes(Query& q) {
  const Placed &a = q.a, &b = q.b;
  near_edges(a, b, q.best + q.tie, q.edges_a);
  near_edges(b, a, q.best + q.tie, q.edges_b);
  for (const int i : q.edges_a) {
    const Edge& ea = a.shape->edges()[i];
    const auto& fa = a.shape->edge_faces()[i];
    const Vec3 n0 = a.r * a.shape->planes()[fa[0]].normal,
               n1 = a.r * a.shape->planes()[fa[1]].normal;
    const Vec3 da = a.v[ea.b] - a.v[ea.a];
    for (const int j : q.edges_b) {
      const Edge& eb = b.shape->edges()[j];
      const auto& fb = b.shape->edge_faces()[j];
      const Vec3 m0 = b.r * b.shape->planes()[fb[0]].normal,
                 m1 = b.r * b.shape->planes()[fb[1]].normal;
      if (!arcs_cross(n0, n1, -m0, -m1)) continue;
      const Vec3 db = b.v[eb.b] - b.v[eb.a];
      Vec3 d = da.cross(db);
      // Parallel edges (sine below 1e-9) give no axis of their own: a face normal covers them.
      if (!(d.squaredNorm() > 1e-18 * da.squaredNorm() * db.squaredNorm())) continue;
      d.normalize();
      // The distance of the two edges' lines along d: the pair's overlap when it is a face of
      // A - B, so a pair beyond the least overlap so far is skipped before any projection.
      if (std::abs(d.dot(b.v[eb.a] - a.v[ea.a])) > q.best + q.tie) continue;
      const Vec3 c = canonical(d);
      int at_a = ea.a, at_b = eb.a;
      const double hi_a = a.max_along(c, at_a), hi_b = b.max_along(c, at_b);
      at_a = ea.a;
      at_b = eb.a;
      const double lo_a = -a.max_along(-c, at_a), lo_b = -b.max_along(-c, at_b);
      // A above B along c (normal c), or below it (normal -c): the smaller move.
      const double up = hi_b - lo_a, down = hi_a - lo_b;
      Candidate k;
      k.kind = 1;
      k.axis = c;
      k.source = PlaneAxis::EdgeEdge;
      k.overlap = std::min(up, down);
      k.normal = up <= down ? c : Vec3(-c);
      q.keep(k);
    }
  }
}

}  // namespace

ContactPlane choose_contact_plane(const ConvexPolyhedron& a, const Pose& pa,
                                  const ConvexPolyhedron& b, const Pose& pb) {
  // Scratch reused across queries on this thread (allocated once, as the detector's).
  thread_local Query q;
  place(a, pa, q.a);
  place(b, pb, q.b);
  q.best = kInf;
  q.kept.clear();
  // Round-off of a projection difference is a few ulps of the largest coordinate; 1e-12 of it is
  // ~10^3 times that, far below any depth a tolerance in the harness distinguishes.
  const double scale = std::max({q.a.lo.cwiseAbs().maxCoeff(), q.a.hi.cwiseAbs().maxCoeff(),
                                 q.b.lo.cwiseAbs().maxCoeff(), q.b.hi.cwiseAbs().maxCoeff()});
  q.tie = 1e-12 * scale;

  face_axes(q, q.a, q.b, true);
  face_axes(q, q.b, q.a, false);
  edge_axes(q);

  // Among the candidates within the tie margin of the least overlap: faces first, then the
  // smaller sign-free axis, then the smaller overlap. Every key is the geometry's, not the slot's.
  const Candidate* pick = nullptr;
  for (const Candidate& c : q.kept) {
    if (c.overlap > q.best + q.tie) continue;
    if (!pick || c.kind < pick->kind ||
        (c.kind == pick->kind &&
         (lex_less(c.axis, pick->axis) || (c.axis == pick->axis && c.overlap < pick->overlap))))
      pick = &c;
  }
  ContactPlane out;
  out.normal = pick->normal;
  out.depth = std::max(pick->overlap, 0.0);
  out.axis = pick->source;
  return out;
}

}  // namespace rbx
