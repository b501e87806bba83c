#include "engine/manifold.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "engine/contact_plane.h"
#include "engine/contact_plane_detail.h"
#include "engine/contact_region.h"

namespace rbx {

namespace {

// Size of a shape (m): the diagonal of its bounds.

// The edges of the solid: an edge whose two triangles are not coplanar. Triangulation diagonals
// of a flat face are skipped (their crossings lie inside a face contact and add nothing).
std::vector<Edge> feature_edges(const ConvexPolyhedron& s) {
  std::map<std::pair<int, int>, std::vector<int>> faces_of;
  const auto& tris = s.triangles();
  for (int f = 0; f < static_cast<int>(tris.size()); ++f)
    for (int k = 0; k < 3; ++k) {
      const int u = tris[f][k], v = tris[f][(k + 1) % 3];
      faces_of[{std::min(u, v), std::max(u, v)}].push_back(f);
    }
  std::vector<Edge> out;
  for (const Edge& e : s.edges()) {
    const auto& fs = faces_of[{e.a, e.b}];
    // 1 - cos(angle) below 1e-12: the same plane to the validation's convexity tolerance.
    if (fs.size() == 2 && s.planes()[fs[0]].normal.dot(s.planes()[fs[1]].normal) > 1.0 - 1e-12)
      continue;
    out.push_back(e);
  }
  return out;
}

// Closest points of segments p0 + s d0 and q0 + t d1 (s, t in [0, 1]); false when the segments
// are parallel to 1e-9 rad or the closest points are not interior to both (a crossing at an
// end is a vertex, found by the vertex tests).
bool crossing(const Vec3& p0, const Vec3& d0, const Vec3& q0, const Vec3& d1, Vec3& c0, Vec3& c1) {
  const double a = d0.dot(d0), c = d1.dot(d1), b = d0.dot(d1);
  const double denom = a * c - b * b;  // |d0 x d1|^2
  if (!(denom > 1e-18 * a * c)) return false;
  const Vec3 r = p0 - q0;
  const double d = d0.dot(r), e = d1.dot(r);
  const double s = (b * e - c * d) / denom, t = (a * e - b * d) / denom;
  // 1e-9 of the segment: the end of a segment is the vertex's business.
  if (!(s > 1e-9 && s < 1.0 - 1e-9 && t > 1e-9 && t < 1.0 - 1e-9)) return false;
  c0 = p0 + s * d0;
  c1 = q0 + t * d1;
  return true;
}

// The deepest of the points, by a key of the geometry: of the points within round-off of the
// greatest depth (1e-12 of the largest coordinate: the depths are differences of projections),
// the one last by position. Several points are often equally deep (A's lowest vertex inside B
// and B's highest inside A are both as deep as the shapes overlap), and round-off orders them
// differently in either body order; a key of the points keeps the same one in both.
const ManifoldPoint& deepest_of(const std::vector<ManifoldPoint>& pts) {
  double most = -std::numeric_limits<double>::infinity(), scale = 0.0;
  for (const ManifoldPoint& p : pts) {
    most = std::max(most, p.depth);
    scale = std::max(scale, p.point.cwiseAbs().maxCoeff());
  }
  const double round_off = 1e-12 * std::max(scale, std::abs(most));
  const ManifoldPoint* best = nullptr;
  for (const ManifoldPoint& p : pts) {
    if (!(p.depth >= most - round_off)) continue;
    if (!best || std::lexicographical_compare(best->point.data(), best->point.data() + 3,
                                              p.point.data(), p.point.data() + 3))
      best = &p;
  }
  return *best;
}

// The points that span the contact region: the corners of its outline in the contact plane.
// Departure from collecting every point: a point inside the outline, or within `slack` of the
// line through its two neighbours on it, adds no contact wrench the others cannot give (normal
// velocity and a rigid body's wrench are affine in the point, so a point that is a mix of
// others is redundant), but it adds a nearly dependent row to the solve: a cube turned by
// 1e-6 rad on another gives an octagon whose corners come in pairs 1e-6 apart, whose rows the
// solver cannot tell apart to round-off. The corners are found on the plane's coordinates by
// Andrew's monotone chain; then the corner nearest the line of its neighbours is dropped while
// it is within `slack`. A region within `slack` of a segment keeps its two ends; of a point,
// its deepest point. The deepest point always stays (see below).
std::vector<ManifoldPoint> support_corners(const std::vector<ManifoldPoint>& pts, const Vec3& n,
                                           double slack) {
  if (pts.size() <= 1) return pts;
  // The plane's frame from the sign-free axis, so that either body order (the normal reversed)
  // sorts the points alike and keeps the same corners of near-coincident ones.
  const Vec3 axis = plane_detail::canonical(n);
  const Vec3 t1 =
      (std::abs(axis.x()) < 0.57735 ? Vec3::UnitX() : Vec3::UnitY()).cross(axis).normalized();
  const Vec3 t2 = axis.cross(t1);
  struct Planar {
    double u, v;
    size_t index;
  };
  std::vector<Planar> q;
  for (size_t i = 0; i < pts.size(); ++i)
    q.push_back({pts[i].point.dot(t1), pts[i].point.dot(t2), i});
  std::sort(q.begin(), q.end(), [](const Planar& a, const Planar& b) {
    return a.u < b.u || (a.u == b.u && (a.v < b.v || (a.v == b.v && a.index < b.index)));
  });
  auto cross = [](const Planar& o, const Planar& a, const Planar& b) {
    return (a.u - o.u) * (b.v - o.v) - (a.v - o.v) * (b.u - o.u);
  };
  // Lower and upper chains, counter-clockwise, collinear points dropped.
  std::vector<Planar> hull;
  for (int pass = 0; pass < 2; ++pass) {
    const size_t base = hull.size();
    for (const Planar& p : q) {
      while (hull.size() >= base + 2 && cross(hull[hull.size() - 2], hull.back(), p) <= 0.0)
        hull.pop_back();
      hull.push_back(p);
    }
    hull.pop_back();  // each chain's last point starts the other
    std::reverse(q.begin(), q.end());
  }
  // Corners within `slack` of the line through their neighbours, nearest first.
  auto off_line = [&](size_t k) {
    const Planar &a = hull[(k + hull.size() - 1) % hull.size()], &b = hull[(k + 1) % hull.size()];
    const double length = std::hypot(b.u - a.u, b.v - a.v);
    if (!(length > 0.0)) return std::hypot(hull[k].u - a.u, hull[k].v - a.v);
    return std::abs(cross(a, b, hull[k])) / length;
  };
  while (hull.size() > 2) {
    size_t nearest = 0;
    for (size_t k = 1; k < hull.size(); ++k)
      if (off_line(k) < off_line(nearest)) nearest = k;
    if (!(off_line(nearest) <= slack)) break;
    hull.erase(hull.begin() + static_cast<std::ptrdiff_t>(nearest));
  }
  if (hull.size() == 1 ||
      (hull.size() == 2 && std::hypot(hull[1].u - hull[0].u, hull[1].v - hull[0].v) <= slack)) {
    // A region within `slack` of a point: its deepest point.
    return {deepest_of(pts)};
  }
  // In the order the points were found (deterministic, and the solver sweeps in that order).
  std::vector<size_t> kept;
  for (const Planar& p : hull) kept.push_back(p.index);
  std::sort(kept.begin(), kept.end());
  std::vector<ManifoldPoint> out;
  for (size_t i : kept) out.push_back(pts[i]);
  // The deepest point stays, so that the position projection sees the whole penetration (a
  // region that is not flat, a corner pushed deep into a face, is deepest inside its outline):
  // where it is deeper than every corner by more than `slack`, a corner within `slack` of it
  // takes its depth, else it is kept as well.
  auto shallower = [](const ManifoldPoint& a, const ManifoldPoint& b) { return a.depth < b.depth; };
  const ManifoldPoint& deepest = deepest_of(pts);
  if (!(deepest.depth > std::max_element(out.begin(), out.end(), shallower)->depth + slack))
    return out;
  const Vec3& pd = deepest.point;
  for (ManifoldPoint& p : out) {
    const Vec3 d = p.point - pd;
    if (std::hypot(d.dot(t1), d.dot(t2)) <= slack) {
      p.depth = deepest.depth;
      return out;
    }
  }
  out.push_back(deepest);
  return out;
}

}  // namespace

std::optional<ContactManifold> build_manifold(const ConvexPolyhedron& a, const Pose& pa,
                                              const ConvexPolyhedron& b, const Pose& pb,
                                              DetectorVariant variant, double support_slack) {
  DetectionCache cache;
  ContactScratch scratch;
  return build_manifold(a, pa, b, pb, variant, support_slack, cache, scratch);
}

std::optional<ContactManifold> build_manifold(const ConvexPolyhedron& a, const Pose& pa,
                                              const ConvexPolyhedron& b, const Pose& pb,
                                              DetectorVariant variant, double support_slack,
                                              DetectionCache& cache, ContactScratch& scratch) {
  const auto hit = detect(a, pa, b, pb, variant, cache);
  if (!hit) return std::nullopt;
  ContactManifold m;
  m.detector_contact = *hit;
  // The tests decide that the shapes touch; the plane is chosen (engine/contact_plane.h), the
  // overlap along the tests' normal bounding it from the start.
  const ContactPlane plane =
      choose_contact_plane(a, pa, b, pb, hit->normal, hit->depth, PlaneMethod::Automatic, scratch);
  m.normal = plane.normal;
  m.depth = plane.depth;
  const Vec3& n = m.normal;
  const double tol = point_in_mesh_tolerance(a, b);

  // World vertices, and the overlap slab along n: A's lowest and B's highest projection.
  std::vector<Vec3> va, vb;
  va.reserve(a.vertices().size());
  vb.reserve(b.vertices().size());
  double lo_a = std::numeric_limits<double>::infinity();
  double hi_b = -std::numeric_limits<double>::infinity();
  for (const Vec3& v : a.vertices()) {
    va.push_back(pa.apply(v));
    lo_a = std::min(lo_a, va.back().dot(n));
  }
  for (const Vec3& v : b.vertices()) {
    vb.push_back(pb.apply(v));
    hi_b = std::max(hi_b, vb.back().dot(n));
  }

  std::vector<ManifoldPoint> pts;
  // Vertices of A inside B: depth below B's extreme along n (exact for a flat contact face).
  for (const Vec3& p : va)
    if (point_in_mesh(b, pb, p, tol)) pts.push_back({p, std::max(hi_b - p.dot(n), 0.0)});
  // Vertices of B inside A.
  for (const Vec3& p : vb)
    if (point_in_mesh(a, pa, p, tol)) pts.push_back({p, std::max(p.dot(n) - lo_a, 0.0)});
  // Edge-edge crossings: only edges that reach into the overlap slab [lo_a, hi_b] can cross.
  const std::vector<Edge> ea = feature_edges(a), eb = feature_edges(b);
  std::vector<Edge> ea_in, eb_in;
  for (const Edge& e : ea)
    if (std::min(va[e.a].dot(n), va[e.b].dot(n)) <= hi_b + tol) ea_in.push_back(e);
  for (const Edge& e : eb)
    if (std::max(vb[e.a].dot(n), vb[e.b].dot(n)) >= lo_a - tol) eb_in.push_back(e);
  for (const Edge& e : ea_in)
    for (const Edge& f : eb_in) {
      Vec3 ca, cb;
      if (!crossing(va[e.a], va[e.b] - va[e.a], vb[f.a], vb[f.b] - vb[f.a], ca, cb)) continue;
      const Vec3 mid = 0.5 * (ca + cb);
      if (!point_in_mesh(a, pa, mid, tol) || !point_in_mesh(b, pb, mid, tol)) continue;
      // A lies on the +n side: penetrating edges have B's point above A's along n.
      pts.push_back({mid, std::max((cb - ca).dot(n), 0.0)});
    }

  // Touching, overlapping by no more than the tests' tolerance (as at a time of impact): which
  // vertex is inside the other shape is then decided by round-off, and the tests may see a touch
  // where nothing overlaps. The points are instead the vertices of each shape that lie lowest
  // toward the other along the normal and face it across the gap, placed midway across it: a
  // face landing gets its four corners, a corner landing its corner. An edge crossing keeps the
  // crossings found above.
  if (hi_b - lo_a <= tol) {
    std::vector<ManifoldPoint> facing;
    const double gap = lo_a - hi_b;
    for (const Vec3& p : va)
      if (p.dot(n) <= lo_a + tol && point_in_mesh(b, pb, p - gap * n, tol))
        facing.push_back({p - 0.5 * gap * n, 0.0});
    for (const Vec3& p : vb)
      if (p.dot(n) >= hi_b - tol && point_in_mesh(a, pa, p + gap * n, tol))
        facing.push_back({p + 0.5 * gap * n, 0.0});
    if (!facing.empty()) pts = std::move(facing);
  }

  // Merge coincident points (a stacked cube's corners sit on the corners below it).
  const double merge = 1e-7 * std::max(shape_size(a), shape_size(b));
  for (const ManifoldPoint& p : pts) {
    const bool dup = std::any_of(m.points.begin(), m.points.end(), [&](const ManifoldPoint& q) {
      return (q.point - p.point).norm() <= merge;
    });
    if (!dup) m.points.push_back(p);
  }
  // The corners of the region, to the slack the position projection leaves alone.
  m.points = support_corners(m.points, n, support_slack * std::min(shape_size(a), shape_size(b)));
  // No vertex inside and no crossing (a thin plate pierced through a face): the centre of the
  // contact region on the plane, the same from either body order (the detector's first hit is
  // not).
  if (m.points.empty()) {
    std::string feature;
    m.points.push_back({contact_region_centre(a, pa, b, pb, plane, feature, scratch), m.depth});
  }
  // No point is deeper than the shapes overlap.
  for (ManifoldPoint& p : m.points) p.depth = std::min(p.depth, m.depth);
  return m;
}

}  // namespace rbx
