// The contact point of `custom` on a chosen plane: the centre of the contact region.
//
// Departure from the seed: the seed's contact point is the mean of the centroids of every
// triangle of A inside B (the face test), or of the inside vertices (the vertex test): a mean over
// the whole overlapping cap, which costs a point-in-mesh test per triangle of the cap (most of a
// deep query on large hulls) and drifts with the depth, away from where the shapes will touch once
// separated. Here the point comes from the plane itself: each shape's supporting feature along the
// normal (A's lowest vertices, B's highest: a vertex, an edge or a face), both projected on the
// plane, their overlap (a polygon, a segment or a point), and its centroid, placed midway between
// the two features along the normal. docs/contact_plane.md derives it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/contact.h"
#include "engine/contact_plane.h"
#include "engine/detect.h"
#include "engine/polyhedron.h"

namespace rbx {

/// The centre of the contact region of A and B at their poses, for the plane chosen for them
/// (normal from B toward A): the centroid of the overlap of A's lowest and B's highest feature
/// along the normal, projected on the plane, midway between the two features. The same point
/// from either body order (to the last bit). `feature` names the pair of features: "vertex"
/// when either is a single vertex, "edge" for two edges, "face" otherwise.
/// With `patch`, also the contact patch (docs/contact_manifold.md, the oracle's definition):
/// on a face axis, the corners of the incident feature clipped to the reference face that lie
/// at or below its plane (all above it, touching across a gap: the lowest), each midway between
/// the two surfaces with its own depth; on an edge axis, the centre. Not yet reduced.
Vec3 contact_region_centre(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                           const Pose& pb, const ContactPlane& plane, std::string& feature,
                           ContactScratch& scratch, std::vector<ManifoldPoint>* patch = nullptr);

/// The extended engine's contact of a pair (what `custom` answers a contact query with), the
/// first stages of its contact pipeline (docs/contact_plane.md). Shapes proved to overlap
/// (choose_overlap_plane) take the chosen plane and the centre of the contact region, with no
/// detector. The others (touching within the tolerance, apart, or too close to tell) are left
/// to `detector`, faithful or accelerated (both give the same answer); a hit takes the chosen plane
/// (the overlap along the tests' normal bounding it) and keeps the detector's point. With `patch`,
/// also the contact patch on that plane (contact_region_centre), which build_manifold reduces.
std::optional<ContactPoint> find_contact(const ConvexPolyhedron& a, const Pose& pa,
                                         const ConvexPolyhedron& b, const Pose& pb,
                                         Detector detector, DetectionCache& cache,
                                         ContactScratch& scratch,
                                         std::vector<ManifoldPoint>* patch = nullptr);

}  // namespace rbx
