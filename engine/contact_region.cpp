// The centre of the contact region on a chosen plane (engine/contact_region.h).
#include "engine/contact_region.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/contact_plane_detail.h"
#include "engine/detect.h"

namespace rbx {

namespace {

using Vec2 = Eigen::Vector2d;

// Incident faces whose normals' dot products with the reference normal differ by less than this
// are equally against it: round-off of unit normals of order-1 coordinates is ~1e-16, and a
// real difference of 1e-10 is a tilt of 1e-5 rad.
constexpr double kTieCosine = 1e-10;

// The vertices of a placed shape within `eps` of its furthest along d (world), by index, in the
// order found: the climb's vertex (from `start` or the map's start vertex for d, the higher), then
// every vertex reached over edges without dropping below that height (the vertices above a plane
// of a convex polyhedron are connected by its edges).
void extreme_indices(const plane_detail::Side& s, const Vec3& d, double eps,
                     std::vector<int>& found, int start = -1) {
  const Vec3 local = s.rt * d;
  const GaussMap& g = *s.map;
  const std::vector<Vec3>& v = s.shape->vertices();
  double h = 0.0;  // in the body frame
  found.assign(1, g.climb(v, local, g.better_start(v, local, start), h));
  for (std::size_t k = 0; k < found.size(); ++k)
    for (int e = g.neighbor_start[found[k]]; e < g.neighbor_start[found[k] + 1]; ++e) {
      const int o = g.neighbors[e];
      if (v[o].dot(local) >= h - eps && std::find(found.begin(), found.end(), o) == found.end())
        found.push_back(o);
    }
}

// The same vertices, placed in the world (`found`: the indices' list, reused).
void extreme_feature(const plane_detail::Side& s, const Vec3& d, double eps, std::vector<Vec3>& out,
                     std::vector<int>& found, int start = -1) {
  extreme_indices(s, d, eps, found, start);
  out.clear();
  for (const int i : found) out.push_back(s.world(i));
}

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

bool lex_less(const Vec2& p, const Vec2& q) {
  return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
}

// The convex hull of points on the plane, in place, counter-clockwise (Andrew's monotone chain):
// one point, two (a segment) or a polygon without collinear corners. The lists of this file are
// the caller's scratch (one query allocates nothing once they have grown); `h` is the chain's.
void hull2(std::vector<Vec2>& p, std::vector<Vec2>& h) {
  std::sort(p.begin(), p.end(), lex_less);
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return;
  h.resize(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross2(h[k - 1] - h[k - 2], p[i] - h[k - 2]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(h[k - 1] - h[k - 2], p[i] - h[k - 2]) <= 0) --k;
    h[k++] = p[i];
  }
  p.assign(h.begin(), h.begin() + static_cast<std::ptrdiff_t>(k - 1));
}

// Sutherland-Hodgman on one half-plane: the part of `poly` (a polygon, a segment or a point)
// where f(x) = w . x - c <= tol, for |w| = 1 (so that f is a distance), into `out`.
void clip_half(const std::vector<Vec2>& poly, const Vec2& w, double c, double tol,
               std::vector<Vec2>& out) {
  out.clear();
  for (std::size_t j = 0; j < poly.size(); ++j) {
    const Vec2 &x = poly[j], &y = poly[(j + 1) % poly.size()];
    const double fx = w.dot(x) - c, fy = w.dot(y) - c;
    if (fx <= tol) out.push_back(x);
    if (poly.size() > 1 && ((fx <= tol) != (fy <= tol)))
      out.push_back(x + (y - x) * (fx / (fx - fy)));
  }
}

// `poly` cut, in place, to its part inside every edge of the counter-clockwise convex polygon
// `clip`; `cut` holds each half-plane's result.
void clip_by(std::vector<Vec2>& poly, const std::vector<Vec2>& clip, double tol,
             std::vector<Vec2>& cut) {
  for (std::size_t i = 0; i < clip.size() && !poly.empty(); ++i) {
    const Vec2 e = clip[(i + 1) % clip.size()] - clip[i];
    // The edge's outward normal (the polygon lies to the left of each edge).
    const Vec2 w = Vec2(e.y(), -e.x()).normalized();
    clip_half(poly, w, w.dot(clip[i]), tol, cut);
    poly.swap(cut);
  }
}

// The midpoint of the closest points of two segments (or points) on the plane; for parallel
// overlapping segments, the middle of their overlap.
Vec2 segments_meet(const std::vector<Vec2>& s, const std::vector<Vec2>& t) {
  const Vec2 p = s[0], q = t[0];
  const Vec2 d1 = s.size() > 1 ? Vec2(s[1] - s[0]) : Vec2::Zero();
  const Vec2 d2 = t.size() > 1 ? Vec2(t[1] - t[0]) : Vec2::Zero();
  const double a = d1.squaredNorm(), e = d2.squaredNorm();
  const Vec2 r = p - q;
  double u = 0.0, v = 0.0;
  if (a > 0 && e > 0 && std::abs(cross2(d1, d2)) > 1e-12 * std::sqrt(a * e)) {
    // Crossing lines: the intersection, clamped to both segments.
    u = std::clamp(cross2(q - p, d2) / cross2(d1, d2), 0.0, 1.0);
    v = std::clamp((p + u * d1 - q).dot(d2) / e, 0.0, 1.0);
    u = std::clamp((q + v * d2 - p).dot(d1) / a, 0.0, 1.0);
  } else if (a > 0 && e > 0) {
    // Parallel: the middle of the overlap of their projections on s.
    const double lo = std::max(0.0, std::min((q - p).dot(d1), (q + d2 - p).dot(d1)) / a);
    const double hi = std::min(1.0, std::max((q - p).dot(d1), (q + d2 - p).dot(d1)) / a);
    u = lo <= hi ? 0.5 * (lo + hi) : (hi < 0.0 ? 0.0 : 1.0);
    v = std::clamp((p + u * d1 - q).dot(d2) / e, 0.0, 1.0);
  } else if (a > 0) {
    u = std::clamp(-r.dot(d1) / a, 0.0, 1.0);
  } else if (e > 0) {
    v = std::clamp(r.dot(d2) / e, 0.0, 1.0);
  }
  return 0.5 * ((p + u * d1) + (q + v * d2));
}

// The centroid of a polygon, segment or point on the plane: by area when it has one, else the
// middle of its two furthest points.
Vec2 centroid2(const std::vector<Vec2>& p, double tol) {
  if (p.size() >= 3) {
    double area = 0.0;
    Vec2 c = Vec2::Zero();
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Vec2 &x = p[i], &y = p[(i + 1) % p.size()];
      const double w = cross2(x - p[0], y - p[0]);
      area += w;
      c += w * (x + y - 2.0 * p[0]);
    }
    if (std::abs(area) > tol * tol) return p[0] + c / (3.0 * area);
  }
  Vec2 x = p[0], y = p[0];
  double best = -1.0;
  for (const Vec2& s : p)
    for (const Vec2& t : p)
      if ((s - t).squaredNorm() > best) {
        best = (s - t).squaredNorm();
        x = s;
        y = t;
      }
  return 0.5 * (x + y);
}

// One side's feature on the plane: its hull and its mean height along the axis.
struct Projected {
  std::vector<Vec2> hull;
  double height = 0.0;
  int vertices = 0;
};

// `h` (the heights) and `chain` (hull2's) are the caller's lists.
void project(const std::vector<Vec3>& feature, const Vec3& t1, const Vec3& t2, const Vec3& axis,
             Projected& out, std::vector<double>& h, std::vector<Vec2>& chain) {
  out.hull.clear();
  out.height = 0.0;
  h.clear();
  for (const Vec3& x : feature) {
    out.hull.emplace_back(x.dot(t1), x.dot(t2));
    h.push_back(x.dot(axis));
  }
  // The heights summed in a fixed order (sorted), so that the mean does not depend on the order
  // the climb found the vertices.
  std::sort(h.begin(), h.end());
  for (const double z : h) out.height += z;
  out.height /= static_cast<double>(h.size());
  out.vertices = static_cast<int>(feature.size());
  hull2(out.hull, chain);
}

// A geometric order of the two features (never the argument slot): the one with more hull
// corners first, then the lexicographically smaller hull.
bool before(const Projected& x, const Projected& y) {
  if (x.hull.size() != y.hull.size()) return x.hull.size() > y.hull.size();
  return std::lexicographical_compare(x.hull.begin(), x.hull.end(), y.hull.begin(), y.hull.end(),
                                      lex_less);
}

}  // namespace

