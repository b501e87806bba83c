// What every contact model steps: the bodies, the clock, the collisions resolved so far, and
// what is fixed per body. World owns it; SeedStep and ExtendedStep advance it by one step.
#pragma once

#include <string>
#include <vector>

#include "engine/body.h"
#include "engine/body_facts.h"
#include "engine/broadphase.h"
#include "engine/contact.h"
#include "engine/detect.h"
#include "engine/integrate.h"
#include "engine/settings.h"
#include "engine/world_definition.h"

namespace rbx {

/// One resolved collision: a detection that applied a non-zero impulse.
struct CollisionEvent {
  double time = 0.0;  // s, start of the step in which it was detected
  long step = 0;
  std::string body_a, body_b;
  ContactPoint contact;  // normal from body_b toward body_a
  double impulse = 0.0;  // N s, magnitude j along the normal
};

/// One contact point as a step's solve left it: the impulse it applied and where, so that the
/// contact laws can be checked on it (the comparisons' contact-law residuals).
struct SolvedContact {
  int a = 0, b = 0;              // body indices, scene order
  Vec3 point = Vec3::Zero();     // m, world, at detection
  Vec3 normal = Vec3::UnitZ();   // unit, world, from b toward a
  double depth = 0.0;            // m, >= 0, the point's penetration at detection
  Vec3 impulse = Vec3::Zero();   // N s, on a (normal and friction); b takes the opposite
  Vec3 centre_a = Vec3::Zero();  // m, a's centre of mass at detection
  Vec3 centre_b = Vec3::Zero();  // m, b's centre of mass at detection
};

/// The state both contact models advance, step by step.
struct WorldState {
  /// Places the bodies at t = 0, with their facts and the broad phase built from `tunables`.
  WorldState(SimSettings sim, std::vector<RigidBody> bodies, Detector detector,
             BroadPhaseMethod broad_phase, const WorldSettings& tunables);

  SimSettings sim;
  std::vector<RigidBody> bodies;  // in scene order
  std::vector<BodyFacts> facts;   // per body, in the same order
  Detector detector;
  WorldSettings tunables;
  BroadPhase broad_phase;  // the pairs passing the bounding check, at the step's start poses
  std::vector<CollisionEvent> events;        // every collision resolved so far, in order
  double time = 0.0;                         // s, at the start of the step being taken
  long step = 0;                             // steps taken
  std::vector<SolvedContact> step_contacts;  // every contact point the last step solved
  /// Why the last step cannot vouch for its result ("" when it can): a time of impact whose
  /// search stopped uncertified. The world's guard stops the run on it.
  std::string uncertain;

  /// Records a collision of bodies i and j resolved at `time` with normal impulse `impulse`
  /// (N s): the one place both contact models build an event.
  void add_event(int i, int j, const ContactPoint& contact, double impulse, double at) {
    events.push_back({at, step, bodies[i].name, bodies[j].name, contact, impulse});
  }
};

}  // namespace rbx
