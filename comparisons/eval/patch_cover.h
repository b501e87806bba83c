// How much of the contact a backend's set of points describes, against the exact contact patch
// (docs/contact_manifold.md): every point's distance from the true contact region, how far the
// points' hull falls short of the patch (coverage), and whether that hull holds each body's
// centre where the patch does (the support polygon). Pure functions of shapes and points, so
// each rule is tested by hand (tests/comparisons/patch_cover_test.cpp).
#pragma once

#include <optional>
#include <vector>

#include "engine/body.h"
#include "engine/contact.h"
#include "reference/backend.h"
#include "reference/exact.h"

namespace rbx {

/// A set of contact points measured against the true patch.
struct PatchCover {
  int points = 0;  // points the backend returned for the pair
  /// m: the largest contact_point_error over the points (the worst point, where the metric
  /// point_err_rel scores the deepest one).
  double worst_point_err = 0.0;
  /// m: the largest distance, in the contact plane, from a corner of the true patch to the
  /// convex hull of the points projected on that plane; 0 when the points span the patch.
  double coverage_err = 0.0;
  /// 1 when, for some moving body of the pair, the points' hull holds the projection of its
  /// centre of mass along the normal and the true patch does not, or the other way round; 0 when
  /// they agree; empty when not measured (the patch has no area, or a centre lies on the patch's
  /// outline within round-off, where either answer is right). Held means inside by more than
  /// round-off: a point or a segment holds nothing, as it cannot keep a body from tipping.
  std::optional<double> support_err;
};

/// Measures `points` (a backend's answer for A and B) against `patch`, the exact oracle's contact
/// polygon (or segment, or point) for the pair, whose normal is `normal`. Coverage is measured
/// in the plane across the normal, so that a library placing its points on A's surface, on B's
/// or midway (the conventions differ, docs/contact_manifold.md) is not penalised for it; the
/// depth those heights carry is scored by the point and depth metrics. `points` must not be
/// empty, nor `patch`.
PatchCover patch_cover(const std::vector<ContactPoint>& points, const RigidBody& a,
                       const RigidBody& b, const std::vector<Vec3>& patch, const Vec3& normal);

/// The exact patch an answer is measured against: the oracle's (`sat.manifold`, across
/// `sat.normal`), or, where the answer's deepest normal is another axis tied for the least
/// overlap (a cube on another's diagonal: x, y and z are equally right), that axis's patch
/// across it (sat_patch_along), so that a right choice among ties is not scored as a miss.
/// `sat` must be touching with a patch.
SatPatch true_patch(const ContactResult& r, const RigidBody& a, const RigidBody& b,
                    const SatResult& sat);

/// Distance (m), in the plane across the unit `normal`, from `p` to the convex hull of `set`
/// projected on that plane: 0 inside it (or on its outline). `set` must not be empty.
double distance_to_hull_across(const Vec3& p, const std::vector<Vec3>& set, const Vec3& normal);

}  // namespace rbx
