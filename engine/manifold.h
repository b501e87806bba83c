// Contact manifold: every contact point of a pair, with one normal: the extended engine's
// contact pipeline, the same for its world's step and for its contact query.
//
// Departure from the seed, which resolves the first face / vertex / edge hit (or an average of
// one kind) as a single point (seed correction 12 (what the seed admits it lacks) names a
// contact plane from the detector as future work). Four stages (docs/contact_plane.md):
//   1. the features in contact: an overlap proved by the plane search, else the detector's hit
//      (Moore & Wilhelms, engine/detect.h);
//   2. the chosen plane (engine/contact_plane.h): the direction of least overlap;
//   3. the patch clipped on it (engine/contact_region.h): the incident face cut to the
//      reference face, its corners at or below the reference plane, each with its own depth;
//   4. the reduction (support_corners): the corners that span the patch.
// A face-face landing then has its four corners, not one averaged point; no stage visits every
// vertex, so the cost follows the features in contact, not the size of the hulls.
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

/// Every contact point of one pair, sharing one normal (engine/contact.h convention: from B
/// toward A).
struct ContactManifold {
  Vec3 normal = Vec3::UnitZ();        // unit, world, from B toward A
  double depth = 0.0;                 // m, overlap of the two shapes along the normal
  ContactPoint contact;               // the pair's one-point contact (find_contact's answer)
  std::vector<ManifoldPoint> points;  // at least one
};

/// The manifold of A and B at their poses, or nothing when they do not touch (find_contact finds
/// nothing). The normal and depth are the chosen plane's; `contact` is find_contact's one point;
/// the points are the contact patch (contact_region_centre) with points closer than 1e-7 of the
/// larger shape's size merged, reduced to the corners of the region they span in the contact
/// plane: a point inside it, or within `support_slack` (relative to the smaller shape's size) of
/// the line through its neighbours on its outline, is dropped (it adds no contact wrench the
/// corners cannot give; engine/manifold.cpp, support_corners), except the deepest point when it
/// is deeper than every corner by more than the slack. Either body order gives the same points.
/// The detector runs on `cache` and the plane on `scratch`, the caller's (a world's step keeps
/// one of each); the answer does not depend on them.
std::optional<ContactManifold> build_manifold(const ConvexPolyhedron& a, const Pose& pa,
                                              const ConvexPolyhedron& b, const Pose& pb,
                                              Detector detector, double support_slack,
                                              DetectionCache& cache, ContactScratch& scratch);

/// The same into `out`, whose lists are reused (a caller that queries again allocates nothing
/// once they have grown); false, and `out` unspecified, when A and B do not touch.
bool build_manifold(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                    const Pose& pb, Detector detector, double support_slack, DetectionCache& cache,
                    ContactScratch& scratch, ContactManifold& out);
/// The same on a cache and scratch of its own (allocated for the one query: tests and tools).
std::optional<ContactManifold> build_manifold(const ConvexPolyhedron& a, const Pose& pa,
                                              const ConvexPolyhedron& b, const Pose& pb,
                                              Detector detector,
                                              double support_slack = WorldSettings{}.position_slop);

}  // namespace rbx
