#include "engine/body_facts.h"

#include <algorithm>

#include "engine/detect.h"
#include "engine/separation.h"
#include "engine/time_of_impact.h"

namespace rbx {

BodyFacts BodyFacts::of(const RigidBody& body) {
  const ConvexPolyhedron& shape = *body.shape;
  BodyFacts f;
  f.thickness = shape_thickness(shape);
  for (const Vec3& v : shape.vertices()) f.radius = std::max(f.radius, v.norm());
  f.reach = tolerance_reach(shape);
  f.own_tol = point_in_mesh_tolerance(shape, shape);
  f.principal = principal_frame(body.inertia_body);
  f.turn_rate = free_turn_rate(f.principal);
  f.sphere_centre = shape.bounds().center();
  f.sphere_radius = shape.bounds().half_extents().norm();
  f.centre_reach = std::max(f.radius, f.sphere_centre.norm());
  return f;
}

}  // namespace rbx
