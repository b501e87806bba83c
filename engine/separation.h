// Proof that the detector finds no contact, cheaper than running it: the extended world keeps,
// per pair, an axis along which the two bodies are apart by more than the detector's tolerance
// can bridge, and skips detection while it holds (most pairs that pass the bounding check in a
// crowd, and every body against a far wall).
#pragma once

#include "engine/math.h"
#include "engine/polyhedron.h"

namespace rbx {

/// How far the detector's tolerant inside test reaches beyond a shape, per unit tolerance: the
/// test accepts p when (p - q_f) . n_f <= tol for every triangle f, a region that extends past
/// the shape along a unit direction u by at most tol * c (c >= 1). Bound used: at the support
/// vertex v of u, u = sum of lambda_f n_f over v's triangles with lambda >= 0, and for any unit
/// w with n_f . w > 0 on all of them, sum lambda_f <= 1 / min_f n_f . w; w is the normalised
/// sum of v's distinct triangle normals; c is the largest such bound over the vertices (sqrt 3 for
/// a box). Infinite when a vertex's normals admit no such w (no witness is then ever given).
double tolerance_reach(const ConvexPolyhedron& shape);

/// The margin an axis must clear (m): (max(c_a, c_b) + 1) x the pair's point-in-mesh tolerance
/// (c from tolerance_reach). Every point the Moore & Wilhelms tests try in B (triangle
/// centroids, vertices, points on edges of A) lies in A, and B's tolerant inside region lies
/// within c_b tol of B; if A and B are apart along an axis by more than c_b tol, no tried point
/// of A is inside B, and likewise with A and B swapped: the detector returns nothing. The extra
/// tol covers the round-off between this test's arithmetic and the detector's (~1e-15 of the
/// coordinates, 10^6 times smaller for poses within 10^6 sizes of the origin).
double separation_margin(double tol, double reach_a, double reach_b);

/// The gap between `a` and `b` along the unit world axis `u` pointing from b toward a:
/// min over a's vertices of u . v minus max over b's vertices of u . v (m; negative: overlap).
double gap_along(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                 const Pose& pb, const Vec3& u);

/// A lower bound on gap_along(a, pa, b, pb, u) from each shape's bounding box in its own frame
/// (exact for boxes): the same two rotations of u, no loop over the vertices.
double gap_bound_along(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                       const Pose& pb, const Vec3& u);

/// A unit world axis from b toward a along which the pair is apart by more than `margin`, from
/// a few candidates (the direction between the centres of mass, b's triangle normal nearest it,
/// a's triangle normal nearest its opposite; then the direction from each body's box, in its
/// own frame, to the other's centre, and the triangle normals nearest those); the zero vector
/// when none is. Large shapes (more
/// than kMaxSeparationWork vertices and triangles together) get none: the detector's own trees
/// are then the cheaper way.
Vec3 find_separating_axis(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                          const Pose& pb, double margin);
constexpr long kMaxSeparationWork = 4096;

}  // namespace rbx
