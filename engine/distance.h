// Separation distance: how far apart two convex shapes are, and a closest point on each.
//
// Departure from the seed, which asks only whether shapes touch. GJK (Gilbert, Johnson and
// Keerthi 1988) on the Minkowski difference D = A - B: the distance is that of the origin from
// D, found by growing a simplex of D's support points toward the origin; the closest point of the
// last simplex, as a mix of its points, gives the closest points on A and on B by the same mix of
// the shapes' vertices. The supports are the contact plane's (a scan of the vertices on small
// shapes, a climb over the Gauss map on large ones), so a query's cost follows the hull's
// neighbourhoods, not its size. Derivation and termination: docs/distance.md.
#pragma once

#include "engine/polyhedron.h"

namespace rbx {

/// Two shapes' separation.
struct Separation {
  bool overlapping = false;     // D holds the origin (to round-off): no distance, no points
  double distance = 0.0;        // m, |point_a - point_b|
  Vec3 point_a = Vec3::Zero();  // world: the point of A nearest B
  Vec3 point_b = Vec3::Zero();  // world: the point of B nearest A
};

/// The distance between A and B at their poses and a closest point on each; `overlapping` when
/// they overlap or touch to round-off (1e-12 of the pair's size), where the contact query answers
/// instead.
Separation shape_distance(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                          const Pose& pb);

}  // namespace rbx
