// What a body's shape and mass fix for a whole run: the figures the step and the time of impact
// would otherwise recompute from its vertices, faces and inertia at every use.
#pragma once

#include "engine/body.h"
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

  /// The facts of `body`.
  static BodyFacts of(const RigidBody& body);
};

}  // namespace rbx
