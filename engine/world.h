// The world: bodies stepped by one of two contact models (ContactModel), each a class of its
// own (engine/seed_step.h, engine/extended_step.h) over the state they share
// (engine/world_state.h), with the health guard that checks every step.
#pragma once

#include <string>
#include <vector>

#include "engine/body.h"
#include "engine/broadphase.h"
#include "engine/contact_solver.h"
#include "engine/detect.h"
#include "engine/extended_step.h"
#include "engine/response.h"
#include "engine/seed_step.h"
#include "engine/settings.h"
#include "engine/world_definition.h"
#include "engine/world_state.h"

namespace rbx {

/// Outcome of a whole run.
struct RunResult {
  bool ok = true;
  std::string message;  // why the run stopped early, when !ok
  long steps_taken = 0;
  std::vector<CollisionEvent> events;
  std::vector<RigidBody> bodies;  // final states
};

/// A set of bodies stepped by one of two contact models (ContactModel): the seed's algorithm
/// (`custom-seed`) or the extended engine's (`custom`), named by whoever builds the world.
class World {
 public:
  /// `model` is the contact model every step uses: Seed, the seed's single-point impulse;
  /// Extended, manifolds, friction, resting contact and time of impact (engine/extended_step.h).
  /// `broad_phase` chooses how the pairs passing the bounding check are found; every method
  /// finds the same pairs and the world resolves them in the seed's (i, j) order, so results
  /// do not depend on it (AllPairs is the seed's double loop). `tunables`: the broad phase's
  /// settings and the extended step's solver, projection and time-of-impact ones
  /// (engine/settings.h).
  World(SimSettings sim, std::vector<RigidBody> bodies, ContactModel model,
        Detector detector = Detector::Accelerated,
        BroadPhaseMethod broad_phase = BroadPhaseMethod::Tree,
        const WorldSettings& tunables = WorldSettings());

  /// Advances one step of sim.dt with the chosen contact model (SeedStep::advance or
  /// ExtendedStep::advance), then checks the state. Returns false (and sets failure()) when the
  /// state became non-finite or the energy grew past sim.max_energy_ratio; the world must not
  /// be stepped further then.
  bool step();
  /// Runs until `duration`, stopping early (ok = false) on a non-finite state or runaway energy.
  RunResult run();
  /// Why the last step failed ("" while healthy): names the body, the step and the quantity.
  const std::string& failure() const { return failure_; }
  /// Steps taken so far.
  long steps_taken() const { return state_.step; }
  /// Seed model only: each hit is resolved by `response` instead of the seed's single-point
  /// impulse (a researcher's own response, engine/response.h); an empty function restores it.
  /// An event is recorded for every non-zero impulse, with its normal component as `impulse`;
  /// a non-finite impulse throws std::runtime_error (step() and run() pass it on).
  void set_response(ResponseFn response) { seed_.set_response(std::move(response)); }

  /// The bodies in their current state, in scene order.
  const std::vector<RigidBody>& bodies() const { return state_.bodies; }
  /// Every collision resolved so far, in order.
  const std::vector<CollisionEvent>& events() const { return state_.events; }
  /// Every contact point the last step solved, with its impulse (empty before the first step).
  const std::vector<SolvedContact>& step_contacts() const { return state_.step_contacts; }
  /// Simulated time (s) reached.
  double time() const { return state_.time; }
  /// Total kinetic plus gravitational potential energy (J).
  double energy() const;

 private:
  // The health guard after each step: every state finite, the energy within its budget.
  bool check_state();

  WorldState state_;
  ContactModel contact_model_;
  SeedStep seed_;
  ExtendedStep extended_;
  std::string failure_;
  double energy0_ = 0.0;       // J, total energy at t = 0
  double energy_scale_ = 0.0;  // J, the energy budget the guard compares growth with
};

/// Builds every body of the definition and runs it with the given contact model.
RunResult run_world(const WorldDefinition& definition, ContactModel model,
                    Detector detector = Detector::Accelerated,
                    BroadPhaseMethod broad_phase = BroadPhaseMethod::Tree);

}  // namespace rbx
