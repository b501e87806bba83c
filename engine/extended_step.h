// The extended engine's step (the `custom` backend): the seed's bounding check and Moore &
// Wilhelms detector, then contact manifolds, simultaneous impulses with Coulomb friction and
// resting contact (engine/contact_solver.h), time of impact for every new contact, integration
// and position projection.
#pragma once

#include <optional>
#include <unordered_map>
#include <vector>

#include "engine/broadphase.h"
#include "engine/contact_solver.h"
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
  // Integrates every body the time of impact did not carry (`moved`) through the step.
  static void integrate_bodies(WorldState& world, const std::vector<bool>& moved);
  // True when the pair (i, j) is proved apart (the detector would find nothing): by its kept
  // axis, else by a new one, which is then kept.
  bool separated(const WorldState& world, int i, int j);

  // The second broad phase, on the poses at the step's end (new contacts).
  BroadPhase ahead_broad_phase_;
  std::vector<RigidBody> ahead_;  // scratch: the bodies moved to the step's end
  // Per pair (key i * bodies + j) that passed the bounding check but was found apart: the axis
  // that proved it (engine/separation.h), in b's frame, tried first at the next step.
  std::unordered_map<long long, Vec3> witnesses_;
};

}  // namespace rbx
