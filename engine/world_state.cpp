#include "engine/world_state.h"

#include <utility>

namespace rbx {

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
