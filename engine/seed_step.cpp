#include "engine/seed_step.h"

#include <stdexcept>

#include "engine/bounding.h"
#include "engine/integrate.h"

namespace rbx {

void SeedStep::advance(WorldState& world) {
  // Bounding check, detection and response, in index order (deterministic). Responses change
  // velocities only, never poses, so the pairs passing the bounding check are fixed for the
  // whole step and the broad phase can find them all first; it returns them in the seed's
  // (i, j) order, so the contacts are resolved in the same order as by the double loop.
  if (world.broad_phase.method() == BroadPhaseMethod::AllPairs) {
    // The seed's double loop, kept as it was (the reference of the broad phase).
    const int n = static_cast<int>(world.bodies.size());
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) collide_pair(world, i, j, false);
  } else {
    for (const BodyPair& pair : world.broad_phase.find_pairs(world.bodies))
      collide_pair(world, pair.first, pair.second, true);
  }
  for (size_t i = 0; i < world.bodies.size(); ++i)
    integrate(world.bodies[i], world.sim, world.sim.dt, &world.facts[i].principal);
}

void SeedStep::collide_pair(WorldState& world, int i, int j, bool bounded) {
  RigidBody& a = world.bodies[i];
  RigidBody& b = world.bodies[j];
  if (a.is_static && b.is_static) return;
  if (!bounded && !bounding_check(a, b)) return;
  // The seed's order: face, vertex, edge; each resolved as soon as it hits. After the first
  // impulse the pair separates at the contact, so later hits add an impulse only if the new
  // velocities still approach at their own point.
  // Responses change velocities only, so the pair is placed once for the three tests.
  detection_.prepare(*a.shape, a.pose(), *b.shape, b.pose(), world.detector);
  for (Feature feature : {Feature::Face, Feature::Vertex, Feature::Edge}) {
    const auto contact = detection_.test(feature);
    if (!contact) continue;
    if (response_) {
      // A researcher's response (set_response): its impulse vector, applied as given.
      const Vec3 impulse = response_(a, b, *contact, world.sim.restitution);
      if (!impulse.allFinite())
        throw std::runtime_error("the response returned a non-finite impulse");
      if (impulse.isZero(0.0)) continue;
      apply_impulse_at(a, b, contact->point, impulse);
      world.step_contacts.push_back(
          {i, j, contact->point, contact->normal, contact->depth, impulse, a.position, b.position});
      world.add_event(i, j, *contact, impulse.dot(contact->normal), world.time);
      continue;
    }
    const double j_mag = apply_impulse(a, b, *contact, world.sim.restitution);
    if (!(j_mag > 0.0)) continue;
    // Only the hits that pushed: a later test's hit on a separating pair carries a depth the
    // seed never uses.
    world.step_contacts.push_back({i, j, contact->point, contact->normal, contact->depth,
                                   j_mag * contact->normal, a.position, b.position});
    world.add_event(i, j, *contact, j_mag, world.time);
  }
}

}  // namespace rbx
