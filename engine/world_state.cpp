#include "engine/world_state.h"

#include <algorithm>

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
  return f;
}

WorldState::WorldState(SimSettings sim_settings, std::vector<RigidBody> start, Detector detector,
                       BroadPhaseMethod broad_phase_method, const WorldSettings& world_tunables)
    : sim(std::move(sim_settings)),
      bodies(std::move(start)),
      detector(detector),
      tunables(world_tunables),
      broad_phase(broad_phase_method, world_tunables) {
  for (const RigidBody& b : bodies) facts.push_back(BodyFacts::of(b));
}

}  // namespace rbx
