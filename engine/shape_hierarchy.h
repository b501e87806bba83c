// Hierarchies a convex polyhedron carries for the accelerated detector: bounding volume trees
// over its triangles, vertices and edges, with bounds on the face planes of every triangle
// cluster, all in the shape's own frame. Built once with the shape (which is immutable), so no
// detector keeps a cache of them.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "engine/bvh.h"

namespace rbx {

class ConvexPolyhedron;

/// Shapes with at most this many triangles carry no hierarchy and are tested with plain loops
/// (a box has 12): below that, a tree costs more to traverse than the faces it would skip.
constexpr int kSmallTriangles = 32;

/// A face plane in the body frame, packed for the leaves of the triangle tree: n . p - d is the
/// plane distance of a body-frame point p (d = n . q_f). Within round-off of the seed's
/// world-frame value, so it only ever decides with a margin.
struct LocalPlane {
  Vec3 n = Vec3::UnitZ();
  double d = 0.0;  // m
};

/// Bounds on the face planes of a node of the triangle tree. For a face f of the node, with
/// outward normal n_f and vertex q_f, the seed's plane distance of a point p is
/// s_f(p) = n_f . (p - q_f) = n_f . (p - c) - e_f, c the node's box centre and
/// e_f = n_f . (q_f - c) in [e_min, e_max]. The normals' components lie in [nlo, nhi], so with
/// w = p - c, n_f . w lies between sum_i min(nlo_i w_i, nhi_i w_i) and the same with max (no
/// square root; for the small clusters near a contact about as tight as a cone of normals).
struct NormalBox {
  Vec3 center = Vec3::Zero();  // m, the node's box centre (body frame)
  Vec3 nlo = Vec3::Zero(), nhi = Vec3::Zero();
  double e_min = 0.0, e_max = 0.0;  // m, the range of e_f
};

/// Everything the accelerated detector precomputes for one shape, in its body frame.
struct ShapeHierarchy {
  Bvh triangles;                    // over triangles (boxes of their three vertices)
  std::vector<NormalBox> boxes;     // one per node of `triangles`
  std::vector<LocalPlane> planes;   // the face planes in the order of triangles.order
  Bvh vertices;                     // over vertices
  Bvh edges;                        // over edges (boxes of their two ends)
  std::array<int, 6> axis_faces{};  // the face whose normal is most along +x, -x, +y, ... -z
  // A ball inside the shape: around the vertex mean, as far as its nearest face plane (m, body
  // frame; <= 0 when the mean is on or beyond a face plane). Every face's plane distance of a
  // point within it is at most |p - centre| - radius, so inside() certifies it without a search.
  Vec3 ball_centre = Vec3::Zero();
  double ball_radius = 0.0;
  // Incidence, compressed by vertex: the edges of vertex v are
  // vertex_edges[edge_start[v] .. edge_start[v + 1]), its triangles likewise.
  std::vector<int> edge_start, vertex_edges;
  std::vector<int> triangle_start, vertex_triangles;
  // The three triangles across the edges of each triangle (closed mesh: always three).
  std::vector<std::array<int, 3>> triangle_neighbors;

  /// Builds the hierarchies of `shape` (its vertices, triangles, edges and planes must be set).
  static ShapeHierarchy build(const ConvexPolyhedron& shape);

  /// Upper bound (m) on the plane distances of the faces of node k at p (NormalBox).
  double plane_upper(int k, const Vec3& p_local) const;
  /// Bounds [lo, hi] (m) on the plane distances s_f(p) of every face of node k, p in the body
  /// frame (NormalBox).
  void plane_bounds(int k, const Vec3& p_local, double& lo, double& hi) const;
};

inline double ShapeHierarchy::plane_upper(int k, const Vec3& p_local) const {
  const NormalBox& b = boxes[k];
  const double wx = p_local.x() - b.center.x(), wy = p_local.y() - b.center.y(),
               wz = p_local.z() - b.center.z();
  return std::max(b.nlo.x() * wx, b.nhi.x() * wx) + std::max(b.nlo.y() * wy, b.nhi.y() * wy) +
         std::max(b.nlo.z() * wz, b.nhi.z() * wz) - b.e_min;
}

inline void ShapeHierarchy::plane_bounds(int k, const Vec3& p_local, double& lo, double& hi) const {
  const NormalBox& b = boxes[k];
  const double wx = p_local.x() - b.center.x(), wy = p_local.y() - b.center.y(),
               wz = p_local.z() - b.center.z();
  const double ax = b.nlo.x() * wx, bx = b.nhi.x() * wx, ay = b.nlo.y() * wy, by = b.nhi.y() * wy,
               az = b.nlo.z() * wz, bz = b.nhi.z() * wz;
  hi = std::max(ax, bx) + std::max(ay, by) + std::max(az, bz) - b.e_min;
  lo = std::min(ax, bx) + std::min(ay, by) + std::min(az, bz) - b.e_max;
}

}  // namespace rbx
