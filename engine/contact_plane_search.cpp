// The direction of least overlap of two convex polyhedra, by branch and bound over their Gauss
// maps. Every candidate axis (a face normal, or the crossing of two edges' arcs) is a face normal
// of the Minkowski difference D = A - B, and its overlap is h_A(n) + h_B(-n). Over a cone of one
// shape's normals, its own support is at least the least face offset in the cone (plus its
// position along n) and the other's is at least that of any one of its points, so a cone whose
// bound exceeds the least overlap measured cannot hold the answer and is skipped with every face
// and edge in it. docs/contact_plane.md derives the bound and says why no candidate within the tie
// margin is ever skipped. When the inner polytope (engine/contact_plane_polytope.cpp) has narrowed
// the directions to a cone, only the nodes, faces and arcs that meet it are opened, and a narrow
// cone is enumerated from the vertices that support it, without the trees.
#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/contact_plane_detail.h"
#include "engine/gauss_map.h"

namespace rbx::plane_detail {

namespace {

// The least of x . u over the unit vectors u of a cone (axis in the world): |x| cos(theta + r)
// for theta the angle of x to the axis and r the cone's, or -|x| once theta + r reaches pi.
double cone_bound(const Vec3& x, const Vec3& axis, const DirectionCone& cone) {
  const double size = x.norm();
  if (cone.whole) return -size;
  const double along = x.dot(axis);
  // The cone reaches the direction opposite x (its angle to x plus the cone's is pi or more).
  if (along <= -size * cone.cos_angle) return -size;
  return along * cone.cos_angle - x.cross(axis).norm() * cone.sin_angle;
}

// The trees searched: the faces and the arcs of A and of B.
enum Tree { kFacesA = 0, kFacesB = 1, kArcsA = 2, kArcsB = 3 };

// A node waiting in the search: the lower bound it carries, and the vertex of the other shape
// from which its climb starts (its parent's, near its axis; -1 at a root: from the Gauss map's
// start vertices).
struct Pending {
  double bound = -kInf;
  int tree = 0, node = 0;
  int at_other = -1;
  // The heap's order: the least bound on top; ties by tree and node (deterministic).
  bool operator<(const Pending& o) const {
    if (bound != o.bound) return bound > o.bound;
    if (tree != o.tree) return tree > o.tree;
    return node > o.node;
  }
};

// An arc kept for pairing: its D-space endpoints and cone axis, and its edge.
struct KeptArc {
  double bound = -kInf;
  Vec3 n0, n1, axis;
  const DirectionCone* cone = nullptr;
  int edge = 0;
};

// The state of one query.
struct Query {
  Side a, b;
  double upper = kInf;  // m, the least overlap measured so far: an upper bound on the answer
  Vec3 upper_normal = Vec3::UnitZ();  // the normal of the candidate that gave `upper`
  double tie = 0.0;                   // m, overlaps closer than this are equal (round-off)
  DirectionCone within;               // D's directions that may hold the answer (world)
  int narrow_at[2] = {-1, -1};        // narrowed: A's and B's vertices supporting D along its axis
  double narrow_bound[2] = {0, 0};    // narrowed: cone_bound over `within` from A's and B's side
  Vec3 narrow_y[2];                   // narrowed: own position minus the other's supporting point
  Vec3 within_local[2];  // narrowed: `within`'s axis in A's and B's body frame (B's negated)
  std::vector<Candidate> kept;
  std::vector<Pending> heap;
  std::vector<KeptArc> arcs[2];  // A's and B's arcs that may hold the answer
  std::vector<int> found;        // the local search's vertices
  // Per vertex and per face of the shape searched, the local search that last took it (a count
  // of searches, so that nothing is cleared between them).
  std::vector<unsigned> vertex_mark, face_mark;
  unsigned mark = 0;

