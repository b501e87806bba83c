// The accelerated detector's shape view: the same tests as the faithful one (engine/features.h),
// the same answers bit for bit, less work.
//
// Design note. The seed's answers depend on order ("the first triangle whose centroid is
// inside", "the first vertex", "the first edge with an inside midpoint") and on exact
// floating-point expressions (the tolerance comparisons, the averaged points). This view
// therefore never changes a formula: every value that reaches an answer (a plane distance, a
// centroid, a crossing parameter, a dot product for the depth) is computed by the seed's own
// expression on the seed's own world-frame data. What changes is which of those expressions
// get evaluated:
//   - Candidates. A point of A can only be inside B if it lies inside every face plane of B
//     (plus the tolerance), so A's triangles, vertices and edges are culled against a few of
//     B's face planes (the one facing A, and the ones extreme along B's axes) using A's
//     hierarchy (engine/shape_hierarchy.h) in its body frame. The survivors are sorted by index,
//     so "the first" is the seed's first.
//   - Point in mesh. The seed checks every face; here B's triangle tree bounds the plane
//     distance of a whole cluster of faces at once (a cone of normals and a range of plane
//     offsets), certifying the cluster without visiting it. Only faces whose bound comes within
//     a safety margin of the tolerance are evaluated with the seed's expression.
//   - Depth, closest face, plane crossings and the nearest triangle: branch and bound over the
//     same trees, with exact evaluation at the leaves.
//   - Whole orders. Before the tests, each shape's facing face (its face most along the line to
//     the other's centre) is found; a shape lying wholly outside one face plane of the other
//     skips that order, and every point-in-mesh test tries the facing face first.
// Every bound is computed in a body frame and carries a safety margin (kMarginScale times the
// coordinate scale of the query, ~10^5 times the round-off of either computation), so a bound
// only ever skips primitives whose exact value is far on the safe side of the comparison.
// Shapes of at most kSmallTriangles triangles (boxes, low prisms) carry no hierarchy: their
// world vertices and normals are computed once per pair into the caller's workspace and the
// seed's loops run on them; for two such shapes a table of every vertex's distance to every
// distinct face plane of the other culls vertices, centroids and edges (see candidates).
#pragma once

#include <optional>
#include <vector>

#include "engine/features.h"
#include "engine/shape_hierarchy.h"

namespace rbx::detail {

/// The constants of one query: the seed's tolerance and the safety margin of the bounds.
struct Limits {
  double tol = 0.0;     // m, point-in-mesh tolerance (point_in_mesh_tolerance)
  double margin = 0.0;  // m, safety margin of every bound
};

/// A shape placed in the world for one pair, answering the view queries of engine/features.h.
/// World vertices and normals are the seed's expressions (r v + position, r n), bit-identical.
struct AcceleratedView {
  const ConvexPolyhedron* shape = nullptr;
  const ShapeHierarchy* accel = nullptr;    // null: small shape, plain loops over world copies
  Mat3 r = Mat3::Identity();                // body to world
  Mat3 rt = Mat3::Identity();               // world to body
  Vec3 position = Vec3::Zero();             // m, world
  const Vec3* world_vertices = nullptr;     // small shapes only
  const Vec3* world_normals = nullptr;      // small shapes only (unset when neither can enter)
  const unsigned char* distinct = nullptr;  // small shapes: shape->new_plane()
  int facing = -1;     // the face most along the direction toward the other shape (facing_face)
  bool enters = true;  // false: no point of this shape can be inside the other (prepare)
  // Two small shapes: the seed's plane distance of each of this shape's vertices from each
  // distinct face plane of the other, vertex-major (prepare); null otherwise, and when this
  // shape cannot enter the other (no test reads it then).
  const double* plane_table = nullptr;
  int table_planes = 0;  // columns of plane_table
  double tol = 0.0;      // m, the pair's Limits
  double margin = 0.0;   // m

  int num_triangles() const { return static_cast<int>(shape->triangles().size()); }
  __attribute__((always_inline)) Vec3 vertex(int i) const {
    if (world_vertices) return world_vertices[i];
    return r * shape->vertices()[i] + position;
  }
  __attribute__((always_inline)) Vec3 normal(int f) const {
    if (world_normals) return world_normals[f];
    return r * shape->planes()[f].normal;
  }
  /// A world point in the body frame.
  Vec3 to_local(const Vec3& p) const { return rt * (p - position); }

  // The view queries (engine/features.h).
  bool may_enter() const { return enters; }
  void candidates(Primitive kind, const AcceleratedView& y, std::vector<int>& out) const;
  bool inside(const Vec3& p) const;
  double support_max(const Vec3& n) const;
  double support_min(const Vec3& n) const;
  int closest_face(const Vec3& v) const;
  void crossings(const Vec3& v_i, const Vec3& v_j, std::vector<Crossing>& out) const;
  int nearest_triangle(const Vec3& p) const;
  bool segment_outside(const AcceleratedView& x, const Vec3& v_i, const Vec3& v_j) const;
};

/// Reusable storage of the accelerated path (owned by a DetectionCache): world copies of two
/// small shapes and their plane tables.
struct AcceleratedWorkspace {
  std::vector<Vec3> vertices[2], normals[2];
  std::vector<double> tables[2];
};

/// A pair ready for the accelerated tests: both shapes placed, facing faces, plane tables.
/// Points into the workspace it was prepared with.
struct AcceleratedPair {
  AcceleratedView a, b;

  /// Places a and b, finds their facing faces and which order can hit.
  void prepare(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b, const Pose& pb,
               AcceleratedWorkspace& workspace);
  /// One test in both orders (seed correction 8 (both orders, normal flipped)).
  std::optional<ContactPoint> test(Feature feature, FeatureScratch& scratch) const;
  /// Face, vertex, edge in turn, each in both orders: the first hit.
  std::optional<ContactPoint> detect(FeatureScratch& scratch) const;
};

}  // namespace rbx::detail