// The contact region's lists, kept by the caller's scratch between queries: each helper's own
// (no two live at once share one).
struct plane_detail::RegionLists {
  std::vector<int> found, deepest, shared, face;  // vertex indices
  std::vector<Vec3> ref_pts, inc_pts;             // the two features' vertices, world
  Projected ref, inc;                             // the two features on the plane
  std::vector<Vec2> region, kept;                 // their overlap, its corners kept
  std::vector<Vec2> chain, cut;                   // hull2's chain, clip_by's half-plane cut
  std::vector<double> heights;                    // project's
};

void plane_detail::ListsDeleter::operator()(RegionLists* p) const { delete p; }

namespace {

using plane_detail::RegionLists;

// A frame of the plane with unit normal `axis`: two unit vectors across it, a function of the
// axis alone.
void plane_frame(const Vec3& axis, Vec3& t1, Vec3& t2) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(axis[i]) < std::abs(axis[k])) k = i;
  t1 = axis.cross(Vec3::Unit(k)).normalized();
  t2 = axis.cross(t1);
}

// An edge-pair axis: each shape's feature along the normal (an edge, to round-off), projected,
// and the midpoint of their closest points, midway between them along the normal.
Vec3 edge_pair_centre(const plane_detail::Side& sa, const plane_detail::Side& sb,
                      const ContactPlane& plane, double eps, RegionLists& w) {
  const Vec3& n = plane.normal;
  std::vector<Vec3>&fa = w.ref_pts, &fb = w.inc_pts;
  extreme_feature(sa, -n, eps, fa, w.found, plane.vertex_a);
  extreme_feature(sb, n, eps, fb, w.found, plane.vertex_b);
  // The frame of the sign-free axis, and the two features in an order of the geometry: the
  // same numbers in either body order.
  const Vec3 axis = plane_detail::canonical(n);
  Vec3 t1, t2;
  plane_frame(axis, t1, t2);
  Projected &pa = w.ref, &pb = w.inc;
  project(fa, t1, t2, axis, pa, w.heights, w.chain);
  project(fb, t1, t2, axis, pb, w.heights, w.chain);
  const Projected& ref = before(pa, pb) ? pa : pb;
  const Projected& inc = &ref == &pa ? pb : pa;
  Vec2 centre;
  if (ref.hull.size() >= 3) {
    // Parallel faces within round-off of the axis: their overlap.
    w.region = inc.hull;
    clip_by(w.region, ref.hull, eps, w.cut);
    centre = centroid2(w.region.empty() ? inc.hull : w.region, eps);
  } else {
    centre = segments_meet(ref.hull, inc.hull);
  }
  return centre.x() * t1 + centre.y() * t2 + (0.5 * (ref.height + inc.height)) * axis;
}

