#include "engine/touch_witness.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>

#include "engine/separation.h"

namespace rbx {

namespace {

// True when the world point p is below every triangle plane of `mesh` placed by `pose`.
bool strictly_inside(const ConvexPolyhedron& mesh, const Pose& pose, const Vec3& p) {
  const Vec3 local = pose.inverse_apply(p);
  for (const Plane& plane : mesh.planes())
    if (!(plane.distance(local) < 0.0)) return false;
  return true;
}

// True when edge e of `owner` (placed by `po`) passes through `mesh` (placed by `pm`) along more
// than 2 tol of its length. The detector's edge test cuts the edge where it crosses the plane of
// each of the mesh's triangles, merges cuts closer than tol along it, and tries the middle of
// each two consecutive cuts left (the edge's ends included). Along the edge each plane's signed
// distance is linear, so the part inside runs from the last entry to the first exit and no plane
// is crossed between them. The cut kept last at or before the entry is within tol of it, and,
// the part being longer than tol, the next one kept is the exit (or a cut inside): a middle the
// detector tries lies in the inside part, below or on every plane. The second tol covers
// round-off.
bool passes_through(const ConvexPolyhedron& owner, const Pose& po, int e,
                    const ConvexPolyhedron& mesh, const Pose& pm, double tol) {
  const Edge& edge = owner.edges()[static_cast<size_t>(e)];
  const Vec3 p0 = pm.inverse_apply(po.apply(owner.vertices()[static_cast<size_t>(edge.a)]));
  const Vec3 p1 = pm.inverse_apply(po.apply(owner.vertices()[static_cast<size_t>(edge.b)]));
  double enter = 0.0, exit = 1.0;
  for (const Plane& plane : mesh.planes()) {
    const double d0 = plane.distance(p0), d1 = plane.distance(p1);
    if (d0 > 0.0 && d1 > 0.0) return false;
    if (d0 > 0.0) enter = std::max(enter, d0 / (d0 - d1));
    if (d1 > 0.0) exit = std::min(exit, d0 / (d0 - d1));
  }
  return (exit - enter) * (p1 - p0).norm() > 2.0 * tol;
}

// The edge of `shape` (placed by `pose`) nearest the world point p, among the edges between two
// planes (a box face's diagonal is none: it has no edge-on-edge touch); -1 when there is none.
int nearest_edge(const ConvexPolyhedron& shape, const Pose& pose, const Vec3& p) {
  const Vec3 q = pose.inverse_apply(p);
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (size_t e = 0; e < shape.edges().size(); ++e) {
    const std::array<int, 2>& faces = shape.edge_faces()[e];
    if (shape.planes()[static_cast<size_t>(faces[0])].normal ==
        shape.planes()[static_cast<size_t>(faces[1])].normal)
      continue;
    const Vec3& x0 = shape.vertices()[static_cast<size_t>(shape.edges()[e].a)];
    const Vec3& x1 = shape.vertices()[static_cast<size_t>(shape.edges()[e].b)];
    const double s = std::clamp((q - x0).dot(x1 - x0) / (x1 - x0).squaredNorm(), 0.0, 1.0);
    const double distance = (x0 + s * (x1 - x0) - q).norm();
    if (distance < best_distance) {
      best_distance = distance;
      best = static_cast<int>(e);
    }
  }
  return best;
}

Vec3 edge_direction(const ConvexPolyhedron& shape, const Pose& pose, int e) {
  const Edge& edge = shape.edges()[static_cast<size_t>(e)];
  return pose.orientation * (shape.vertices()[static_cast<size_t>(edge.b)] -
                             shape.vertices()[static_cast<size_t>(edge.a)]);
}

long work(const ConvexPolyhedron& shape) {
  return static_cast<long>(shape.vertices().size() + shape.triangles().size());
}

}  // namespace

std::optional<TouchWitness> TouchWitness::of(const ConvexPolyhedron& a, const Pose& pa,
                                             const ConvexPolyhedron& b, const Pose& pb,
                                             const ContactPoint& hit) {
  if (work(a) + work(b) > kMaxSeparationWork) return std::nullopt;
  return TouchWitness(a, pa, b, pb, hit);
}

TouchWitness::TouchWitness(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                           const Pose& pb, const ContactPoint& hit)
    : a_(&a),
      b_(&b),
      normal_(hit.normal),
      normal_in_a_(pa.orientation.conjugate() * hit.normal),
      normal_in_b_(pb.orientation.conjugate() * hit.normal),
      vertex_a_(a.support_index(-normal_in_a_)),
      vertex_b_(b.support_index(normal_in_b_)),
      edge_a_(nearest_edge(a, pa, hit.point)),
      edge_b_(nearest_edge(b, pb, hit.point)) {}

std::optional<bool> TouchWitness::settle(const Pose& pa, const Pose& pb, double reach, double tol) {
  const ConvexPolyhedron &a = *a_, &b = *b_;
  constexpr int kAxes = 4;
  for (int k = 0; k < kAxes; ++k) {
    const int axis = (last_axis_ + k) % kAxes;
    Vec3 u = normal_;
    if (axis == 1) u = pb.orientation * normal_in_b_;
    if (axis == 2) u = pa.orientation * normal_in_a_;
    if (axis == 3) {
      if (edge_a_ < 0 || edge_b_ < 0) continue;
      const Vec3 ea = edge_direction(a, pa, edge_a_), eb = edge_direction(b, pb, edge_b_);
      u = ea.cross(eb);
      // Parallel edges give no axis (an edge lying on an edge touches along a face's normal).
      if (!(u.squaredNorm() > 1e-12 * ea.squaredNorm() * eb.squaredNorm())) continue;
      u = (u.dot(normal_) < 0.0 ? -u : u).normalized();
    }
    if (gap_along(a, pa, b, pb, u) > reach) {
      last_axis_ = axis;
      return false;
    }
  }
  if (strictly_inside(b, pb, pa.apply(a.vertices()[static_cast<size_t>(vertex_a_)])) ||
      strictly_inside(a, pa, pb.apply(b.vertices()[static_cast<size_t>(vertex_b_)])) ||
      (edge_a_ >= 0 && passes_through(a, pa, edge_a_, b, pb, tol)) ||
      (edge_b_ >= 0 && passes_through(b, pb, edge_b_, a, pa, tol)))
    return true;
  return std::nullopt;
}

}  // namespace rbx
