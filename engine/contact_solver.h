// Simultaneous contact response over manifolds: Newton restitution, Coulomb friction (exact
// cone), resting contact, and position projection. The extended engine's answer to what the
// seed admits it lacks (seed correction 12 (what the seed admits it lacks): resting contact
// and friction).
//
// Design note. Of the two resting-contact schemes the issue names, sequential impulses to
// convergence (projected Gauss-Seidel on accumulated impulses, Catto 2005; the velocity-level
// LCP it solves is that of Anitescu & Potra 1997) is chosen over a direct LCP solver: it handles
// the exact friction cone (a pivoting LCP needs a pyramid), costs nothing for the many pairs
// with one or two points, and is run to convergence, so the answer does not depend on an
// iteration count. Gravity is added to the velocities before the solve (the order of
// Guendelman, Bridson & Fedkiw 2003: velocity update, then contact, then positions), so a body
// at rest ends its step at rest instead of carrying -g dt into the next one.
#pragma once

#include <vector>

#include "engine/body.h"
#include "engine/manifold.h"
#include "engine/settings.h"

namespace rbx {

/// Which response a world runs (the contact model; the detector is the other axis,
/// Detector). `Seed`: the seed's algorithm with its corrections (first hit, single-point
/// impulse, frictionless), `custom-seed`. `Extended`: manifolds, simultaneous impulses with
/// Coulomb friction, resting contact, position projection and time of impact, `custom`.
enum class ContactModel { Seed, Extended };

/// The manifold of bodies a and b (indices into the world's bodies).
struct PairManifold {
  int a = 0, b = 0;
  ContactManifold manifold;
  Pose pose_a, pose_b;  // the bodies' poses at detection (anchors for the position projection)
};

/// What one solve is asked: the scene's restitution and friction, the resting threshold, and
/// the engine's tunables (engine/settings.h).
struct ContactSolverSettings {
  double restitution = 1.0;  // Newton's e on the normal velocity, [0, 1]
  double friction = 0.0;     // Coulomb mu >= 0
  double rest_speed = 0.0;   // m/s: approaches slower than this get e = 0 (resting contact)
  // Islands of at most this many points are solved by active sets first (see
  // solve_contact_velocities): 32 points, 96 unknowns, hold a stack of eight boxes on face
  // contacts, whose friction the projections settle only after very many iterations once anything
  // in it slides; larger piles go to the projections at O(points) per iteration. 0 leaves every
  // island to the projections alone (tests compare the two).
  int active_set_rows = 32;
  WorldSettings tunables;  // convergence test and caps of the projections
};

/// One solved point: the accumulated impulses (N s) in the manifold's frame.
struct SolvedPoint {
  int manifold = 0;
  int index = 0;                         // the point's index in its manifold
  Vec3 point = Vec3::Zero();             // m, world, at detection
  double normal_impulse = 0.0;           // N s, >= 0, along the manifold normal (on A)
  Vec3 friction_impulse = Vec3::Zero();  // N s, world, tangent to the normal (on A)
  double approach_speed = 0.0;           // m/s, -(v_rel . n) before the solve (> 0 approaching)
  double target = 0.0;  // m/s, the normal velocity aimed at (Newton's, or the energy guard's)
};

/// What a solve did (counts, for tests and profiles; none of it changes the answer).
struct SolverWork {
  int solves = 0;        // island solves (the energy guard's restarts included)
  int active_set = 0;    // of them, settled by active sets
  long iterations = 0;   // projected Gauss-Seidel iterations, both stages, every island
  int drifts_taken = 0;  // steady drifts taken at once (see solve_island)
};

/// Solves the velocity-level contact problem of `manifolds` on `bodies` in place.
///
/// `approach` holds, per manifold and point, the normal relative velocity v_rel . n measured
/// before this step's forces (the restitution law uses it: Newton, v_n' >= -e v_n0 where
/// v_n0 < -rest_speed, else v_n' >= 0). The bodies' current velocities (forces already added)
/// are then corrected by impulses at every point, to convergence: normal impulses j_n >= 0
/// with complementarity, friction impulses inside the cone |j_t| <= mu j_n (the disc, not a
/// pyramid), sticking when the impulse that stops the slip fits in the cone, else sliding at
/// its edge exactly against the slip, which never adds kinetic energy. Where Newton's law with
/// friction would end with more kinetic energy than the solve started with (Kane & Levinson's
/// paradox), the restitution targets are scaled down to the largest fraction that adds none.
/// How: each island (points sharing a moving body) of at most `active_set_rows` points is
/// first solved by active sets (each point guessed pressed-sticking, pressed-sliding or
/// separating, one linear system per guess, Newton on the sliding directions); projected
/// Gauss-Seidel (staggered projections) then polishes that answer or, where the guesses did
/// not settle, solves from zero. Returns every point's impulses; adds what it did to `work`
/// when given.
std::vector<SolvedPoint> solve_contact_velocities(std::vector<RigidBody>& bodies,
                                                  const std::vector<PairManifold>& manifolds,
                                                  const std::vector<std::vector<double>>& approach,
                                                  const ContactSolverSettings& settings,
                                                  SolverWork* work = nullptr);

/// Normal relative velocity v_rel . n at every point of every manifold (m/s), for
/// solve_contact_velocities' restitution law.
std::vector<std::vector<double>> normal_velocities(const std::vector<RigidBody>& bodies,
                                                   const std::vector<PairManifold>& manifolds);

/// Position projection (nonlinear Gauss-Seidel, as Box2D's position solver): after the poses
/// moved, each point's penetration is re-evaluated from its anchors on both bodies and a
/// fraction of what exceeds a slop is removed by moving the bodies apart along the normal.
/// Velocities are not touched, so no kinetic energy is added; the potential energy can rise
/// only by the penetration it removes. `tunables`: the fraction, iterations and slop.
void project_contact_positions(std::vector<RigidBody>& bodies,
                               const std::vector<PairManifold>& manifolds,
                               const WorldSettings& tunables = WorldSettings());

}  // namespace rbx