// The incident feature of a face contact: the face of shape `is` most against the reference
// normal m (world) among the faces around its deepest vertex along -m; several within round-off
// of that (kTieCosine) give the feature they share instead (an edge, or the vertex), so that no
// choice among equals is made. Its vertices go to `pts`.
struct Incident {
  Vec3 normal = Vec3::Zero();  // world, the (first) incident face's outward normal
  double offset = 0.0;         // m, that face's plane: normal . x = offset
  bool single = false;         // one deepest vertex (a vertex contact)
  int deep = -1;               // the deepest vertex (the first by index of several)
};
Incident incident_feature(const plane_detail::Side& is, const Vec3& m, double eps, int hint,
                          std::vector<Vec3>& pts, RegionLists& w) {
  const GaussMap& gi = *is.map;
  // The deepest vertex: of several within the tolerance, the first by index (not the climb's,
  // which depends on where it started).
  std::vector<int>& deepest = w.deepest;
  extreme_indices(is, -m, eps, deepest, hint);
  const int deep = *std::min_element(deepest.begin(), deepest.end());
  const Vec3 m_local = is.rt * m;
  const auto& planes = is.shape->planes();
  double most = plane_detail::kInf;
  for (int k = gi.vertex_triangle_start[deep]; k < gi.vertex_triangle_start[deep + 1]; ++k)
    most = std::min(most, planes[gi.vertex_triangles[k]].normal.dot(m_local));
  std::vector<int>&shared = w.shared, &face = w.face;
  shared.clear();
  Incident out;
  out.single = deepest.size() == 1;
  out.deep = deep;
  for (int k = gi.vertex_triangle_start[deep]; k < gi.vertex_triangle_start[deep + 1]; ++k) {
    const Plane& pl = planes[gi.vertex_triangles[k]];
    if (pl.normal.dot(m_local) > most + kTieCosine) continue;
    const Vec3 nw = is.r * pl.normal;
    if (nw == out.normal) continue;  // a coplanar triangle of a face already taken
    extreme_indices(is, nw, eps, face, deep);
    if (out.normal == Vec3::Zero()) {
      shared = face;
      out.normal = nw;
      out.offset = pl.offset + nw.dot(is.p);
      continue;
    }
    shared.erase(
        std::remove_if(shared.begin(), shared.end(),
                       [&](int v) { return std::find(face.begin(), face.end(), v) == face.end(); }),
        shared.end());
  }
  pts.clear();
  for (const int v : shared) pts.push_back(is.world(v));
  return out;
}

}  // namespace

