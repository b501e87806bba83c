// Exact contact oracle: separating-axis test over all face normals and edge-pair cross products,
// and the contact manifold by clipping the reference face against the incident face.
#pragma once

#include <memory>
#include <optional>

#include "reference/backend.h"

namespace rbx {

/// Result of the exact SAT query between two placed convex polyhedra.
struct SatResult {
  bool touching = false;        // overlap >= 0 on every axis (touching counts)
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B toward A: minimum-translation direction
  double depth = 0.0;          // m: minimum translation distance (negative: separation lower bound)
  std::string axis_kind;       // "face_a" | "face_b" | "edge_edge"
  std::vector<Vec3> manifold;  // contact polygon (world): clipped reference and incident faces
};

namespace exact_detail {
struct Topology;  // merged faces, feature edges and parallel-edge classes (exact.cpp)
}  // namespace exact_detail

/// A polyhedron prepared for the exact query: its merged faces and edge classes, computed once
/// for many queries (the shape must outlive it; copies share the topology).
class SatShape {
 public:
  explicit SatShape(const ConvexPolyhedron& shape);
  /// The polyhedron it was built from.
  const ConvexPolyhedron& shape() const { return *shape_; }
  /// Its topology (exact.cpp).
  const exact_detail::Topology& topology() const { return *topology_; }

 private:
  const ConvexPolyhedron* shape_;
  std::shared_ptr<const exact_detail::Topology> topology_;
};

/// Exact separating-axis query.
SatResult sat_query(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                    const Pose& pb);

/// The same query on prepared shapes (same answer, without rebuilding their topology).
SatResult sat_query(const SatShape& a, const Pose& pa, const SatShape& b, const Pose& pb);

/// The exact contact patch of a tied axis: where the least overlap is reached along several face
/// normals (a cube on another's diagonal: x, y and z; two coincident cubes: all six), the patch
/// of the tied face axis nearest `normal` (from B toward A), within 1 degree of it; nothing when
/// no tied face axis lies that near, or the pair is apart. On the oracle's own axis it is
/// sat_query's manifold.
struct SatPatch {
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B toward A: the tied axis
  std::vector<Vec3> corners;    // its contact polygon (world)
};
std::optional<SatPatch> sat_patch_along(const ConvexPolyhedron& a, const Pose& pa,
                                        const ConvexPolyhedron& b, const Pose& pb,
                                        const Vec3& normal);

/// The exact separation of two placed convex polyhedra (reference/exact_distance.cpp): the
/// distance and a closest point on each, from every vertex-triangle and edge-edge pair in closed
/// form (docs/distance.md).
struct ExactDistance {
  bool overlapping = false;  // the shapes overlap by more than touching: no distance
  double distance = 0.0;     // m; 0 when they touch
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();  // world, on A and on B
  std::string feature_a, feature_b;  // what each point lies on: "vertex" | "edge" | "face"
};
ExactDistance exact_distance(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                             const Pose& pb);

/// How far the world point `x` is from shape `s` at pose `p` (0 inside or on it), in closed form
/// over its triangles: what a distance query's witness point is checked with.
double exact_point_distance(const ConvexPolyhedron& s, const Pose& p, const Vec3& x);

/// The exact first contact of two convex polyhedra translating at constant velocities over
/// [0, dt] (reference/exact_time_of_impact.cpp): the largest entering time over every separating
/// axis (the faces' normals and the edge pairs' cross products), when no axis has closed again
/// by then (docs/distance.md, "Time of impact").
struct ExactImpact {
  std::optional<double> time;   // s: the first touch in [0, dt] (0: touching at the start)
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B toward A: the axis that closed last
};
ExactImpact exact_translation_impact(const ConvexPolyhedron& a, const Pose& pa, const Vec3& va,
                                     const ConvexPolyhedron& b, const Pose& pb, const Vec3& vb,
                                     double dt);

/// The oracle's time of impact of two bodies under the stated motion (reference/backend.h,
/// ToiResult): in pure translation exact_translation_impact's time, in closed form; with rotation
/// conservative advancement on exact_distance, each step certified by a bound on the motion,
/// until the pair is within kExactToiTouchRel of its size (docs/time_of_impact.md). An error
/// result when that takes more than `max_steps` steps.
constexpr double kExactToiTouchRel = 1e-12;
ToiResult exact_toi(const RigidBody& a, const RigidBody& b, double dt, long max_steps = 200000);

/// Backend `exact`: one contact per manifold point, each with the SAT normal and depth;
/// the first contact is the manifold centroid.
ContactResult exact_contact(const RigidBody& a, const RigidBody& b);
/// The oracle as a backend: `exact` (exact_contact), contact queries only.
const Adapter& exact_adapter();

}  // namespace rbx
