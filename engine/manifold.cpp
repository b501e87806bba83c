#include "engine/manifold.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/contact_plane_detail.h"
#include "engine/contact_region.h"

namespace rbx {

namespace {

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
}  // namespace

// The reduction's lists, kept by the caller's scratch between queries (a point of the plane and
// the index of the manifold point it came from).
struct plane_detail::ManifoldLists {
  struct Planar {
    double u, v;
    size_t index;
  };
  std::vector<Planar> sorted, hull;
};

void plane_detail::ListsDeleter::operator()(ManifoldLists* p) const { delete p; }

namespace {

void support_corners(std::vector<ManifoldPoint>& pts, const Vec3& n, double slack,
                     plane_detail::ManifoldLists& w) {
  if (pts.size() <= 1) return;
  // The plane's frame from the sign-free axis, so that either body order (the normal reversed)
  // sorts the points alike and keeps the same corners of near-coincident ones.
  const Vec3 axis = plane_detail::canonical(n);
  const Vec3 t1 =
      (std::abs(axis.x()) < 0.57735 ? Vec3::UnitX() : Vec3::UnitY()).cross(axis).normalized();
  const Vec3 t2 = axis.cross(t1);
  using Planar = plane_detail::ManifoldLists::Planar;
  std::vector<Planar>& q = w.sorted;
  q.clear();
  for (size_t i = 0; i < pts.size(); ++i)
    q.push_back({pts[i].point.dot(t1), pts[i].point.dot(t2), i});
  std::sort(q.begin(), q.end(), [](const Planar& a, const Planar& b) {
    return a.u < b.u || (a.u == b.u && (a.v < b.v || (a.v == b.v && a.index < b.index)));
  });
  auto cross = [](const Planar& o, const Planar& a, const Planar& b) {
    return (a.u - o.u) * (b.v - o.v) - (a.v - o.v) * (b.u - o.u);
  };
  // Lower and upper chains, counter-clockwise, collinear points dropped.
  std::vector<Planar>& hull = w.hull;
  hull.clear();
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
  // Corners within `slack` of the line through their neighbours, nearest first (distances
  // compared squared: the order is the same, without a root per corner and pass).
  auto off_line2 = [&](size_t k) {
    const Planar &a = hull[(k + hull.size() - 1) % hull.size()], &b = hull[(k + 1) % hull.size()];
    const double length2 = (b.u - a.u) * (b.u - a.u) + (b.v - a.v) * (b.v - a.v);
    const double du = hull[k].u - a.u, dv = hull[k].v - a.v;
    if (!(length2 > 0.0)) return du * du + dv * dv;
    const double c = cross(a, b, hull[k]);
    return c * c / length2;
  };
  const double slack2 = slack * slack;
  while (hull.size() > 2) {
    size_t nearest = 0;
    double least = off_line2(0);
    for (size_t k = 1; k < hull.size(); ++k) {
      const double off = off_line2(k);
      if (off < least) {
        nearest = k;
        least = off;
      }
    }
    if (!(least <= slack2)) break;
    hull.erase(hull.begin() + static_cast<std::ptrdiff_t>(nearest));
  }
  const ManifoldPoint deepest = deepest_of(pts);
  auto apart2 = [](const Planar& x, const Planar& y) {
    return (x.u - y.u) * (x.u - y.u) + (x.v - y.v) * (x.v - y.v);
  };
  if (hull.size() == 1 || (hull.size() == 2 && apart2(hull[1], hull[0]) <= slack2)) {
    // A region within `slack` of a point: its deepest point.
    pts.assign(1, deepest);
    return;
  }
  // In the order the points were found (deterministic, and the solver iterates in that order).
  std::sort(hull.begin(), hull.end(),
            [](const Planar& a, const Planar& b) { return a.index < b.index; });
  size_t kept = 0;
  for (const Planar& p : hull) pts[kept++] = pts[p.index];  // p.index >= kept: sorted, distinct
  pts.resize(kept);
  // The deepest point stays, so that the position projection sees the whole penetration (a
  // region that is not flat, a corner pushed deep into a face, is deepest inside its outline):
  // where it is deeper than every corner by more than `slack`, a corner within `slack` of it
  // takes its depth, else it is kept as well.
  auto shallower = [](const ManifoldPoint& a, const ManifoldPoint& b) { return a.depth < b.depth; };
  if (!(deepest.depth > std::max_element(pts.begin(), pts.end(), shallower)->depth + slack)) return;
  const Vec3& pd = deepest.point;
  for (ManifoldPoint& p : pts) {
    const Vec3 d = p.point - pd;
    const double du = d.dot(t1), dv = d.dot(t2);
    if (du * du + dv * dv <= slack2) {
      p.depth = deepest.depth;
      return;
    }
  }
  pts.push_back(deepest);
}

}  // namespace

std::optional<ContactManifold> build_manifold(const ConvexPolyhedron& a, const Pose& pa,
                                              const ConvexPolyhedron& b, const Pose& pb,
                                              Detector detector, double support_slack) {
  DetectionCache cache;
  ContactScratch scratch;
  return build_manifold(a, pa, b, pb, detector, support_slack, cache, scratch);
}

std::optional<ContactManifold> build_manifold(const ConvexPolyhedron& a, const Pose& pa,
                                              const ConvexPolyhedron& b, const Pose& pb,
                                              Detector detector, double support_slack,
                                              DetectionCache& cache, ContactScratch& scratch) {
  ContactManifold m;
  m.points.reserve(8);  // a face contact's corners, and a few clipped ones, in one allocation
  if (!build_manifold(a, pa, b, pb, detector, support_slack, cache, scratch, m))
    return std::nullopt;
  return m;
}

bool build_manifold(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                    const Pose& pb, Detector detector, double support_slack, DetectionCache& cache,
                    ContactScratch& scratch, ContactManifold& m) {
  // 1-3. The features in contact, the chosen plane and the patch clipped on it: the query's
  // own pipeline (engine/contact_region.h), so that `custom` answers with this manifold.
  auto contact = find_contact(a, pa, b, pb, detector, cache, scratch, &m.points);
  if (!contact) return false;
  m.normal = contact->normal;
  m.depth = contact->depth;
  m.contact = std::move(*contact);
  // Merge coincident points (a clipped corner on a corner of the reference face), the first of
  // each kept.
  const double size_a = shape_size(a), size_b = shape_size(b);
  const double merge = 1e-7 * std::max(size_a, size_b), merge2 = merge * merge;
  size_t kept = 0;
  for (size_t i = 0; i < m.points.size(); ++i) {
    const Vec3& p = m.points[i].point;
    if (std::none_of(m.points.begin(), m.points.begin() + static_cast<std::ptrdiff_t>(kept),
                     [&](const ManifoldPoint& q) { return (q.point - p).squaredNorm() <= merge2; }))
      m.points[kept++] = m.points[i];
  }
  m.points.resize(kept);
  // 4. The reduction: the corners of the region, to the slack the position projection leaves
  // alone.
  plane_detail::Scratch& lists = scratch.lists();
  if (!lists.manifold) lists.manifold.reset(new plane_detail::ManifoldLists);
  support_corners(m.points, m.normal, support_slack * std::min(size_a, size_b), *lists.manifold);
  return true;
}

}  // namespace rbx
