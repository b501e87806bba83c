// Contact manifold: every contact point of a pair in one pass, with one normal.
//
// Departure from the seed, which resolves the first face / vertex / edge hit (or an average of
// one kind) as a single point (seed correction 12 (what the seed admits it lacks) names a
// contact plane from the detector as future work): once the detector (Moore & Wilhelms,
// engine/detect.h) finds a contact, the manifold takes the chosen plane (engine/contact_plane.h,
// the direction of least overlap, not the first face hit) and collects, against it, every vertex
// of A inside B, every vertex
// of B inside A and every crossing of a real edge of A with a real edge of B (the closest points of
// two crossing segments). A face-face landing then has its four corners, not one averaged point.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/contact.h"
#include "engine/contact_scratch.h"
#include "engine/detect.h"
#include "engine/polyhedron.h"
#include "engine/settings.h"

namespace rbx {

/// One point of a manifold.
struct ManifoldPoint {
  Vec3 point = Vec3::Zero();  // m, world
  double depth = 0.0;         // m, >= 0, penetration along the manifold normal at this point
};

/// Every contact point of one pair, sharing one normal (engine/contact.h convention: from B
/// toward A).
struct ContactManifold {
  Vec3 normal = Vec3::UnitZ();        // unit, world, from B toward A
  double depth = 0.0;                 // m, overlap of the two shapes along the normal
  ContactPoint detector_contact;      // the detector's first hit (its point, normal, feature)
  std::vector<ManifoldPoint> points;  // at least one
};

/// The manifold of A and B at their poses, or nothing when the detector finds no contact.
/// The normal is the chosen plane's (choose_contact_plane); the points are the vertices of each
/// shape inside the other (point_in_mesh with point_in_mesh_tolerance) and the edge-edge crossings
/// whose midpoint lies in both shapes. Edges between two coplanar triangles (a face's triangulation
/// diagonal) are not edges of the solid and are skipped. Points closer than 1e-7 of the larger
/// shape's size are merged. Of the rest only the corners of the region they span in the contact
/// plane are kept: a point inside it, or within `support_slack` (relative to the smaller shape's
/// size) of the line through its neighbours on its outline, is dropped (it adds no contact wrench
/// the corners cannot give; engine/manifold.cpp, support_corners), except the deepest point when
/// it is deeper than every corner by more than the slack. When no point qualifies (a face
/// centroid inside, no vertex), the centre of the contact region on the plane
/// (engine/contact_region.h) is the manifold. Either body order gives the same points.
/// The detector runs on `cache` and the plane on `scratch`, the caller's (a world's step keeps
/// one of each); the answer does not depend on them.
std::optional<ContactManifold> build_manifold(const ConvexPolyhedron& a, const Pose& pa,
                                              const ConvexPolyhedron& b, const Pose& pb,
                                              DetectorVariant variant, double support_slack,
                                              DetectionCache& cache, ContactScratch& scratch);

/// The same on a cache and scratch of its own (allocated for the one query: tests and tools).
std::optional<ContactManifold> build_manifold(const ConvexPolyhedron& a, const Pose& pa,
                                              const ConvexPolyhedron& b, const Pose& pb,
                                              DetectorVariant variant,
                                              double support_slack = WorldSettings{}.position_slop);

}  // namespace rbx
