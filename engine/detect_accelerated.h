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
//     B's face planes (the one facing A, and the ones extreme along B's axes). A shape with a
//     hierarchy first finds its "cap": the vertices within the tolerance of B's facing face
//     plane or beyond it, grown over edges from one such vertex (the vertices on one side of a
//     plane are connected by edges, as in the simplex method), so the rest are never visited;
//     the candidates are the cap's vertices and the triangles and edges that have one. The
//     survivors are sorted by index, so "the first" is the seed's first.
//   - Point in mesh. The seed checks every face; here a point within B's inscribed ball (grown
//     by tol - margin) is inside at once, and otherwise B's triangle tree bounds the plane
//     distance of a whole cluster of faces at once (the range of their normals' components
//     and of their plane offsets), certifying the cluster without visiting it. In a leaf, the
//     face's plane distance in B's body frame (within round-off of the seed's) decides unless
//     it is within a safety margin of the tolerance; only those faces take the seed's
//     expression.
//   - Depth, closest face, plane crossings and the nearest triangle: branch and bound over the
//     same trees, with the same body-frame rule at the leaves and the seed's expression
//     wherever a comparison is within the margin.
//   - Whole orders. Before the tests, each shape's facing face (its face most along the line to
//     the other's centre; for a shape with a hierarchy, found by climbing over adjacent faces)
//     is found; a shape lying wholly outside one face plane of the other, or with an empty cap,
//     skips that order, and every point-in-mesh test tries the facing face first.
// Every bound is computed in a body frame and carries a safety margin (kMarginScale times the
// coordinate scale of the query, ~10^5 times the round-off of either computation), so a bound
// only ever skips primitives whose exact value is far on the safe side of the comparison.
// Shapes of at most kSmallTriangles triangles (boxes, low prisms) carry no hierarchy: their
// world vertices and normals are computed once per pair into the caller's workspace and the
// seed's loops run on them; for two such shapes a table of every vertex's distance to every
// distinct face plane of the other culls vertices, centroids and edges (see candidates).
// Shapes with a hierarchy and at most kLinearVertices vertices scan their body-frame planes
// and vertices (with the same margin rule) instead of searching the trees.
#pragma once

#include <cstdint>
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

/// A face plane of the other shape used to cull this shape's primitives: every point p of a hit
/// has s(p) = (p - q) . n <= tol (the seed's inside() checks every face). Precomputed for this
/// shape's body frame: s(r c + position) = c . m + c0, with m = rt n and c0 = (position - q) . n.
struct CullPlane {
  Vec3 m = Vec3::Zero();
  Vec3 m_abs = Vec3::Zero();
  double c0 = 0.0;
  Vec3 normal = Vec3::Zero();  // world, the seed's n_f
  Vec3 point = Vec3::Zero();   // m, world, the seed's q_f
  /// The seed's plane distance (p - q_f) . n_f of a world point.
  double distance(const Vec3& p) const { return (p - point).dot(normal); }
  /// The same for a body-frame point, within round-off of it.
  double local_distance(const Vec3& c) const {
    return (c.x() * m.x() + c.y() * m.y()) + c.z() * m.z() + c0;
  }
};

/// Shapes with a hierarchy and at most this many vertices are scanned, not searched (measured
/// on hulls of random points on a sphere: at 32 vertices the scans take ~half the time of the
/// searches; the trees win from a few hundred).
constexpr int kLinearVertices = 256;

/// At most this many cull planes: the other shape's facing face and its six axis faces.
constexpr int kMaxCullPlanes = 7;

/// A shape placed in the world for one pair, answering the view queries of engine/features.h.
/// World vertices and normals are the seed's expressions (r v + position, r n), bit-identical.
struct AcceleratedView {
  const ConvexPolyhedron* shape = nullptr;
  const ShapeHierarchy* accel = nullptr;  // null: small shape, plain loops over world copies
  // A hierarchy over few vertices (kLinearVertices): the queries scan its body-frame planes and
  // vertices instead of searching its trees, which cost more than they skip at that size.
  bool linear = false;
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
  // The other shape's cull planes in this shape's frame (prepare), the facing face's first.
  const CullPlane* cull = nullptr;
  int cull_count = 0;
  // A shape with a hierarchy: the vertices that may lie within tol of the other's facing face
  // plane or beyond it (its "cap", increasing; prepare). Every hit lies on a primitive with a
  // vertex in the cap. Null: no cap (no facing face), the trees cull instead.
  const std::vector<int>* cap = nullptr;
  // With a cap: the workspace's bitmap that puts index lists in order (sort_unique), left cleared.
  std::vector<std::uint64_t>* bits = nullptr;

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
  CullPlane cull[2][kMaxCullPlanes];
  std::vector<int> cap[2];
  std::vector<unsigned> seen[2];    // cap search marks: seen[v] == stamp
  std::vector<std::uint64_t> bits;  // sort_unique's bitmap, cleared between uses
  unsigned stamp[2] = {0, 0};
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