Vec3 contact_region_centre(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                           const Pose& pb, const ContactPlane& plane, std::string& feature,
                           ContactScratch& scratch, std::vector<ManifoldPoint>* patch) {
  plane_detail::Scratch& lists = scratch.lists();
  if (!lists.region) lists.region.reset(new RegionLists);
  RegionLists& w = *lists.region;
  plane_detail::Side sa, sb;
  sa.set(a, pa);
  sb.set(b, pb);
  const Vec3& n = plane.normal;
  // The features within the engine's point-in-mesh tolerance of each extreme: a face's vertices
  // lie within round-off of its plane, far inside it.
  const double eps = point_in_mesh_tolerance(a, b);
  if (plane.axis == PlaneAxis::EdgeEdge) {
    feature = "edge";
    const Vec3 c = edge_pair_centre(sa, sb, plane, eps, w);
    // The patch of an edge pair is its one point (as the oracle's).
    if (patch) patch->assign(1, {c, plane.depth});
    return c;
  }

  // A face axis: the reference face (the face whose normal is the axis, outward m) and the
  // incident face, the other shape's face most against m among those at its deepest vertex.
  const bool ref_b = plane.axis == PlaneAxis::FaceOfB;
  const plane_detail::Side& rs = ref_b ? sb : sa;
  const plane_detail::Side& is = ref_b ? sa : sb;
  const Vec3 m = ref_b ? n : Vec3(-n);
  std::vector<Vec3>&ref_pts = w.ref_pts, &inc_pts = w.inc_pts;
  extreme_feature(rs, m, eps, ref_pts, w.found, ref_b ? plane.vertex_b : plane.vertex_a);
  const Incident inc_face =
      incident_feature(is, m, eps, ref_b ? plane.vertex_a : plane.vertex_b, inc_pts, w);
  const Vec3& inc_n = inc_face.normal;
  const double inc_offset = inc_face.offset;
  // A single deepest vertex is a vertex contact.
  feature = inc_face.single ? "vertex" : "face";

  // The frame of the sign-free axis (so that parallel faces, below, get the same numbers in
  // either body order); `up` is m in it.
  const Vec3 axis = plane_detail::canonical(m);
  const double up = axis == m ? 1.0 : -1.0;
  Vec3 t1, t2;
  plane_frame(axis, t1, t2);
  Projected &ref = w.ref, &inc = w.inc;
  project(ref_pts, t1, t2, axis, ref, w.heights, w.chain);
  project(inc_pts, t1, t2, axis, inc, w.heights, w.chain);
  // Heights along m: the reference plane's, and the incident face's over the plane's point
  // (u, v), on its plane inc_n . x = inc_offset.
  const double ref_height = up * ref.height;
  const double a0 = inc_offset / inc_n.dot(m), au = -inc_n.dot(t1) / inc_n.dot(m),
               av = -inc_n.dot(t2) / inc_n.dot(m);
  auto inc_height = [&](const Vec2& p) { return a0 + au * p.x() + av * p.y(); };
  auto place = [&](const Vec2& p, double height) {
    return Vec3(p.x() * t1 + p.y() * t2 + height * m);
  };
  // The patch: each corner midway between the two surfaces, as deep as they are apart there.
  auto write_patch = [&](const std::vector<Vec2>& corners) {
    if (!patch) return;
    patch->clear();
    for (const Vec2& p : corners)
      patch->push_back({place(p, 0.5 * (inc_height(p) + ref_height)),
                        std::min(std::max(ref_height - inc_height(p), 0.0), plane.depth)});
  };
  // Parallel faces (the incident one within round-off of against m): the plane's keys may have
  // taken either as the reference, so the two are ordered by the geometry instead, and the
  // patch is their overlap, each corner as deep as the two faces' planes are apart there.
  std::vector<Vec2>&region = w.region, &kept = w.kept;
  if (1.0 + inc_n.dot(m) <= 1e-12) {
    const bool ref_first = !before(inc, ref);
    const Projected& x = ref_first ? ref : inc;
    const Projected& y = ref_first ? inc : ref;
    region = y.hull;
    clip_by(region, x.hull, eps, w.cut);
    write_patch(region);
    const Vec2 c = centroid2(region.empty() ? y.hull : region, eps);
    if (patch && patch->empty())
      patch->push_back({place(c, 0.5 * up * (x.height + y.height)), plane.depth});
    return c.x() * t1 + c.y() * t2 + (0.5 * (x.height + y.height)) * axis;
  }
  // The incident feature clipped to the reference face's sides, and of its corners those at or
  // below the reference plane (the manifold's points, as Box2D keeps them). None there, all
  // above it by a gap (touching within the detector's tolerance): the lowest, to `eps`. None
  // at all: the deepest vertex. The centre is their centroid, midway between the incident
  // surface and the reference plane.
  region = inc.hull;
  clip_by(region, ref.hull, eps, w.cut);
  double lowest = plane_detail::kInf;
  for (const Vec2& p : region) lowest = std::min(lowest, inc_height(p) - ref_height);
  const double keep_below = std::max(lowest, 0.0) + eps;
  kept.clear();
  for (const Vec2& p : region)
    if (inc_height(p) - ref_height <= keep_below) kept.push_back(p);
  if (kept.empty()) {
    const Vec3 x = is.world(inc_face.deep);
    kept.emplace_back(x.dot(t1), x.dot(t2));
  }
  write_patch(kept);
  hull2(kept, w.chain);
  const Vec2 c = centroid2(kept, eps);
  return place(c, 0.5 * (inc_height(c) + ref_height));
}

std::optional<ContactPoint> find_contact(const ConvexPolyhedron& a, const Pose& pa,
                                         const ConvexPolyhedron& b, const Pose& pb,
                                         Detector detector, DetectionCache& cache,
                                         ContactScratch& scratch,
                                         std::vector<ManifoldPoint>* patch) {
  // 1. The features in contact and 2. the chosen plane: proved to overlap, or found by the
  // detector and the plane chosen for its hit.
  if (const auto plane = choose_overlap_plane(a, pa, b, pb, scratch)) {
    ContactPoint c;
    c.normal = plane->normal;
    c.depth = plane->depth;
    // 3. The patch clipped on the plane, with its centre.
    c.point = contact_region_centre(a, pa, b, pb, *plane, c.feature, scratch, patch);
    return c;
  }
  auto c = detect(a, pa, b, pb, detector, cache);
  if (!c) return c;
  const ContactPlane plane =
      choose_contact_plane(a, pa, b, pb, c->normal, c->depth, PlaneMethod::Automatic, scratch);
  c->normal = plane.normal;
  c->depth = plane.depth;
  if (patch) {
    std::string feature;
    contact_region_centre(a, pa, b, pb, plane, feature, scratch, patch);
  }
  return c;
}

}  // namespace rbx
