// The accelerated view (see the design note in engine/detect_accelerated.h).
#include "engine/detect_accelerated.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "engine/detect.h"

namespace rbx::detail {

namespace {

// Safety margin of every bound, relative to the query's coordinate scale (m): the exact and the
// bounding computations each carry a few ulps (~1e-16) of the coordinates; 1e-10 is far above
// both and still far below any distance that decides a test.
constexpr double kMarginScale = 1e-10;

// (p - q) . n, written out in the order Eigen's dot product of 3-vectors adds the terms,
// ((x + y) + z): bit-identical to the seed's Eigen expression (the equivalence test compares
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
__attribute__((always_inline)) inline double plane_distance(const AcceleratedView& y, int f,
                                                            const Vec3& p) {
  if (y.world_vertices)
    return plane_dist(p, y.world_vertices[y.shape->triangles()[f][0]], y.world_normals[f]);
  return plane_dist(p, y.vertex(y.shape->triangles()[f][0]), y.normal(f));
}

// Size (m) of a shape: the diagonal of its local bounding box.

// Places a shape: small shapes get world vertices in workspace slot `slot`; their world normals
// follow in place_normals.
AcceleratedView place(const ConvexPolyhedron& shape, const Pose& pose, const Limits& lim,
                      AcceleratedWorkspace& ws, int slot) {
  AcceleratedView p;
  p.shape = &shape;
  p.accel = shape.hierarchy();
  p.linear = p.accel && static_cast<int>(shape.vertices().size()) <= kLinearVertices;
  p.r = pose.rotation();
  p.rt = p.r.transpose();
  p.position = pose.position;
  p.tol = lim.tol;
  p.margin = lim.margin;
  if (p.accel) return p;
  std::vector<Vec3>& wv = ws.vertices[slot];
  // The seed's world copies, into reused buffers.
  wv.resize(shape.vertices().size());
  for (std::size_t i = 0; i < wv.size(); ++i) wv[i] = p.r * shape.vertices()[i] + pose.position;
  p.world_vertices = wv.data();
  p.distinct = shape.new_plane().data();
  return p;
}

// The world normals of a small placed shape, r n per triangle. Coplanar triangles (a box face
// is two) share their normal bit for bit; the same input gives the same product, so it is
// computed once.
void place_normals(AcceleratedView& p, AcceleratedWorkspace& ws, int slot) {
  const auto& planes = p.shape->planes();
  std::vector<Vec3>& wn = ws.normals[slot];
  wn.resize(planes.size());
  for (std::size_t f = 0; f < wn.size(); ++f)
    wn[f] = p.distinct[f] ? Vec3(p.r * planes[f].normal) : wn[f - 1];
  p.world_normals = wn.data();
}

// Two small shapes: true when every vertex of x lies beyond y's facing face plane by more than
// tol + margin (the rule of may_enter(); the normal r n is the one place_normals computes).
bool beyond_facing(const AcceleratedView& x, const AcceleratedView& y, const Limits& lim) {
  if (y.facing < 0) return false;
  const Vec3& q = y.world_vertices[y.shape->triangles()[y.facing][0]];
  const Vec3 n = y.r * y.shape->planes()[y.facing].normal;
  const double limit = lim.tol + lim.margin;
  const int nv = static_cast<int>(x.shape->vertices().size());
  for (int i = 0; i < nv; ++i)
    if (plane_dist(x.world_vertices[i], q, n) <= limit) return false;
  return true;
}

// The face of y whose outward normal is most along the direction from y's centre (of its
// bounding box) to x's: for shapes in contact, the face plane most likely to have x's points
// outside it. -1 when the centres coincide.
int facing_face(const AcceleratedView& y, const AcceleratedView& x) {
  const Vec3 cy = y.r * y.shape->bounds().center() + y.position;
  const Vec3 cx = x.r * x.shape->bounds().center() + x.position;
  const Vec3 d = cx - cy;
  if (!(d.norm() > 0.0)) return -1;
  const Vec3 dl = y.rt * d.normalized();
  const auto& pl = y.shape->planes();
  if (!y.accel) {
    // A face sharing the previous face's normal has its dot product and cannot beat it.
    int best = 0;
    double best_dot = pl[0].normal.dot(dl);
    for (int f = 1; f < y.num_triangles(); ++f) {
      if (!y.distinct[f]) continue;
      const double dot = pl[f].normal.dot(dl);
      if (dot > best_dot) {
        best_dot = dot;
        best = f;
      }
    }
    return best;
  }
  const ShapeHierarchy& acc = *y.accel;
  // Hill climbing over adjacent triangles, from the axis face nearest dl: a face none of whose
  // neighbours is more along dl. Deterministic, and any face would give the same answers (the
  // facing face only decides how much is culled and which face inside() tries first), so a
  // local best is enough; on a convex shape it is nearly always the global one.
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(dl[k]) > std::abs(dl[axis])) axis = k;
  int best = acc.axis_faces[2 * axis + (dl[axis] < 0.0 ? 1 : 0)];
  double best_dot = pl[best].normal.dot(dl);
  for (int step = 0; step < y.num_triangles(); ++step) {
    int next = -1;
    for (int g : acc.triangle_neighbors[best]) {
      if (g < 0) continue;  // (a validated closed mesh has all three)
      const double dot = pl[g].normal.dot(dl);
      if (dot > best_dot) {
        best_dot = dot;
        next = g;
      }
    }
    if (next < 0) break;
    best = next;
  }
  return best;
}

// False when no point of x can be inside y: x lies wholly outside one face plane of y (by
// more than tol + margin), tried on y's facing face, then on every distinct face plane of a
// small y or the axis faces of a larger one. Every point a test derives from x (a centroid, a
// vertex, a point on an edge) is a convex combination of x's vertices, so its plane distance
// exceeds the smallest of theirs less round-off, which the margin covers; x's vertices are
// tested one by one (small x) or through its bounding box (larger x).
bool may_enter(const AcceleratedView& x, const AcceleratedView& y, const Limits& lim) {
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
    const BvhNode& root = x.accel->vertices.nodes[0];
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

// Two small shapes: fills x's plane table against y (see AcceleratedView::plane_table) and
// decides whether x may enter y from it (the same rule as may_enter(), on every distinct plane
// of y).
void fill_plane_table(AcceleratedView& x, const AcceleratedView& y, const Limits& lim,
                      std::vector<double>& table) {
  const int nv = static_cast<int>(x.shape->vertices().size());
  const auto& tris = y.shape->triangles();
  const double limit = lim.tol + lim.margin;
  // Most pairs passing the bounding check are apart: x wholly beyond y's facing face plane
  // settles it (the rule of may_enter()) without the table.
  if (y.facing >= 0) {
    const Vec3& q = y.world_vertices[tris[y.facing][0]];
    const Vec3& n = y.world_normals[y.facing];
    bool separated = true;
    for (int i = 0; i < nv && separated; ++i)
      separated = plane_dist(x.world_vertices[i], q, n) > limit;
    if (separated) {
      x.plane_table = nullptr;
      x.table_planes = 0;
      x.enters = false;
      return;
    }
  }
  int planes[kSmallTriangles];
  int count = 0;
  for (int f = 0; f < y.num_triangles(); ++f)
    if (y.distinct[f]) planes[count++] = f;
  table.resize(static_cast<std::size_t>(nv) * count);
  bool separated[kSmallTriangles];
  for (int k = 0; k < count; ++k) separated[k] = true;
  for (int i = 0; i < nv; ++i)
    for (int k = 0; k < count; ++k) {
      const int f = planes[k];
      const double d =
          plane_dist(x.world_vertices[i], y.world_vertices[tris[f][0]], y.world_normals[f]);
      table[static_cast<std::size_t>(i) * count + k] = d;
      if (d <= limit) separated[k] = false;
    }
  x.plane_table = table.data();
  x.table_planes = count;
  x.enters = true;
  for (int k = 0; k < count; ++k)
    if (separated[k]) x.enters = false;
}

// The cull planes of y against x: y's facing face (first), and the faces most along y's body
// axes (for a box, its faces).
int cull_planes(const AcceleratedView& x, const AcceleratedView& y, CullPlane* planes) {
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
bool primitive_culled(const AcceleratedView& x, Primitive kind, int i, const CullPlane* planes,
                      int count) {
  if (kind == Primitive::Edges) {
    const Edge& e = x.shape->edges()[i];
    const Vec3 v_i = x.vertex(e.a), v_j = x.vertex(e.b);
    const double limit = x.tol + x.margin;
    for (int k = 0; k < count; ++k)
      if (planes[k].distance(v_i) > limit && planes[k].distance(v_j) > limit) return true;
    return false;
  }
  Vec3 p;
  if (kind == Primitive::Vertices) {
    p = x.vertex(i);
  } else {
    const auto& t = x.shape->triangles()[i];
    p = (x.vertex(t[0]) + x.vertex(t[1]) + x.vertex(t[2])) / 3.0;  // the seed's centroid
  }
  for (int k = 0; k < count; ++k)
    if (planes[k].distance(p) > x.tol) return true;
  return false;
}

// The plane-table culling of two small shapes (see AcceleratedView::candidates).
void table_candidates(const AcceleratedView& x, Primitive kind, int n, std::vector<int>& out) {
  const int m = x.table_planes;
  const double limit = x.tol + x.margin;
  auto row = [&](int v) { return x.plane_table + static_cast<std::size_t>(v) * m; };
  for (int i = 0; i < n; ++i) {
    bool out_of_y = false;
    if (kind == Primitive::Vertices) {
      const double* r = row(i);
      for (int k = 0; k < m && !out_of_y; ++k) out_of_y = r[k] > x.tol;
    } else if (kind == Primitive::Triangles) {
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
}

// Puts a list of indices below n in increasing order without repeats, through a bitmap: linear
// in the list plus n / 64 words, where a comparison sort of the thousands of primitives a deep
// cap holds took a large share of the query. The bitmap (the workspace's) is left cleared.
void sort_unique(std::vector<int>& list, std::size_t n, std::vector<std::uint64_t>& bits) {
  if (bits.size() < (n + 63) / 64) bits.assign((n + 63) / 64, 0);
  if (list.empty()) return;
  std::size_t lo = bits.size(), hi = 0;
  for (const int i : list) {
    const std::size_t w = static_cast<std::size_t>(i) / 64;
    bits[w] |= std::uint64_t{1} << (i % 64);
    lo = std::min(lo, w);
    hi = std::max(hi, w);
  }
  list.clear();
  for (std::size_t w = lo; w <= hi; ++w) {
    for (std::uint64_t b = bits[w]; b != 0; b &= b - 1)
      list.push_back(static_cast<int>(w * 64 + static_cast<std::size_t>(__builtin_ctzll(b))));
    bits[w] = 0;
  }
}

// x's cap against y's facing face plane (the first cull plane), for x with a hierarchy: every
// vertex whose plane distance may be within tol + margin, found without visiting the rest.
// The vertices of a convex polyhedron on one side of a plane are connected by its edges (from
// each, an edge path of non-increasing distance leads to the lowest vertex, as in the simplex
// method), so a search from one cap vertex over edges, through vertices below a slightly larger
// limit (tol + 4 margin: the body-frame distances carry round-off far below the margin),
// reaches them all. The first cap vertex comes from the vertex tree. Returns false when the cap
// is empty: then no point of x can be inside y.
bool find_cap(AcceleratedView& x, const Limits& lim, AcceleratedWorkspace& ws, int slot) {
  const CullPlane& plane = x.cull[0];
  const auto& verts = x.shape->vertices();
  const ShapeHierarchy& h = *x.accel;
  const double start_limit = lim.tol + 2.0 * lim.margin;
  const double limit = lim.tol + 4.0 * lim.margin;
  std::vector<int>& cap = ws.cap[slot];
  cap.clear();
  x.cap = &cap;
  x.bits = &ws.bits;
  if (x.linear) {
    // Few vertices: every one below the limit, by a scan.
    const int nv = static_cast<int>(verts.size());
    for (int i = 0; i < nv; ++i)
      if (plane.local_distance(verts[i]) <= limit) cap.push_back(i);
    return !cap.empty();
  }
  // A first vertex below start_limit: depth first, lower boxes first.
  int first = -1;
  const Bvh& tree = h.vertices;
  tree.search(
      [&](int k) {
        const BvhNode& node = tree.nodes[k];
        return plane.local_distance(node.center) - node.half.dot(plane.m_abs);
      },
      [&](double low) { return low > start_limit; },
      [&](int i) {
        if (plane.local_distance(verts[i]) > start_limit) return false;
        first = i;
        return true;
      },
      false);
  if (first < 0) return false;
  // Breadth first over edges; `seen` marks every vertex whose distance was computed.
  std::vector<unsigned>& seen = ws.seen[slot];
  if (seen.size() < verts.size() || ++ws.stamp[slot] == 0) {
    seen.assign(std::max(seen.size(), verts.size()), 0);
    ws.stamp[slot] = 1;
  }
  const unsigned stamp = ws.stamp[slot];
  seen[first] = stamp;
  cap.push_back(first);
  for (std::size_t k = 0; k < cap.size(); ++k) {
    const int v = cap[k];
    for (int j = h.edge_start[v]; j < h.edge_start[v + 1]; ++j) {
      const Edge& e = x.shape->edges()[h.vertex_edges[j]];
      const int w = e.a == v ? e.b : e.a;
      if (seen[w] == stamp) continue;
      seen[w] = stamp;
      if (plane.local_distance(verts[w]) <= limit) cap.push_back(w);
    }
  }
  sort_unique(cap, verts.size(), ws.bits);
  return true;
}

// True when a body-frame point of x is beyond one cull plane by more than `limit`.
bool local_culled(const AcceleratedView& x, const Vec3& c, double limit) {
  for (int k = 0; k < x.cull_count; ++k)
    if (x.cull[k].local_distance(c) > limit) return true;
  return false;
}

// Candidates from x's cap: its vertices, and the triangles and edges that have one, less those
// beyond a cull plane. Body-frame distances decide with the margin (a point beyond a plane by
// more than tol + margin in the body frame is beyond it by more than tol for the seed's
// expression); an edge needs both ends beyond one plane by tol + 2 margin.
void cap_candidates(const AcceleratedView& x, Primitive kind, std::vector<int>& out) {
  const ShapeHierarchy& h = *x.accel;
  const auto& verts = x.shape->vertices();
  const double limit = x.tol + x.margin;
  const std::vector<int>& cap = *x.cap;
  if (kind == Primitive::Vertices) {
    for (int v : cap)
      if (!local_culled(x, verts[v], limit)) out.push_back(v);
    return;
  }
  const bool triangles = kind == Primitive::Triangles;
  const std::vector<int>& start = triangles ? h.triangle_start : h.edge_start;
  const std::vector<int>& list = triangles ? h.vertex_triangles : h.vertex_edges;
  for (int v : cap) out.insert(out.end(), list.begin() + start[v], list.begin() + start[v + 1]);
  sort_unique(out, triangles ? x.shape->triangles().size() : x.shape->edges().size(), *x.bits);
  std::size_t kept = 0;
  for (int i : out) {
    bool culled_out;
    if (triangles) {
      const auto& t = x.shape->triangles()[i];
      culled_out = local_culled(x, (verts[t[0]] + verts[t[1]] + verts[t[2]]) / 3.0, limit);
    } else {
      const Edge& e = x.shape->edges()[i];
      culled_out = false;
      for (int k = 0; k < x.cull_count && !culled_out; ++k)
        culled_out = x.cull[k].local_distance(verts[e.a]) > limit + x.margin &&
                     x.cull[k].local_distance(verts[e.b]) > limit + x.margin;
    }
    if (!culled_out) out[kept++] = i;
  }
  out.resize(kept);
}

// Whether x may enter y (pairs with a hierarchy; x's cull planes set): a small x by
// may_enter(); an x with a hierarchy when its root box is not beyond a cull plane and its cap
// against y's facing face is not empty (find_cap, which also sets x.cap).
bool may_enter_with_cap(AcceleratedView& x, const AcceleratedView& y, const Limits& lim,
                        AcceleratedWorkspace& ws, int slot) {
  if (!x.accel) return may_enter(x, y, lim);
  const BvhNode& root = x.accel->vertices.nodes[0];
  if (culled(x.cull, x.cull_count, root.center, root.half, lim.tol + lim.margin)) return false;
  if (y.facing < 0) return true;  // no facing face: no cap, the trees cull
  return find_cap(x, lim, ws, slot);
}

}  // namespace

// Indices of x's primitives of `kind` that may lie (in part) inside y, in increasing order:
// from the plane table (two small shapes), by a loop (a small x), from the cap (cap_candidates),
// or, without a cap, from x's tree: every point a test derives from a primitive (a centroid, a
// vertex, a point on an edge) lies in the primitive's box, so a box outside one of y's cull
// planes holds no hit; the primitives of the remaining leaves are culled one by one
// (primitive_culled).
void AcceleratedView::candidates(Primitive kind, const AcceleratedView& /*y*/,
                                 std::vector<int>& out) const {
  const AcceleratedView& x = *this;
  out.clear();
  if (!x.accel) {
    const int n = kind == Primitive::Triangles  ? x.num_triangles()
                  : kind == Primitive::Vertices ? static_cast<int>(x.shape->vertices().size())
                                                : static_cast<int>(x.shape->edges().size());
    // Two small shapes: culled on the plane table. A vertex outside one plane by more than
    // tol is outside y for the seed's inside() (the table holds the seed's own value for that
    // face). Plane distances are affine along a triangle or an edge, so a centroid's is the
    // mean of its vertices' (to round-off), and the part of an edge within tol + margin of
    // every plane is an interval of its parameter clipped plane by plane (Cyrus-Beck); a
    // centroid beyond one plane by tol + margin, or an edge whose interval is empty, holds no
    // point inside y.
    if (x.plane_table) return table_candidates(x, kind, n, out);
    for (int i = 0; i < n; ++i)
      if (!primitive_culled(x, kind, i, x.cull, x.cull_count)) out.push_back(i);
    return;
  }
  if (x.cap) return cap_candidates(x, kind, out);
  const CullPlane* planes = x.cull;
  const int count = x.cull_count;
  const double limit = tol + margin;
  const Bvh& tree = kind == Primitive::Triangles  ? x.accel->triangles
                    : kind == Primitive::Vertices ? x.accel->vertices
                                                  : x.accel->edges;
  tree.search(
      [&](int k) {
        const BvhNode& node = tree.nodes[k];
        return culled(planes, count, node.center, node.half, limit) ? 1.0 : 0.0;
      },
      [](double cut) { return cut > 0.0; },
      [&](int i) {
        if (!primitive_culled(x, kind, i, planes, count)) out.push_back(i);
        return false;
      });
  std::sort(out.begin(), out.end());
}

// seed correction 1 (point in mesh uses p - q_f) point in mesh, the seed's predicate exactly: (p -
// q_f) . n_f <= tol for every face. Small shapes: the seed's loop. Others: faces (or, in the tree,
// clusters of faces) whose body-frame bound is at most tol - margin are certified, those beyond
// tol + margin are outside, and only the rest take the seed's expression; the first face found
// outside ends the search (the answer is an AND, so order does not matter).
bool AcceleratedView::inside(const Vec3& p) const {
  // The face toward the other shape first: most points of the other shape are outside it.
  if (facing >= 0 && plane_distance(*this, facing, p) > tol) return false;
  if (!accel) {
    // The seed's loop on the world copies.
    const auto& tris = shape->triangles();
    const Vec3* wv = world_vertices;
    const Vec3* wn = world_normals;
    const int n = num_triangles();
    for (int f = 0; f < n; ++f)
      if (plane_dist(p, wv[tris[f][0]], wn[f]) > tol) return false;
    return true;
  }
  const Vec3 pl = to_local(p);
  const double certified = tol - margin, outside = tol + margin;
  // Within the inscribed ball grown by `certified`: every face's body-frame plane distance is
  // at most `certified`, the rule the tree's leaves apply face by face.
  const double reach = accel->ball_radius + certified;
  if (reach > 0 && (pl - accel->ball_centre).squaredNorm() <= reach * reach) return true;
  const Bvh& tree = accel->triangles;
  if (linear) {
    const int n = num_triangles();
    for (int i = 0; i < n; ++i) {
      const LocalPlane& lp = accel->planes[i];
      const double s = dot3(pl, lp.n) - lp.d;
      if (s > certified && (s > outside || plane_distance(*this, tree.order[i], p) > tol))
        return false;
    }
    return true;
  }
  // Depth first over the triangle tree; a node whose bound is certified is skipped. In a leaf,
  // the body-frame plane distance decides whenever it is further than the margin from tol (it
  // is within round-off of the seed's value); only the rest take the seed's expression.
  int stack[128];
  int size = 0;
  stack[size++] = 0;
  while (size > 0) {
    const int k = stack[--size];
    double lo, hi;
    accel->plane_bounds(k, pl, lo, hi);
    if (hi <= certified) continue;
    // Every face of the cluster has p beyond it: outside, whichever face the seed's loop meets.
    if (lo > outside) return false;
    const BvhNode& node = tree.nodes[k];
    if (node.child >= 0) {
      // The child reaching further outside first: the answer is an AND, so order changes only
      // how soon a face with p outside is met.
      double lo0, hi0, lo1, hi1;
      accel->plane_bounds(node.child, pl, lo0, hi0);
      accel->plane_bounds(node.child + 1, pl, lo1, hi1);
      const bool first_is_0 = hi0 >= hi1;
      stack[size++] = first_is_0 ? node.child + 1 : node.child;
      stack[size++] = first_is_0 ? node.child : node.child + 1;
      continue;
    }
    for (int i = node.begin; i < node.end; ++i) {
      const LocalPlane& lp = accel->planes[i];
      const double s = dot3(pl, lp.n) - lp.d;
      if (s <= certified) continue;
      if (s > outside || plane_distance(*this, tree.order[i], p) > tol) return false;
    }
  }
  return true;
}

// max over the world vertices of v . n, the seed's expression. Branch and bound: a node's
// bound is the max of n . x over its box, in world terms.
double AcceleratedView::support_max(const Vec3& n) const {
  double best = -std::numeric_limits<double>::infinity();
  const int nv = static_cast<int>(shape->vertices().size());
  if (!accel) {
    for (int i = 0; i < nv; ++i) best = std::max(best, dot3(world_vertices[i], n));
    return best;
  }
  const Bvh& tree = accel->vertices;
  const Vec3 nl = rt * n;
  const double offset = position.dot(n);
  if (linear) {
    // The seed's value of every vertex whose body-frame value comes within 2 margins of the
    // largest so far: a superset of those that may reach the maximum.
    const auto& verts = shape->vertices();
    double top = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < nv; ++i) {
      const double value = dot3(verts[i], nl);
      if (value + 2.0 * margin < top) continue;
      top = std::max(top, value);
      best = std::max(best, vertex(i).dot(n));
    }
    return best;
  }
  tree.search(
      [&](int k) {
        const BvhNode& node = tree.nodes[k];
        return node.center.dot(nl) + node.half.dot(nl.cwiseAbs()) + offset;
      },
      [&](double b) { return b + margin < best; },
      [&](int i) {
        // The body-frame value decides when it is below the best by more than the margin.
        if (dot3(shape->vertices()[i], nl) + offset + margin < best) return false;
        best = std::max(best, vertex(i).dot(n));
        return false;
      });
  return best;
}

// min over the world vertices of v . n. Negating n negates every product and sum exactly, so
// this is exactly minus the max along -n.
double AcceleratedView::support_min(const Vec3& n) const { return -support_max(-n); }

// argmin over faces of |s_f(v)|, ties to the lowest index.
int AcceleratedView::closest_face(const Vec3& v) const {
  int closest = 0;
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](int f) {
    const double d = std::abs(plane_distance(*this, f, v));
    if (d < best || (d == best && f < closest)) {
      best = d;
      closest = f;
    }
    return false;
  };
  if (!accel) {
    for (int f = 0; f < num_triangles(); ++f) consider(f);
    return closest;
  }
  const Vec3 vl = to_local(v);
  if (linear) {
    for (int i = 0; i < num_triangles(); ++i) {
      const LocalPlane& lp = accel->planes[i];
      if (std::abs(dot3(vl, lp.n) - lp.d) - margin <= best) consider(accel->triangles.order[i]);
    }
    return closest;
  }
  // Lower bound of |s_f| over a node from the bounds on s_f; nearer clusters first. In a leaf,
  // the body-frame distance skips a face that is further than the best by the margin.
  accel->triangles.search_slots(
      [&](int k) {
        double lo, hi;
        accel->plane_bounds(k, vl, lo, hi);
        return lo > 0.0 ? lo : (hi < 0.0 ? -hi : 0.0);
      },
      [&](double b) { return b - margin > best; },  // cannot reach (or tie) the best
      [&](int slot) {
        const LocalPlane& lp = accel->planes[slot];
        if (std::abs(dot3(vl, lp.n) - lp.d) - margin > best) return false;
        return consider(accel->triangles.order[slot]);
      },
      false);
  return closest;
}

// The seed's crossings of the segment [v_i, v_j] with the planes of the triangles, in face
// order. Clusters whose two ends are certainly on the same side of every plane are skipped.
void AcceleratedView::crossings(const Vec3& v_i, const Vec3& v_j,
                                std::vector<Crossing>& out) const {
  out.clear();
  if (!accel) {
    for (int f = 0; f < num_triangles(); ++f) crossing_of(*this, f, v_i, v_j, out);
    return;
  }
  const Vec3 pi = to_local(v_i), pj = to_local(v_j);
  // Both ends on one side by more than the margin in the body frame: no crossing.
  auto may_cross = [&](int slot) {
    const LocalPlane& lp = accel->planes[slot];
    const double s_i = dot3(pi, lp.n) - lp.d, s_j = dot3(pj, lp.n) - lp.d;
    return !((s_i > margin && s_j > margin) || (s_i < -margin && s_j < -margin));
  };
  if (linear) {
    for (int i = 0; i < num_triangles(); ++i)
      if (may_cross(i)) crossing_of(*this, accel->triangles.order[i], v_i, v_j, out);
  } else {
    accel->triangles.search_slots(
        [&](int k) {
          double lo_i, hi_i, lo_j, hi_j;
          accel->plane_bounds(k, pi, lo_i, hi_i);
          accel->plane_bounds(k, pj, lo_j, hi_j);
          // Both ends strictly inside every plane of the cluster, or both strictly outside.
          const bool same_side = (hi_i + margin < 0.0 && hi_j + margin < 0.0) ||
                                 (lo_i - margin > 0.0 && lo_j - margin > 0.0);
          return same_side ? 1.0 : 0.0;
        },
        [](double same_side) { return same_side > 0.0; },
        [&](int slot) {
          if (may_cross(slot)) crossing_of(*this, accel->triangles.order[slot], v_i, v_j, out);
          return false;
        });
  }
  std::sort(out.begin(), out.end(),
            [](const Crossing& x, const Crossing& z) { return x.face < z.face; });
}

// argmin of triangle_distance, ties to the lowest index. Branch and bound on the distance to
// node boxes, nearer first.
int AcceleratedView::nearest_triangle(const Vec3& p) const {
  int face = -1;
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](int f) {
    const double d = triangle_distance(*this, f, p);
    if (face < 0 || d < best || (d == best && f < face)) {
      best = d;
      face = f;
    }
    return false;
  };
  if (!accel) {
    for (int f = 0; f < num_triangles(); ++f) consider(f);
    return face;
  }
  const Vec3 pl = to_local(p);
  accel->triangles.search(
      [&](int k) {
        const BvhNode& node = accel->triangles.nodes[k];
        return ((pl - node.center).cwiseAbs() - node.half).cwiseMax(0.0).norm();
      },
      [&](double b) { return b - margin > best; }, consider, false);
  return face;
}

// True when one face plane of this shape has both ends of the segment [v_i, v_j] beyond
// tol + margin: then no point of the segment is inside, and the edge can have no hit whatever
// its plane crossings. Two small shapes: always false (x's plane table already culled the edge).
bool AcceleratedView::segment_outside(const AcceleratedView& x, const Vec3& v_i,
                                      const Vec3& v_j) const {
  if (x.plane_table) return false;
  const double limit = tol + margin;
  if (facing >= 0 && plane_distance(*this, facing, v_i) > limit &&
      plane_distance(*this, facing, v_j) > limit)
    return true;
  if (!accel) {
    // Small shapes: every distinct face plane (coplanar triangles share one).
    for (int f = 0; f < num_triangles(); ++f)
      if (distinct[f] && f != facing && plane_distance(*this, f, v_i) > limit &&
          plane_distance(*this, f, v_j) > limit)
        return true;
    return false;
  }
  const Vec3 pi = to_local(v_i), pj = to_local(v_j);
  // Both ends beyond one face plane by more than the limit; the body-frame distances decide
  // unless one is within the margin of the limit.
  auto beyond = [&](int slot) {
    const LocalPlane& lp = accel->planes[slot];
    const double s_i = dot3(pi, lp.n) - lp.d, s_j = dot3(pj, lp.n) - lp.d;
    if (s_i <= limit - margin || s_j <= limit - margin) return false;
    if (s_i > limit + margin && s_j > limit + margin) return true;
    const int f = accel->triangles.order[slot];
    return plane_distance(*this, f, v_i) > limit && plane_distance(*this, f, v_j) > limit;
  };
  if (linear) {
    for (int i = 0; i < num_triangles(); ++i)
      if (beyond(i)) return true;
    return false;
  }
  // Upper bound on min(s_f(v_i), s_f(v_j)) over a cluster; clusters far outside first.
  return accel->triangles.search_slots(
      [&](int k) {
        double lo, hi_i, hi_j;
        accel->plane_bounds(k, pi, lo, hi_i);
        accel->plane_bounds(k, pj, lo, hi_j);
        return std::min(hi_i, hi_j);
      },
      [&](double b) { return b <= limit; }, beyond);
}

void AcceleratedPair::prepare(const ConvexPolyhedron& sa, const Pose& pa,
                              const ConvexPolyhedron& sb, const Pose& pb,
                              AcceleratedWorkspace& ws) {
  // The query's constants: the seed's tolerance, and the margin scaled by the coordinates.
  Limits lim;
  lim.tol = point_in_mesh_tolerance(sa, sb);
  const double scale =
      pa.position.norm() + pb.position.norm() + 2.0 * shape_size(sa) + 2.0 * shape_size(sb);
  lim.margin = kMarginScale * scale;
  a = place(sa, pa, lim, ws, 0);
  b = place(sb, pb, lim, ws, 1);
  // Each shape's facing face, and whether its points can enter the other.
  a.facing = facing_face(a, b);
  b.facing = facing_face(b, a);
  // Two small shapes apart across a facing face plane each way: every test returns at
  // may_enter(), so neither the world normals nor the plane tables are needed.
  if (!a.accel && !b.accel && beyond_facing(a, b, lim) && beyond_facing(b, a, lim)) {
    a.enters = false;
    b.enters = false;
    return;
  }
  if (!a.accel) place_normals(a, ws, 0);
  if (!b.accel) place_normals(b, ws, 1);
  if (!a.accel && !b.accel) {
    fill_plane_table(a, b, lim, ws.tables[0]);
    fill_plane_table(b, a, lim, ws.tables[1]);
    return;
  }
  // Each shape's cull planes against the other, once for the three tests; then whether its
  // points can enter the other, and its cap.
  a.cull_count = cull_planes(a, b, ws.cull[0]);
  a.cull = ws.cull[0];
  b.cull_count = cull_planes(b, a, ws.cull[1]);
  b.cull = ws.cull[1];
  a.enters = may_enter_with_cap(a, b, lim, ws, 0);
  b.enters = may_enter_with_cap(b, a, lim, ws, 1);
}

std::optional<ContactPoint> AcceleratedPair::test(Feature feature, FeatureScratch& scratch) const {
  return both_orders(feature, a, b, scratch);
}

std::optional<ContactPoint> AcceleratedPair::detect(FeatureScratch& scratch) const {
  return all_features(a, b, scratch);
}

}  // namespace rbx::detail
