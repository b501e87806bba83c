// The extended engine's step (the `custom` backend): the seed's bounding check and Moore &
// Wilhelms detector, then contact manifolds, simultaneous impulses with Coulomb friction and
// resting contact (engine/contact_solver.h), time of impact for every new contact, integration
// and position projection.
#pragma once

#include <optional>
#include <vector>

#include "engine/broadphase.h"
#include "engine/contact_scratch.h"
#include "engine/contact_solver.h"
#include "engine/detect.h"
#include "engine/pair_table.h"
#include "engine/time_of_impact.h"
#include "engine/world_state.h"

namespace rbx {

/// The extended engine's contact model, one step at a time.
class ExtendedStep {
 public:
  /// `tunables`: the settings of its second broad phase (the poses at the step's end).
  explicit ExtendedStep(const WorldSettings& tunables);
  /// One step of sim.dt as a list of stages: detect, approach velocities, forces, solve,
  /// events, time of impact, integrate, project.
  void advance(WorldState& world);

 private:
  // One manifold per pair passing the bounding check, not proved apart, at the step's poses.
  std::vector<PairManifold> detect_manifolds(WorldState& world);
  // The solver's settings for this step: the scene's restitution and friction, the resting
  // threshold, the world's tunables.
  static ContactSolverSettings solver_settings(const WorldState& world);
  // Appends one event per manifold whose total normal impulse is positive (with `rest_speed`,
  // only those with a point approaching faster): the impulse at its centre of pressure, at
  // `time`. Returns every manifold's total normal impulse (N s).
  static std::vector<double> record_events(WorldState& world,
                                           const std::vector<PairManifold>& manifolds,
                                           const std::vector<SolvedPoint>& solved, double time,
                                           std::optional<double> rest_speed);
  // Time of impact within the step for pairs apart at its start: moves, resolves and finishes
  // the step for each such pair; returns which bodies it carried through the step.
  std::vector<bool> time_of_impact_step(WorldState& world,
                                        const std::vector<PairManifold>& manifolds,
                                        const ContactSolverSettings& settings);
  // Integrates every body the time of impact did not carry (`moved`) through the step; with the
  // symplectic scheme, takes the move from `ahead` (the bodies at the step's end) when given.
  static void integrate_bodies(WorldState& world, const std::vector<bool>& moved,
                               const std::vector<RigidBody>* ahead);
  // True when bodies i and j, as `a` and `b` (at the step's start, or moved to its end), are
  // proved apart (the detector would find nothing): by their world boxes; with `travel` (m, the
  // two bodies' travel over the step, for poses at its end), by the gap kept this step at its
  // start less that travel; by the pair's kept axis; else by a new one, which is then kept.
  bool separated(const WorldState& world, const RigidBody& a, const RigidBody& b, int i, int j,
                 double travel = -1.0);

  // For a pair the axes do not prove apart at the step's end (a, b moved there; the start poses
  // in `world`): true when the distance proves it apart at the end and, with the gap at the
  // start, through the whole step (the detector, with `margin`, finds nothing anywhere); the
  // end's direction is kept as the pair's axis, and the end's distance in end_distance_.
  bool apart_through_step(const WorldState& world, const RigidBody& a, const RigidBody& b, int i,
                          int j, double margin);

  // The growth of the bounding spheres (m) for one broad phase serving both the step's start and
  // its end (the look-ahead): twice the farthest any body's sphere centre reaches at its start
  // velocity; 0 (two broad phases) under the seed's Euler or when that is not small beside the
  // smallest body.
  static double look_ahead_growth(const WorldState& world);
  // The pairs whose spheres touch at the step's end (ahead_): the start's grown pairs filtered,
  // or the look-ahead broad phase when a sphere centre moved too far for them (by rates_, this
  // step's).
  const std::vector<BodyPair>& look_ahead_pairs(const WorldState& world);
  // Places a world box around each of `bodies` (the set separated() is asked about next): a
  // moving body's is its bounding ball's about the centre of mass, a static body's the box of its
  // world vertices (computed once: a static body never moves).
  void place_boxes(const std::vector<RigidBody>& bodies, const std::vector<BodyFacts>& facts);

  // The second broad phase, on the poses at the step's end (new contacts).
  BroadPhase ahead_broad_phase_;
  // The bodies moved to the step's end; kept from step to step (each step refreshes what it
  // moves), and filled (`ahead_filled_`) by the symplectic scheme's time of impact: at a step's
  // start, the last step's.
  std::vector<RigidBody> ahead_;
  bool ahead_filled_ = false;
  // The distance at the step's end of the last pair apart_through_step was asked about (none
  // when separated() did not reach it): the time of impact's own sample there, handed over.
  std::optional<Separation> end_distance_;
  // What proved a pair apart (engine/separation.h): the axis, in b's frame, tried first at the
  // next test; the gap along it (m) and the step (steps_) at which it was measured (or bounded
  // from below). `end_gap`: a lower bound on the gap at the end of step `end_step`, along the
  // world direction the gap was last measured along; while nothing but the step's own motion
  // moves the bodies (their travel covers it), a bound along a fixed direction stays one.
  struct Witness {
    Vec3 axis = Vec3::UnitZ();
    double gap = 0.0;
    long step = -1;
    double end_gap = 0.0;
    long end_step = -1;
  };
  // Per pair (key i * bodies + j) that passed the bounding check but was found apart.
  PairTable<Witness> witnesses_;
  long steps_ = 0;                     // steps advanced: stamps the witnesses measured in this one
  std::vector<Vec3> box_lo_, box_hi_;  // m, world: place_boxes' boxes
  double grow_ = 0.0;                  // m, this step's growth (look_ahead_growth)
  std::vector<BodyPair> grown_pairs_;  // the start's pairs of spheres grown by grow_
  std::vector<BodyPair> ahead_pairs_;  // scratch: look_ahead_pairs' output
  std::vector<BodyPair> touching_;     // scratch: the pairs with a manifold at the step's start
  std::vector<BoundingSphere> spheres_;  // scratch: one pose's bounding spheres
  std::vector<TravelRate> rates_;        // scratch: the bodies' travel rates after the step's solve
  std::vector<char> unmoved_;            // per body: at its pose in ahead_ from the last step
  std::vector<Vec3> static_lo_, static_hi_;  // m, world: the static bodies' boxes, once
  // The manifolds' detector cache and contact-plane scratch, reused pair after pair.
  DetectionCache detection_;
  ContactScratch contact_scratch_;
};

}  // namespace rbx
