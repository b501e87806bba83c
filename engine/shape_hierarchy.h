// Hierarchies a convex polyhedron carries for the accelerated detector: bounding volume trees
// over its triangles, vertices and edges, with bounds on the face planes of every triangle
// cluster, all in the shape's own frame. Built once with the shape (which is immutable), so no
// detector keeps a cache of them.
#pragma once

#include <array>
#include <vector>

#include "engine/bvh.h"

namespace rbx {

class ConvexPolyhedron;

/// Shapes with at most this many triangles carry no hierarchy and are tested with plain loops
/// (a box has 12): below that, a tree costs more to traverse than the faces it would skip.
constexpr int kSmallTriangles = 32;

/// Bounds on the face planes of a node of the triangle tree. For a face f of the node, with
/// outward normal n_f and vertex q_f, the seed's plane distance of a point p is
/// s_f(p) = n_f . (p - q_f) = n_f . (p - c) - e_f, c the node's box centre and
/// e_f = n_f . (q_f - c). The normals lie in a cone (axis, half-angle t), so with w = p - c at an
/// angle phi from the axis, n_f . w <= |w| cos(max(0, phi - t)), and e_f is in [e_min, e_max].
struct FaceCone {
  Vec3 axis = Vec3::UnitZ();  // unit, body frame
  double cos_half = -1.0;     // cosine and sine of the half-angle, widened by round-off
  double sin_half = 0.0;
  double e_min = 0.0, e_max = 0.0;  // m, plane offsets from the node centre
};

/// Everything the accelerated detector precomputes for one shape, in its body frame.
struct ShapeHierarchy {
  Bvh triangles;                    // over triangles (boxes of their three vertices)
  std::vector<FaceCone> cones;      // one per node of `triangles`
  Bvh vertices;                     // over vertices
  Bvh edges;                        // over edges (boxes of their two ends)
  std::array<int, 6> axis_faces{};  // the face whose normal is most along +x, -x, +y, ... -z

  /// Builds the hierarchies of `shape` (its vertices, triangles, edges and planes must be set).
  static ShapeHierarchy build(const ConvexPolyhedron& shape);

  /// Bounds [lo, hi] (m) on the plane distances s_f(p) of every face of node k of the triangle
  /// tree, p in the body frame (see FaceCone).
  void plane_bounds(int k, const Vec3& p_local, double& lo, double& hi) const;
};

inline void ShapeHierarchy::plane_bounds(int k, const Vec3& p_local, double& lo, double& hi) const {
  const BvhNode& node = triangles.nodes[k];
  const FaceCone& cone = cones[k];
  const Vec3 w = p_local - node.center;
  const double len = w.norm();
  const double along = cone.axis.dot(w);            // |w| cos(phi)
  const double across = cone.axis.cross(w).norm();  // |w| sin(phi), accurate for small phi
  // max over the cone of n . w: |w| if w is inside the cone, else |w| cos(phi - t).
  const double n_max =
      along >= len * cone.cos_half ? len : along * cone.cos_half + across * cone.sin_half;
  // min over the cone of n . w: -|w| if -w is inside the cone, else |w| cos(phi + t).
  const double n_min =
      -along >= len * cone.cos_half ? -len : along * cone.cos_half - across * cone.sin_half;
  hi = n_max - cone.e_min;
  lo = n_min - cone.e_max;
}

}  // namespace rbx
