// Proof that the detector finds no contact, cheaper than running it: the extended world keeps,
// per pair, a triangle of each body whose plane has the other body wholly beyond it, and skips
// detection while both still hold (most pairs that pass the bounding check in a crowd).
#pragma once

#include "engine/math.h"
#include "engine/polyhedron.h"

namespace rbx {

/// Two triangles that separate a pair: every vertex of A beyond the plane of B's triangle
/// `face_of_b`, every vertex of B beyond the plane of A's triangle `face_of_a` (-1: none).
struct SeparationWitness {
  int face_of_b = -1;
  int face_of_a = -1;
};

/// The margin a witness must clear (m): twice the detector's point-in-mesh tolerance of the pair.
/// Every point the Moore & Wilhelms tests try in B (triangle centroids, vertices, points on
/// edges of A) is a convex combination of A's vertices, and B's inside test is (p - q_f) . n_f
/// <= tol for every triangle f of B; so if one triangle of B has every vertex of A more than
/// tol beyond its plane, no tried point of A is inside B, and likewise with A and B swapped:
/// the detector returns nothing. The second tol covers the round-off between this test's
/// arithmetic and the detector's (~1e-15 of the coordinates, 10^6 times smaller for poses within
/// 10^6 sizes of the origin, see point_in_mesh_tolerance).
double separation_margin(const ConvexPolyhedron& a, const ConvexPolyhedron& b);

/// True when every vertex of `a` at `pa` is more than `margin` beyond the plane of triangle
/// `face` of `b` at `pb`.
bool beyond_face(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                 const Pose& pb, int face, double margin);

/// The triangle of `b` whose normal points most nearly toward `a`'s centre of mass, if every
/// vertex of `a` is more than `margin` beyond its plane; else -1 (also for shapes whose
/// triangles and vertices number more than kMaxSeparationWork: large hulls go to the
/// detector, whose own trees are then the cheaper way).
int find_face_beyond(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                     const Pose& pb, double margin);
constexpr long kMaxSeparationWork = 4096;

/// True when `w` still separates the pair (both triangles set and both planes clear).
bool still_separated(const SeparationWitness& w, const ConvexPolyhedron& a, const Pose& pa,
                     const ConvexPolyhedron& b, const Pose& pb, double margin);

}  // namespace rbx
