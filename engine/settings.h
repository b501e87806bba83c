// Every numerical tunable of the extended engine's step, in one place (after Jolt's
// PhysicsSettings.h): the contact solver's convergence and caps, the position projection, the
// time-of-impact candidates and the broad phase's choice of index. The defaults are the values
// every result so far was computed with; each field says its unit and why it has that value.
#pragma once

#include <cstddef>

namespace rbx {

/// Tunables of the world step (engine/world.h) and the stages it calls. Scene physics
/// (restitution, friction, gravity, dt) is not here: it comes from the scene (SimSettings).
struct WorldSettings {
  // Resting contact (ExtendedStep::solver_settings).

  /// Steps of gravity: an approach no faster than this many steps of gravity (m/s, this many
  /// times |g| dt) is a body settling, not a collision, and gets e = 0; else a resting body with
  /// e > 0 bounces by e g dt for ever. Zero without gravity: every approach is then a
  /// collision, as in the seed.
  double rest_gravity_steps = 2.0;

  // Contact solver (engine/contact_solver.cpp).

  /// Relative: an iteration that changes no point's velocity by more than this fraction of the
  /// island's largest speed is a fixed point to round-off (the seed's closed forms are checked
  /// to 1e-9; 1e-14 leaves five digits).
  double convergence = 1e-14;
  /// Projected Gauss-Seidel iterations of one stage at most: bounds pathological graphs (a chain of
  /// n bodies converges in O(n^2) iterations).
  int max_iterations = 10000;
  /// Rounds of the two stages (normal, then friction) at most, for the same reason.
  int max_stage_rounds = 100;
  /// Iterations of one island solve at most, both stages and every round together; 0: no budget,
  /// the solve runs to convergence within the caps above (the engine's only mode). The
  /// iteration budget other engines expose, kept for comparison: the report steps it through
  /// with theirs (reference/custom.cpp, custom_budget); the active sets come first either way.
  long iteration_budget = 0;
  /// Relative: two iterations that moved the impulses by the same vector to this fraction of its
  /// size are a steady drift, taken at once up to the first bound (solve_island).
  double drift_match = 1e-9;

  // Position projection (project_contact_positions).

  /// Fraction of a point's penetration beyond the slop removed per iteration (Box2D's
  /// b2_baumgarte).
  double baumgarte = 0.2;
  /// Iterations per step: with `baumgarte` they remove 1 - 0.8^4 = 59 % of a penetration per
  /// step, fast enough that a landing at v leaves at most ~v dt, not so fast that a deep start
  /// is thrown apart in one step.
  int position_iterations = 4;
  /// Relative to the smaller body's size (bounding box diagonal): penetration left alone, so
  /// touching contacts stay touching (the detector sees them next step); 10x under the 0.1 % of
  /// a body the issue allows at rest.
  double position_slop = 1e-4;

  // Time of impact (ExtendedStep::time_of_impact_step).

  /// Relative to the thinnest body's thickness: a body sweeping less than this in a step asks
  /// for no time of impact (the faster body of a candidate pair always sweeps more).
  double toi_body_sweep = 0.125;
  /// Relative to the thinner body's thickness: a pair whose relative sweep is at most this is
  /// left to the next step's detection after penetration (nothing can pass through).
  double toi_pair_sweep = 0.25;
  /// Samples one time-of-impact search may take in a step (time_of_impact); a search that
  /// needs more stops the run, saying so, rather than pass a step it cannot certify.
  long toi_max_samples = 1000000;

  // Broad phase (engine/broadphase.cpp); the pairs are the same whatever these say.

  /// Room to move, relative to the median bounding radius of the moving bodies: the broad phase
  /// keeps the pairs of spheres grown by it and reuses them until a centre moves that far
  /// (0: a new index on every call).
  double pair_cache_margin = 0.1;
  /// Moving bodies at least for the uniform grid: below, the tree is as cheap.
  int grid_min_moving = 64;
  /// Static bodies at most kept out of the tree (queried against it instead): a few walls and
  /// a floor would widen its nodes; more (a static terrain) go into the tree with the rest.
  std::size_t statics_apart = 32;
};

}  // namespace rbx
