// What a body's shape and mass fix for a whole run: the figures the step and the time of impact
// would otherwise recompute from its vertices, faces and inertia at every use.
#pragma once

#include "engine/body.h"
#include "engine/bounding.h"
#include "engine/integrate.h"

namespace rbx {

/// What a body's shape and mass fix for the whole run.
struct BodyFacts {
  double thickness = 0.0;    // m, shape_thickness: what a fast body must not pass through
  double radius = 0.0;       // m, bounding radius about the centre of mass
  double reach = 1.0;        // m, how far the detector's tolerance reaches beyond it
  double own_tol = 0.0;      // m, its point-in-mesh tolerance against itself (1e-9 x its size)
  PrincipalFrame principal;  // its inertia's principal frame (the free rotation's)
  double turn_rate = 0.0;    // 1 / (kg m^2), free_turn_rate(principal)
  // The bounding sphere's centre in the body frame (its box's centre) and radius (m).
  Vec3 sphere_centre = Vec3::Zero();
  double sphere_radius = 0.0;
  // m, how far from the centre of mass the body's points and its sphere's centre lie: what a
  // travel bound's radius must cover.
  double centre_reach = 0.0;

  /// The facts of `body`.
  static BodyFacts of(const RigidBody& body);
};

/// bounding_sphere(body), bit for bit, from the body's facts: a crowd's spheres without reading
/// its shapes (a thousand shapes do not stay in cache).
inline BoundingSphere bounding_sphere(const RigidBody& body, const BodyFacts& facts) {
  return {body.pose().apply(facts.sphere_centre), facts.sphere_radius};
}

}  // namespace rbx
