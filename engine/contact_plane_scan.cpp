// The scan for the contact plane (engine/contact_plane_detail.h): face axes with a lower bound
// that skips faces which cannot win, edge-pair axes with the Gauss-map test, projections by
// climbing the vertex graph (exact on a convex polyhedron) or by a scan for the small shapes.
#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/contact_plane_detail.h"
#include "engine/gauss_map.h"

namespace rbx::plane_detail {

namespace {

// A shape placed in the world for one query.
struct Placed {
  const ConvexPolyhedron* shape = nullptr;
  Mat3 r = Mat3::Identity();
  std::vector<Vec3> v;  // m, world vertices (the seed's r v + position)
  Vec3 centre = Vec3::Zero();
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // world bounds of v
  // A few vertices of the shape (its extremes along the world axes and toward the other
  // shape): the least projection over them bounds the shape's least projection from above.
  std::vector<Vec3> samples;

  // The furthest projection of the shape along d, and in `at` a vertex that reaches it. With a
  // hierarchy, climbs the vertex graph from `at`; otherwise scans every vertex.
  double max_along(const Vec3& d, int& at) const {
    double best = -kInf;
    if (shape->hierarchy()) {
      at = shape->gauss_map().climb(v, d, at, best);
      return best;
    }
    for (int i = 0; i < static_cast<int>(v.size()); ++i) {
      const double s = v[i].dot(d);
      if (s > best) {
        best = s;
        at = i;
      }
    }
    return best;
  }
};

// The shape's extreme vertices along +-x, +-y, +-z and along `toward` (samples).
void sample(Placed& x, const Vec3& toward) {
  x.samples.clear();
  const Vec3 dirs[7] = {Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(),
                        Vec3::UnitZ(), -Vec3::UnitZ(), toward};
  const GaussMap& g = x.shape->gauss_map();
  const Mat3 rt = x.r.transpose();
  for (const Vec3& d : dirs) {
    // Climbs start from the Gauss map's start vertex nearest d, a few edges from the answer.
    int at = g.start_for(rt * d);
    x.max_along(d, at);
    x.samples.push_back(x.v[at]);
  }
}

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

// An edge's arc on the Gauss map (between its two faces' normals, negated for B: the faces of
// A - B) and a ball holding it: two arcs can only cross where their balls meet.
struct Arc {
  Vec3 n0 = Vec3::Zero(), n1 = Vec3::Zero();  // unit, world
  Vec3 centre = Vec3::Zero();
  double radius = 0.0;
  int edge = 0;
};

// The state of one query: both shapes placed, the least overlap so far, the candidates kept.
struct Query {
  Placed a, b;
  double best = kInf;  // m, least overlap so far
  double tie = 0.0;    // m, overlaps closer than this are equal (round-off)
  // A point that may lie inside both shapes, to prove they overlap: the witness of the candidate
  // of least overlap (face_axes, edge_axes). When it is a vertex of one shape, `witness_in` is
  // the other (the only one it must be inside); null: it must be inside both.
  Vec3 witness = Vec3::Zero();
  const Placed* witness_in = nullptr;
  double witness_overlap = kInf;
  std::vector<Candidate> kept;
  std::vector<std::pair<double, int>> bounds;  // scratch: (lower bound, face)
  std::vector<int> edges_a, edges_b;           // scratch: solid edges near the other shape
  std::vector<Arc> arcs_a, arcs_b;             // scratch: their Gauss-map arcs
  // Per shape, the face planes (world normal, height) of least overlap found, at most kPlanes.
  static constexpr int kPlanes = 4;
  struct FacePlane {
    Vec3 n;
    double height;
    double overlap = kInf;
  };
  std::vector<FacePlane> planes_a, planes_b;

