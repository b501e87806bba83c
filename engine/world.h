// The world step: broad phase (the bounding check), detection, response, integration.
#pragma once

#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/body.h"
#include "engine/broadphase.h"
#include "engine/contact.h"
#include "engine/contact_solver.h"
#include "engine/detect.h"
#include "engine/integrate.h"
#include "engine/response.h"
#include "engine/scene.h"
#include "engine/separation.h"
#include "engine/settings.h"

namespace rbx {

/// One resolved collision: a detection that applied a non-zero impulse.
struct CollisionEvent {
  double time = 0.0;  // s, start of the step in which it was detected
  long step = 0;
  std::string body_a, body_b;
  ContactPoint contact;  // normal from body_b toward body_a
  double impulse = 0.0;  // N s, magnitude j along the normal
};

/// Outcome of a whole run.
struct RunResult {
  bool ok = true;
  std::string message;  // why the run stopped early, when !ok
  long steps_taken = 0;
  std::vector<CollisionEvent> events;
  std::vector<RigidBody> bodies;  // final states
};

/// A set of bodies stepped by one of two contact models (ContactModel): the seed's algorithm
/// (the default) or the extended engine's.
class World {
 public:
  /// `broad_phase` chooses how the pairs passing the bounding check are found; every method
  /// finds the same pairs and the world resolves them in the seed's (i, j) order, so results
  /// do not depend on it (AllPairs is the seed's double loop). `tunables`: the broad phase's
  /// settings and the extended step's solver, projection and time-of-impact ones
  /// (engine/settings.h).
  World(SimSettings sim, std::vector<RigidBody> bodies,
        DetectorVariant variant = DetectorVariant::Accelerated,
        BroadPhaseMethod broad_phase = BroadPhaseMethod::Tree,
        const WorldSettings& tunables = WorldSettings());

  /// Advances one step of sim.dt with the chosen contact model.
  ///  - Seed: for every pair passing the bounding check (in (i, j) order), the face, vertex
  ///    and edge tests in that order, resolving each hit by a single-point frictionless
  ///    impulse; then integration of every body.
  ///  - Extended (world_extended.cpp): one manifold per pair passing the bounding check and not
  ///    proved apart; this step's forces; simultaneous impulses with Coulomb friction and
  ///    resting contact (engine/contact_solver.h); one event per colliding manifold; time of
  ///    impact for pairs the step would bring into contact; integration; position projection
  ///    of the pairs that pressed together.
  /// Returns false (and sets failure()) when the state became non-finite or the energy grew
  /// past sim.max_energy_ratio; the world must not be stepped further then.
  bool step();
  /// Runs until `duration`, stopping early (ok = false) on a non-finite state or runaway energy.
  RunResult run();
  /// Why the last step failed ("" while healthy): names the body, the step and the quantity.
  const std::string& failure() const { return failure_; }
  /// Steps taken so far.
  long steps_taken() const { return step_; }
  /// Chooses the response (default Seed: the seed's single-point impulse). Extended: manifolds,
  /// friction, resting contact, time of impact (engine/contact_solver.h, world_extended.cpp).
  void set_contact_model(ContactModel model) { contact_model_ = model; }
  /// Seed model only: each hit is resolved by `response` instead of the seed's single-point
  /// impulse (a researcher's own response, engine/response.h); an empty function restores it.
  /// An event is recorded for every non-zero impulse, with its normal component as `impulse`;
  /// a non-finite impulse throws std::runtime_error (step() and run() pass it on).
  void set_response(ResponseFn response) { response_ = std::move(response); }

  /// The bodies in their current state, in scene order.
  const std::vector<RigidBody>& bodies() const { return bodies_; }
  /// Every collision resolved so far, in order.
  const std::vector<CollisionEvent>& events() const { return events_; }
  /// Simulated time (s) reached.
  double time() const { return time_; }
  /// Total kinetic plus gravitational potential energy (J).
  double energy() const;

 private:
  // Detection and response for bodies i and j; `bounded`: the pair already passed the
  // bounding check.
  void collide_pair(int i, int j, bool bounded);
  bool check_state();
  // The seed's detection, response and integration for one step.
  void step_seed();
  // The extended engine's detection, response and integration for one step
  // (engine/world_extended.cpp), and its stages in the order it calls them.
  void step_extended();
  // One manifold per pair passing the bounding check, not proved apart, at the step's poses.
  std::vector<PairManifold> detect_manifolds();
  // The solver's settings for this step: the scene's restitution and friction, the resting
  // threshold, the world's tunables.
  ContactSolverSettings solver_settings() const;
  // Appends one event per manifold whose total normal impulse is positive (with `rest_speed`,
  // only those with a point approaching faster): the impulse at its centre of pressure, at
  // `time`. Returns every manifold's total normal impulse (N s).
  std::vector<double> record_events(const std::vector<PairManifold>& manifolds,
                                    const std::vector<SolvedPoint>& solved, double time,
                                    std::optional<double> rest_speed);
  // Time of impact within the step for pairs separated at its start: moves, resolves and
  // finishes the step for each such pair; returns which bodies it carried through the step.
  std::vector<bool> time_of_impact_step(const std::vector<PairManifold>& manifolds,
                                        const ContactSolverSettings& settings);
  // Integrates every body the time of impact did not carry (`moved`) through the step.
  void integrate_bodies(const std::vector<bool>& moved);

  SimSettings sim_;
  std::vector<RigidBody> bodies_;
  DetectorVariant variant_;
  DetectionCache detection_;  // the pair being resolved: placed once per pair per step
  ContactModel contact_model_ = ContactModel::Seed;
  ResponseFn response_;     // empty: the seed's impulse
  WorldSettings tunables_;  // before the broad phases, which are built from it
  BroadPhase broad_phase_;
  // The extended step's second broad phase, on the poses at the step's end (new contacts).
  BroadPhase ahead_broad_phase_;
  std::vector<RigidBody> ahead_;  // scratch: the bodies moved to the step's end
  std::vector<CollisionEvent> events_;
  double time_ = 0.0;
  long step_ = 0;
  std::string failure_;
  double energy0_ = 0.0;       // J, total energy at t = 0
  double energy_scale_ = 0.0;  // J, the energy budget the guard compares growth with
  // Per body, fixed by its shape and mass: thickness (shape_thickness), bounding radius about
  // the centre of mass, how far the detector's tolerance reaches beyond it (tolerance_reach),
  // its point-in-mesh tolerance against itself (1e-9 x its size), and its inertia's principal
  // frame (the free rotation's). Filled on first use.
  struct ShapeFacts {
    double thickness = 0.0, radius = 0.0, reach = 1.0, own_tol = 0.0;
    PrincipalFrame principal;
  };
  std::vector<ShapeFacts> facts_;
  const std::vector<ShapeFacts>& shape_facts();
  // Per pair (key i * bodies + j) that passed the bounding check but was found apart: the axis
  // that proved it (engine/separation.h), in b's frame, tried first at the next step.
  std::unordered_map<long long, Vec3> witnesses_;
  // True when the pair (i, j) is proved apart (the detector would find nothing): by its kept
  // axis, else by a new one, which is then kept.
  bool separated(int i, int j);
};

/// Builds every body of the scene and runs it with the custom engine (the seed's contact model).
RunResult run_scene(const Scene& scene, DetectorVariant variant = DetectorVariant::Accelerated,
                    BroadPhaseMethod broad_phase = BroadPhaseMethod::Tree);

}  // namespace rbx