  // Nothing whose lower bound exceeds this can be within the tie margin of the answer: twice
  // the margin absorbs the round-off of the bounds themselves.
  double threshold() const { return upper + 2.0 * tie; }
  const Side& side(int tree) const { return tree % 2 == 0 ? a : b; }
  // Directions of B's Gauss map are negated in D = A - B.
  static double sign(int tree) { return tree % 2 == 0 ? 1.0 : -1.0; }
  // Whether a direction of D lies outside the directions searched.
  bool outside(const Vec3& u) const {
    return !within.whole && u.dot(within.axis) < within.cos_angle - 1e-12;
  }

  void keep(const Candidate& c) {
    if (c.overlap < upper) {
      upper = c.overlap;
      upper_normal = c.normal;
    }
    kept.push_back(c);
  }
  void push(double bound, int tree, int node, int at_other) {
    // Written field by field in place: a whole temporary copied in stalls on its narrower stores.
    Pending& p = heap.emplace_back();
    p.bound = bound;
    p.tree = tree;
    p.node = node;
    p.at_other = at_other;
    // Narrowed, the few nodes left are taken depth first (no order to keep).
    if (within.whole) std::push_heap(heap.begin(), heap.end());
  }
  void search();
  void local_search();
  void visit(const Pending& e);
  void leaf_face(int tree, int item, const Vec3& y, int at);
  void leaf_arc(int tree, int item, const Vec3& y);
  void face(int tree, int f, int at_other);
  void pair_arcs();
  void edge_pair(const KeptArc& ka, const KeptArc& kb);
};

void Query::search() {
  heap.clear();
  for (int t = kFacesA; t <= kArcsB; ++t) {
    const GaussMap& g = *side(t).map;
    if (!(t < kArcsA ? g.face_tree : g.arc_tree).nodes.empty()) push(-kInf, t, 0, -1);
  }
  while (!heap.empty()) {
    if (within.whole) std::pop_heap(heap.begin(), heap.end());
    const Pending e = heap.back();
    heap.pop_back();
    if (e.bound > threshold()) {
      // Every node left has a bound at least this one's (not so depth first).
      if (within.whole) break;
      continue;
    }
    visit(e);
  }
}

// One node of the own shape's faces or arcs, whose normals n lie in the node's cone. Each
// overlap there is h_D = h_own(n) + h_other(-n) >= low + (p_own - y) . n for the node's least
// own support `low` and any point y of the other shape; y is the other's lowest point along the
// node's axis (one climb), and the least of (p_own - y) . n over the cone is cone_bound. A leaf's
// faces are then measured, a leaf's arcs kept for pairing, an inner node's children queued with
// their bounds from the same point.
void Query::visit(const Pending& e) {
  const Side& own = side(e.tree);
  const Side& other = side(e.tree + 1);
  const GaussMap& g = *own.map;
  const bool faces = e.tree < kArcsA;
  const Bvh& tree = faces ? g.face_tree : g.arc_tree;
  const std::vector<DirectionCone>& cones = faces ? g.face_cones : g.arc_cones;
  const std::vector<double>& lows = faces ? g.face_lows : g.arc_lows;
  // Narrowed, only the directions of `within` count (tested in the own body frame, where the
  // node's cone lies), and the other shape's point that supports D along its axis serves every
  // node, with one cone bound per tree.
  const bool narrowed = !within.whole;
  const int side_of = e.tree % 2;
  if (narrowed && cones_apart(cones[e.node].axis, cones[e.node], within_local[side_of], within))
    return;
  Vec3 axis = Vec3::Zero();
  int at = e.at_other;
  if (narrowed) {
    at = narrow_at[1 - side_of];
  } else {
    axis = own.r * cones[e.node].axis;
    other.support(-axis, at);
  }
  const Vec3 y = narrowed ? narrow_y[side_of] : Vec3(own.p - other.world(at));
  const double bound = std::max(
      e.bound,
      lows[e.node] + (narrowed ? narrow_bound[side_of] : cone_bound(y, axis, cones[e.node])));
  if (bound > threshold()) return;
  const BvhNode& node = tree.nodes[e.node];
  if (node.child >= 0) {
    for (const int c : {node.child, node.child + 1})
      push(std::max(bound, lows[c] + (narrowed ? narrow_bound[side_of]
                                               : cone_bound(y, own.r * cones[c].axis, cones[c]))),
           e.tree, c, at);
    return;
  }
  for (int i = node.begin; i < node.end; ++i) {
    if (faces)
      leaf_face(e.tree, tree.order[i], y, at);
    else
      leaf_arc(e.tree, tree.order[i], y);
  }
}

// A face of a leaf (or of the local enumeration), with the bound from the other's point y (the
// one that `at` names): measured unless the bound or the narrowing rules it out.
void Query::leaf_face(int tree, int item, const Vec3& y, int at) {
  const Side& own = side(tree);
  const GaussMap::Face& f = own.map->faces[item];
  if (!within.whole && f.normal.dot(within_local[tree % 2]) < within.cos_angle - 1e-12) return;
  // The same bound at the face's own normal, before its climb.
  if (f.offset + y.dot(own.r * f.normal) > threshold()) return;
  face(tree, item, at);
}

// An arc of a leaf (or of the local enumeration): kept for pairing unless its bound or the
// narrowing rules it out.
void Query::leaf_arc(int tree, int item, const Vec3& y) {
  const Side& own = side(tree);
  const GaussMap::Arc& arc = own.map->arcs[item];
  if (!within.whole && cones_apart(arc.cone.axis, arc.cone, within_local[tree % 2], within)) return;
  KeptArc k;
  const Vec3 arc_axis = own.r * arc.cone.axis;
  k.bound = arc.low + cone_bound(y, arc_axis, arc.cone);
  if (k.bound > threshold()) return;
  // For pairing, the arc on D's Gauss map (B's negated).
  const double s = sign(tree);
  k.axis = s * arc_axis;
  k.n0 = s * (own.r * arc.n0);
  k.n1 = s * (own.r * arc.n1);
  k.cone = &arc.cone;
  k.edge = arc.edge;
  arcs[tree - kArcsA].push_back(k);
}

// The narrowed search without the trees, for a narrow cone: every candidate whose direction lies
// in the cone has, on each shape, features supporting that direction, and every vertex that
// supports some direction u of the cone reaches u at least as far as the vertex supporting the
// cone's axis does. Those vertices are found by a walk over edges from that vertex (for each u
// they form the cap above a plane through it, connected, and every cap holds it); their faces
// and their edges to each other are then all the faces and arcs the cone can hold.
void Query::local_search() {
  for (int side_of = 0; side_of < 2; ++side_of) {
    const Side& own = side_of == 0 ? a : b;
    const GaussMap& g = *own.map;
    const std::vector<Vec3>& v = own.shape->vertices();
    const Vec3& u = within_local[side_of];
    const int start = narrow_at[side_of];
    // Round-off of the body-frame projections (coordinates of the shape's size).
    const double slack = 1e-12 * (1.0 + g.radius);
    auto reaches = [&](int w) {
      const Vec3 x = v[w] - v[start];
      // The furthest x . u' over the cone's directions u' is at least x . u (u is in the cone);
      // below that, it is along * cos + across * sin at the cone's edge nearest x (the cone is
      // narrow: x cannot lie inside it). Compared squared: no roots.
      const double along = x.dot(u);
      if (along >= -slack) return true;
      const double need = -slack - along * within.cos_angle;
      return need <= 0.0 ||
             x.cross(u).squaredNorm() * (within.sin_angle * within.sin_angle) >= need * need;
    };
    // A new mark for this side's search; on wrap-around, every old mark is cleared.
    if (++mark == 0) {
      std::fill(vertex_mark.begin(), vertex_mark.end(), 0u);
      std::fill(face_mark.begin(), face_mark.end(), 0u);
      mark = 1;
    }
    if (vertex_mark.size() < v.size()) vertex_mark.resize(v.size(), 0u);
    if (face_mark.size() < g.faces.size()) face_mark.resize(g.faces.size(), 0u);
    found.assign(1, start);
    vertex_mark[start] = mark;
    for (std::size_t k = 0; k < found.size(); ++k)
      for (int e = g.neighbor_start[found[k]]; e < g.neighbor_start[found[k] + 1]; ++e) {
        const int w = g.neighbors[e];
        if (vertex_mark[w] != mark && reaches(w)) {
          vertex_mark[w] = mark;
          found.push_back(w);
        }
      }
    const int face_tree = side_of == 0 ? kFacesA : kFacesB;
    const Vec3& y = narrow_y[side_of];
    const int at = narrow_at[1 - side_of];
    for (const int w : found) {
      for (int k = g.vertex_triangle_start[w]; k < g.vertex_triangle_start[w + 1]; ++k) {
        const int f = g.face_of_triangle[g.vertex_triangles[k]];
        if (face_mark[f] == mark) continue;
        face_mark[f] = mark;
        leaf_face(face_tree, f, y, at);
      }
      for (int e = g.neighbor_start[w]; e < g.neighbor_start[w + 1]; ++e) {
        const int o = g.neighbors[e], arc = g.neighbor_arcs[e];
        if (arc >= 0 && w < o && vertex_mark[o] == mark) leaf_arc(face_tree + 2, arc, y);
      }
    }
  }
}

// A face of one shape: pushing the other out of it along its normal n costs the face's height
// plus the other's support along -n (its lowest point along n).
void Query::face(int tree, int f, int at_other) {
  const Side& own = side(tree);
  const Side& other = side(tree + 1);
  const GaussMap::Face& face = own.map->faces[f];
  const Vec3 n = own.r * face.normal;
  Candidate c;
  c.overlap = (face.offset + n.dot(own.p)) + other.support(-n, at_other);
  if (c.overlap > threshold()) return;
  c.kind = 0;
  c.axis = canonical(n);
  // The other shape moves along n: the normal from B toward A is n when it is A, -n when B.
  c.normal = tree == kFacesA ? Vec3(-n) : n;
  c.source = tree == kFacesA ? PlaneAxis::FaceOfA : PlaneAxis::FaceOfB;
  keep(c);
}

// The edge-pair axes: each kept arc of A against each kept arc of B whose cones meet and whose
// arcs cross.
void Query::pair_arcs() {
  const double limit = threshold();
  for (const KeptArc& ka : arcs[0]) {
    if (ka.bound > limit) continue;
    for (const KeptArc& kb : arcs[1]) {
      if (kb.bound > limit) continue;
      if (cones_apart(ka.axis, *ka.cone, kb.axis, *kb.cone)) continue;
      if (!arcs_cross(ka.n0, ka.n1, kb.n0, kb.n1)) continue;
      edge_pair(ka, kb);
    }
  }
}

// Two edges whose arcs cross: their cross product is a face normal of D, on the side of the
// crossing (the side of either arc's midpoint).
void Query::edge_pair(const KeptArc& ka, const KeptArc& kb) {
  const Edge& ea = a.shape->edges()[ka.edge];
  const Edge& eb = b.shape->edges()[kb.edge];
  const Vec3 a0 = a.world(ea.a), b0 = b.world(eb.a);
  const Vec3 da = a.world(ea.b) - a0, db = b.world(eb.b) - b0;
  Vec3 d = da.cross(db);
  // Parallel edges (sine below 1e-9) give no axis of their own: a face normal covers them.
  if (!(d.squaredNorm() > 1e-18 * da.squaredNorm() * db.squaredNorm())) return;
  d.normalize();
  // The crossing's side: from the arc whose midpoint is further from the great circle of d's
  // plane (both agree unless an arc is a half circle); both sides when neither decides.
  const double on_a = d.dot(ka.n0 + ka.n1), on_b = d.dot(kb.n0 + kb.n1);
  const double side = std::abs(on_a) >= std::abs(on_b) ? on_a : on_b;
  // The pair's overlap when it is a face of D is the distance of the two edges' lines along its
  // normal, so a pair beyond the threshold is skipped before any climb.
  if (std::abs(side) > 1e-9 && (side > 0 ? 1.0 : -1.0) * d.dot(a0 - b0) > threshold()) return;
  Candidate c;
  c.kind = 1;
  c.axis = canonical(d);
  c.source = PlaneAxis::EdgeEdge;
  for (const double sgn : {1.0, -1.0}) {
    if (std::abs(side) > 1e-9 && sgn * side < 0) continue;
    const Vec3 u = sgn * d;
    if (outside(u)) continue;
    int at_a = ea.a, at_b = eb.a;
    const double overlap = a.support(u, at_a) + b.support(-u, at_b);
    if (overlap < c.overlap) {
      c.overlap = overlap;
      c.normal = -u;
    }
  }
  if (c.overlap <= threshold()) keep(c);
}

}  // namespace

// The search's lists: one query's state, kept by the caller's scratch between queries.
struct SearchLists {
  Query q;
};

void ListsDeleter::operator()(SearchLists* p) const { delete p; }

void search_candidates(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                       const Pose& pb, Candidates& out, Scratch& scratch) {
  if (!scratch.search) scratch.search.reset(new SearchLists);
  Query& q = scratch.search->q;
  q.a.set(a, pa);
  q.b.set(b, pb);
  q.upper = kInf;
  q.kept.clear();
  q.arcs[0].clear();
  q.arcs[1].clear();
  // Round-off of a projection difference is a few ulps of the largest coordinate; 1e-12 of it is
  // ~10^3 times that, far below any depth a tolerance in the harness distinguishes.
  const double scale = std::max(pa.position.cwiseAbs().maxCoeff() + q.a.map->radius,
                                pb.position.cwiseAbs().maxCoeff() + q.b.map->radius);
  q.tie = 1e-12 * scale;
  // The inner polytope narrows the directions and may lower the known overlap.
  q.within = DirectionCone{};
  if (out.polytope && inner_polytope_bound(q.a, q.b, q.tie, out, scratch)) {
    q.within = out.within;
    out.proved = true;
  } else if (out.proof_only) {
    return;
  }
  if (!q.within.whole) {
    // Each side's cone bound over `within` (on its own side: B's directions negated), from the
    // other's supporting vertex.
    q.narrow_at[0] = out.within_a;
    q.narrow_at[1] = out.within_b;
    q.narrow_y[0] = q.a.p - q.b.world(out.within_b);
    q.narrow_y[1] = q.b.p - q.a.world(out.within_a);
    q.narrow_bound[0] = cone_bound(q.narrow_y[0], q.within.axis, q.within);
    q.narrow_bound[1] = cone_bound(q.narrow_y[1], -q.within.axis, q.within);
    q.within_local[0] = q.a.rt * q.within.axis;
    q.within_local[1] = q.b.rt * -q.within.axis;
  }
  // A known overlap bounds the least from the start (one tie margin more, as in the scan).
  if (out.known < kInf) {
    q.upper = out.known + q.tie;
    q.upper_normal = out.known_normal;
  }
  // A narrow cone (the polytope converged) is enumerated from its supporting vertices; a wide
  // one searched in the trees.
  constexpr double kLocalCone = 1e-2;  // rad
  if (!q.within.whole && q.within.cos_angle >= std::cos(kLocalCone))
    q.local_search();
  else
    q.search();
  q.pair_arcs();
  out.kept.swap(q.kept);
  out.tie = q.tie;
  out.upper = q.upper;
  out.upper_normal = q.upper_normal;
}

}  // namespace rbx::plane_detail
