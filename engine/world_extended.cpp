// The extended engine's step (World::step_extended): the seed's bounding check and Moore &
// Wilhelms detector, then contact manifolds, simultaneous impulses with Coulomb friction,
// resting contact and position projection (engine/contact_solver.h). Kept out of world.cpp so
// the seed's step stays as it was.
#include <cmath>

#include "engine/contact_solver.h"
#include "engine/integrate.h"
#include "engine/manifold.h"
#include "engine/world.h"

namespace rbx {

void World::step_extended() {
  const double dt = sim_.dt;
  // Detection: one manifold per pair passing the bounding check, at the step's start poses.
  std::vector<PairManifold> manifolds;
  for (const BodyPair& pair : broad_phase_.find_pairs(bodies_)) {
    const RigidBody &a = bodies_[pair.first], &b = bodies_[pair.second];
    if (a.is_static && b.is_static) continue;
    auto m = build_manifold(*a.shape, a.pose(), *b.shape, b.pose(), variant_);
    if (m) manifolds.push_back({pair.first, pair.second, std::move(*m), a.pose(), b.pose()});
  }

  // Approach velocities before this step's forces: the restitution law's v_n0.
  const std::vector<std::vector<double>> approach = normal_velocities(bodies_, manifolds);
  // Symplectic: forces first (Guendelman et al. 2003), so the contacts see this step's gravity
  // and a resting body ends the step at rest. The seed's Euler adds gravity after the move;
  // there the solve runs before it, as the seed's impulses do.
  const bool symplectic = sim_.integrator == Integrator::Symplectic;
  if (symplectic)
    for (RigidBody& b : bodies_)
      if (!b.is_static) b.velocity += sim_.gravity * dt;

  // Resting threshold: an approach no faster than two steps of gravity is a body settling, not
  // a collision, and gets e = 0 (else a resting body with e > 0 bounces by e g dt for ever).
  // Zero without gravity: every approach is then a collision, as in the seed.
  ContactSolverSettings settings;
  settings.restitution = sim_.restitution;
  settings.friction = sim_.friction;
  settings.rest_speed = 2.0 * sim_.gravity.norm() * dt;
  const std::vector<SolvedPoint> solved =
      solve_contact_velocities(bodies_, manifolds, approach, settings);

  // One event per manifold that was a collision: its total normal impulse at the centre of
  // the normal impulses (the centre of pressure).
  std::vector<double> impulse(manifolds.size(), 0.0);
  std::vector<Vec3> moment(manifolds.size(), Vec3::Zero());
  std::vector<bool> collision(manifolds.size(), false);
  for (const SolvedPoint& p : solved) {
    impulse[p.manifold] += p.normal_impulse;
    moment[p.manifold] += p.normal_impulse * p.point;
    if (p.approach_speed > settings.rest_speed) collision[p.manifold] = true;
  }
  for (size_t m = 0; m < manifolds.size(); ++m) {
    if (!collision[m] || !(impulse[m] > 0.0)) continue;
    ContactPoint c = manifolds[m].manifold.detector_contact;
    c.point = moment[m] / impulse[m];
    c.depth = manifolds[m].manifold.depth;
    events_.push_back({time_, step_, bodies_[manifolds[m].a].name, bodies_[manifolds[m].b].name,
                       c, impulse[m]});
  }

  // Integration (gravity already in the velocities for the symplectic scheme), then the
  // position projection on the moved poses.
  for (RigidBody& b : bodies_) {
    if (symplectic)
      integrate_symplectic(b, Vec3::Zero(), dt);
    else
      integrate(b, sim_, dt);
  }
  // Only pairs that pressed together (a normal impulse) are projected apart: a penetration
  // that no approach caused, such as two overlapping bodies moving together
  // (stress/zero_relative_velocity), is left as it is, as the seed leaves it.
  std::vector<PairManifold> pressed;
  for (size_t m = 0; m < manifolds.size(); ++m)
    if (impulse[m] > 0.0) pressed.push_back(std::move(manifolds[m]));
  project_contact_positions(bodies_, pressed);
}

}  // namespace rbx