  void keep(const Candidate& c) {
    best = std::min(best, c.overlap);
    kept.push_back(c);
  }
  void keep_plane(std::vector<FacePlane>& planes, FacePlane p, double overlap) {
    p.overlap = overlap;
    if (static_cast<int>(planes.size()) < kPlanes) {
      planes.push_back(p);
      return;
    }
    auto worst = std::max_element(planes.begin(), planes.end(), [](const auto& u, const auto& w) {
      return u.overlap < w.overlap;
    });
    if (overlap < worst->overlap) *worst = p;
  }
};

// The face axes of x: pushing y out of x along each face normal costs the face's height minus
// y's lowest projection. The lower bound (the face's height minus the least projection of y's
// sample vertices, points of y) skips a face without a projection when it exceeds the least
// overlap so far plus the tie margin, so no face that could win or tie is ever skipped.
void face_axes(Query& q, const Placed& x, const Placed& y, bool x_is_a) {
  const ConvexPolyhedron& s = *x.shape;
  const auto& tris = s.triangles();
  q.bounds.clear();
  for (int f = 0; f < static_cast<int>(tris.size()); ++f) {
    if (!s.new_plane()[f]) continue;  // the same plane as the triangle before it
    const Vec3 n = x.r * s.planes()[f].normal;
    double low = n.dot(y.centre);
    for (const Vec3& p : y.samples) low = std::min(low, n.dot(p));
    q.bounds.push_back({n.dot(x.v[tris[f][0]]) - low, f});
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
    // The lowest point of y along the face of least overlap so far (a vertex of y): inside x, it
    // proves the shapes overlap (overlaps).
    if (c.overlap < q.witness_overlap) {
      q.witness_overlap = c.overlap;
      q.witness = y.v[at];
      q.witness_in = &x;
    }
    c.kind = 0;
    c.axis = canonical(n);
    // y is pushed along n: the normal from B toward A is n when y is A, -n when y is B.
    c.normal = x_is_a ? Vec3(-n) : n;
    c.source = x_is_a ? PlaneAxis::FaceOfA : PlaneAxis::FaceOfB;
    q.keep(c);
    // x's face planes of least overlap: every point within that overlap of x lies below them.
    q.keep_plane(x_is_a ? q.planes_a : q.planes_b, {n, height}, c.overlap);
  }
}

// Whether p lies inside x by more than `margin` below every face plane.
bool strictly_inside(const Placed& x, const Vec3& p, double margin) {
  const ConvexPolyhedron& s = *x.shape;
  const auto& tris = s.triangles();
  for (int f = 0; f < static_cast<int>(tris.size()); ++f)
    if (s.new_plane()[f] && (x.r * s.planes()[f].normal).dot(p - x.v[tris[f][0]]) > -margin)
      return false;
  return true;
}

// Whether the shapes are proved to overlap: a point strictly inside both (the witness of the
// candidate of least overlap, or either shape's vertex mean inside the other). The edge filters
// (near_edges, the lines' distance in edge_axes) assume it: for overlapping shapes every
// candidate's overlap is positive and its two edges pass within it of each other, while shapes
// apart by a hair (which the tests may call touching) have a negative least overlap that two
// edges can give from any distance.
bool overlaps(const Query& q) {
  if (q.witness_overlap < kInf) {
    const bool in_a = q.witness_in == &q.b || strictly_inside(q.a, q.witness, q.tie);
    const bool in_b = q.witness_in == &q.a || strictly_inside(q.b, q.witness, q.tie);
    if (in_a && in_b) return true;
  }
  return strictly_inside(q.a, q.b.centre, q.tie) || strictly_inside(q.b, q.a.centre, q.tie);
}

// The solid edges of x (not a flat face's diagonal) that come within `reach` of the other
// shape: an edge pair can only give an overlap d when its two edges pass within d of each
// other, so within d of the other shape: inside its bounds grown by d, and no further than d
// above any of its face planes (those of least overlap are the tightest near the contact).
void near_edges(const Placed& x, const Placed& other, const std::vector<Query::FacePlane>& planes,
                double reach, std::vector<int>& out) {
  const ConvexPolyhedron& s = *x.shape;
  out.clear();
  const Vec3 lo = other.lo - Vec3::Constant(reach), hi = other.hi + Vec3::Constant(reach);
  for (int i = 0; i < static_cast<int>(s.edges().size()); ++i) {
    const Edge& e = s.edges()[i];
    const Vec3 &p = x.v[e.a], &r = x.v[e.b];
    if ((p.cwiseMax(r).array() < lo.array()).any() || (p.cwiseMin(r).array() > hi.array()).any())
      continue;
    bool far = false;
    for (const Query::FacePlane& f : planes)
      far = far || std::min(f.n.dot(p), f.n.dot(r)) - f.height > reach;
    if (far) continue;
    const auto& f = s.edge_faces()[i];
    // 1 - cos(angle) below 1e-12: the same plane to the validation's convexity tolerance.
    if (s.planes()[f[0]].normal.dot(s.planes()[f[1]].normal) > 1.0 - 1e-12) continue;
    out.push_back(i);
  }
}

void arcs_of(const Placed& x, const std::vector<int>& edges, double sign, std::vector<Arc>& out) {
  out.clear();
  for (const int i : edges) {
    const auto& f = x.shape->edge_faces()[i];
    Arc arc;
    arc.n0 = sign * (x.r * x.shape->planes()[f[0]].normal);
    arc.n1 = sign * (x.r * x.shape->planes()[f[1]].normal);
    const Vec3 mid = arc.n0 + arc.n1;
    // Faces nearly opposite (a sliver's rim): no useful centre, a ball holding the whole sphere.
    arc.centre = mid.norm() > 1e-6 ? Vec3(mid.normalized()) : arc.n0;
    // The chord to either end bounds every point of the short arc; 1e-9 of slack for round-off.
    arc.radius = mid.norm() > 1e-6
                     ? std::max((arc.n0 - arc.centre).norm(), (arc.n1 - arc.centre).norm()) + 1e-9
                     : 2.0 + 1e-9;
    arc.edge = i;
    out.push_back(arc);
  }
}

// The edge-pair axes: each solid edge of A near B against each of B near A whose Gauss-map
// arcs cross, found by a sweep over the arcs' balls along x.
void edge_axes(Query& q) {
  const Placed &a = q.a, &b = q.b;
  near_edges(a, b, q.planes_b, q.best + q.tie, q.edges_a);
  near_edges(b, a, q.planes_a, q.best + q.tie, q.edges_b);
  arcs_of(a, q.edges_a, 1.0, q.arcs_a);
  arcs_of(b, q.edges_b, -1.0, q.arcs_b);
  std::sort(q.arcs_b.begin(), q.arcs_b.end(),
            [](const Arc& u, const Arc& w) { return u.centre.x() < w.centre.x(); });
  double widest = 0.0;
  for (const Arc& arc : q.arcs_b) widest = std::max(widest, arc.radius);
  for (const Arc& arc_a : q.arcs_a) {
    const Edge& ea = a.shape->edges()[arc_a.edge];
    const Vec3 da = a.v[ea.b] - a.v[ea.a];
    const double from = arc_a.centre.x() - arc_a.radius - widest;
    auto it = std::lower_bound(q.arcs_b.begin(), q.arcs_b.end(), from,
                               [](const Arc& u, double x) { return u.centre.x() < x; });
    for (; it != q.arcs_b.end() && it->centre.x() <= arc_a.centre.x() + arc_a.radius + widest;
         ++it) {
      const Arc& arc_b = *it;
      if ((arc_a.centre - arc_b.centre).norm() > arc_a.radius + arc_b.radius) continue;
      if (!arcs_cross(arc_a.n0, arc_a.n1, arc_b.n0, arc_b.n1)) continue;
      const Edge& eb = b.shape->edges()[arc_b.edge];
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
      // The midpoint of the two edges' closest points: inside both shapes, it proves the
      // overlap of a pair whose least overlap is this edge pair's.
      if (k.overlap < q.witness_overlap) {
        const double aa = da.dot(da), bb = db.dot(db), ab = da.dot(db);
        const Vec3 r = a.v[ea.a] - b.v[eb.a];
        const double denom = aa * bb - ab * ab;  // > 0: the edges are not parallel (above)
        const double u = (ab * db.dot(r) - bb * da.dot(r)) / denom;
        const double w = (aa * db.dot(r) - ab * da.dot(r)) / denom;
        if (u >= 0 && u <= 1 && w >= 0 && w <= 1) {
          q.witness_overlap = k.overlap;
          q.witness = 0.5 * ((a.v[ea.a] + u * da) + (b.v[eb.a] + w * db));
          q.witness_in = nullptr;  // inside both
        }
      }
    }
  }
}

}  // namespace

// The scan's lists: one query's state, kept by the caller's scratch between queries.
struct ScanLists {
  Query q;
};

void ListsDeleter::operator()(ScanLists* p) const { delete p; }

bool scan_candidates(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                     const Pose& pb, Candidates& out, Scratch& scratch) {
  if (!scratch.scan) scratch.scan.reset(new ScanLists);
  Query& q = scratch.scan->q;
  place(a, pa, q.a);
  place(b, pb, q.b);
  sample(q.a, q.b.centre - q.a.centre);
  sample(q.b, q.a.centre - q.b.centre);
  q.best = kInf;
  q.kept.clear();
  q.planes_a.clear();
  q.planes_b.clear();
  // Round-off of a projection difference is a few ulps of the largest coordinate; 1e-12 of it is
  // ~10^3 times that, far below any depth a tolerance in the harness distinguishes.
  const double scale = std::max({q.a.lo.cwiseAbs().maxCoeff(), q.a.hi.cwiseAbs().maxCoeff(),
                                 q.b.lo.cwiseAbs().maxCoeff(), q.b.hi.cwiseAbs().maxCoeff()});
  q.tie = 1e-12 * scale;
  // A known overlap bounds the least from the start; one tie margin more absorbs the round-off
  // between its arithmetic and this scan's.
  q.best = out.known + q.tie;

  q.witness_in = nullptr;
  q.witness_overlap = kInf;
  face_axes(q, q.a, q.b, true);
  face_axes(q, q.b, q.a, false);
  edge_axes(q);
  if (!overlaps(q)) return false;
  out.kept.swap(q.kept);
  out.tie = q.tie;
  return true;
}

}  // namespace rbx::plane_detail
