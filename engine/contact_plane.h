// The contact plane chosen, not first found (the extended engine, `custom`).
//
// Departure from the seed: Moore & Wilhelms' tests decide *whether* two shapes touch and where
// (engine/detect.h), but the plane they return is the first face (or edge pair) the loops meet,
// right when contact begins at zero depth and wrong beyond it: the answer then depends on the
// depth, on the order of the bodies and on the phase of the step at which contact is first seen.
// The seed's own closing section names a detector that furnishes the point and the plane together
// as future work. Here, once the tests have found a contact, the plane is chosen by a stated
// criterion: the direction of least overlap (the minimum translation that separates the shapes),
// which for two convex polyhedra lies among the face normals of either shape and the cross
// products of one edge of each whose Gauss-map arcs cross (docs/contact_plane.md derives it).
//
// Order symmetry: every candidate axis and every overlap is computed from the same numbers in
// either order, and ties are broken by a key of the geometry (the kind of axis, then the axis
// itself in a sign-free form), never by argument slot, so (B, A) gives the normal of (A, B)
// negated and the same depth.
#pragma once

#include <optional>

#include "engine/contact_scratch.h"
#include "engine/math.h"
#include "engine/polyhedron.h"

namespace rbx {

/// Which kind of axis gave the contact plane.
enum class PlaneAxis {
  FaceOfA,  ///< a face normal of A (A is pushed against it)
  FaceOfB,  ///< a face normal of B
  EdgeEdge  ///< the cross product of an edge of A and an edge of B
};

/// The chosen contact plane of a pair, in the convention of engine/contact.h.
struct ContactPlane {
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B toward A
  double depth = 0.0;           // m, >= 0: the overlap of the shapes along the normal
  PlaneAxis axis = PlaneAxis::FaceOfB;
  // Where the inner polytope found the supports along the normal (A's lowest vertex, B's
  // highest), or -1: starting points for later climbs over the same shapes, not part of the answer.
  int vertex_a = -1, vertex_b = -1;
};

/// How the candidate axes are found; every method gives the same plane (to round-off).
enum class PlaneMethod {
  Automatic,   ///< the search (the faster on every pair measured)
  Scan,        ///< every face measured, every solid edge near the other shape paired: linear;
               ///< for shapes it cannot prove to overlap (apart by a hair), the search
  Search,      ///< branch and bound over the shapes' Gauss maps: skips whole cones of them, and
               ///< first narrows the directions by an inner polytope of A - B (GJK, then EPA)
  WholeSearch  ///< the search over every direction, without the polytope (its check)
};

/// The direction of least overlap of A and B at their poses: over every distinct face normal of
/// either shape and every pair of solid edges (one of each, not a flat face's diagonal) that forms
/// a face of the Minkowski difference, the one along which A must move least to separate.
/// Meant for shapes the detector found in contact; for separated shapes the depth is 0.
ContactPlane choose_contact_plane(const ConvexPolyhedron& a, const Pose& pa,
                                  const ConvexPolyhedron& b, const Pose& pb,
                                  PlaneMethod method = PlaneMethod::Automatic);

/// The same plane, given an overlap already measured along one direction: `known_overlap` (m)
/// along the unit `known_normal` (from B toward A), such as the detector's contact (its depth is
/// the overlap along its normal). The least overlap is at most that, so every candidate beyond it
/// is skipped from the start instead of after the first few are measured; every candidate within
/// the tie margin of the least is still measured, so the plane chosen is the same, bit for bit.
ContactPlane choose_contact_plane(const ConvexPolyhedron& a, const Pose& pa,
                                  const ConvexPolyhedron& b, const Pose& pb,
                                  const Vec3& known_normal, double known_overlap,
                                  PlaneMethod method, ContactScratch& scratch);

/// The same, on a scratch of its own (allocated for the one query: tests and tools).
ContactPlane choose_contact_plane(const ConvexPolyhedron& a, const Pose& pa,
                                  const ConvexPolyhedron& b, const Pose& pb,
                                  const Vec3& known_normal, double known_overlap,
                                  PlaneMethod method = PlaneMethod::Automatic);

/// The same plane, only for shapes proved to overlap by more than round-off: by the scan's point
/// inside both shapes, or the inner polytope's tetrahedron around the origin of A - B (the
/// search's narrowing). Nothing for shapes touching, apart, or too close to touching to tell
/// (the whole search is then not run): a detector decides those.
std::optional<ContactPlane> choose_overlap_plane(const ConvexPolyhedron& a, const Pose& pa,
                                                 const ConvexPolyhedron& b, const Pose& pb,
                                                 ContactScratch& scratch);

}  // namespace rbx
