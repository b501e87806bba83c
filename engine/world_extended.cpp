// The extended engine's step (World::step_extended): the seed's bounding check and Moore &
// Wilhelms detector, then contact manifolds, simultaneous impulses with Coulomb friction,
// resting contact and position projection (engine/contact_solver.h). Kept out of world.cpp so
// the seed's step stays as it was.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <tuple>
#include <utility>

#include "engine/contact_solver.h"
#include "engine/integrate.h"
#include "engine/manifold.h"
#include "engine/separation.h"
#include "engine/time_of_impact.h"
#include "engine/world.h"

namespace rbx {

// The step as a list of stages: detect, approach velocities, forces, solve, events, time of
// impact, integrate, project.
void World::step_extended() {
  std::vector<PairManifold> manifolds = detect_manifolds();
  // Approach velocities before this step's forces: the restitution law's v_n0.
  const std::vector<std::vector<double>> approach = normal_velocities(bodies_, manifolds);
  // Symplectic: forces first (Guendelman et al. 2003), so the contacts see this step's gravity
  // and a resting body ends the step at rest. The seed's Euler adds gravity after the move;
  // there the solve runs before it, as the seed's impulses do.
  if (sim_.integrator == Integrator::Symplectic)
    for (RigidBody& b : bodies_)
      if (!b.is_static) b.velocity += sim_.gravity * sim_.dt;
  const ContactSolverSettings settings = solver_settings();
  const std::vector<SolvedPoint> solved =
      solve_contact_velocities(bodies_, manifolds, approach, settings);
  // One event per manifold that was a collision.
  const std::vector<double> impulse = record_events(manifolds, solved, time_, settings.rest_speed);
  // Time of impact: pairs separated at the step's start that the step's motion brings into
  // contact (engine/time_of_impact.h) are moved to their first contact, resolved there, and
  // moved on for the rest of the step: an adaptive step for those two bodies only.
  const std::vector<bool> moved = time_of_impact_step(manifolds, settings);
  integrate_bodies(moved);
  // Only pairs that pressed together (a normal impulse) are projected apart: a penetration
  // that no approach caused, such as two overlapping bodies moving together
  // (stress/zero_relative_velocity), is left as it is, as the seed leaves it.
  std::vector<PairManifold> pressed;
  for (size_t m = 0; m < manifolds.size(); ++m)
    if (impulse[m] > 0.0) pressed.push_back(std::move(manifolds[m]));
  project_contact_positions(bodies_, pressed, tunables_);
}

std::vector<PairManifold> World::detect_manifolds() {
  // One manifold per pair passing the bounding check, at the step's start poses.
  std::vector<PairManifold> manifolds;
  for (const BodyPair& pair : broad_phase_.find_pairs(bodies_)) {
    const RigidBody &a = bodies_[pair.first], &b = bodies_[pair.second];
    if (a.is_static && b.is_static) continue;
    if (separated(pair.first, pair.second)) continue;  // the detector would find nothing
    auto m = build_manifold(*a.shape, a.pose(), *b.shape, b.pose(), variant_);
    if (m) manifolds.push_back({pair.first, pair.second, std::move(*m), a.pose(), b.pose()});
  }
  return manifolds;
}

ContactSolverSettings World::solver_settings() const {
  // Resting threshold: a few steps of gravity (WorldSettings::rest_gravity_steps).
  ContactSolverSettings settings;
  settings.restitution = sim_.restitution;
  settings.friction = sim_.friction;
  settings.rest_speed = tunables_.rest_gravity_steps * sim_.gravity.norm() * sim_.dt;
  settings.tunables = tunables_;
  return settings;
}

std::vector<double> World::record_events(const std::vector<PairManifold>& manifolds,
                                         const std::vector<SolvedPoint>& solved, double time,
                                         std::optional<double> rest_speed) {
  // A manifold's event: its total normal impulse at the centre of the normal impulses (the
  // centre of pressure), with the detector's contact for the rest.
  std::vector<double> impulse(manifolds.size(), 0.0);
  std::vector<Vec3> moment(manifolds.size(), Vec3::Zero());
  std::vector<bool> collision(manifolds.size(), !rest_speed);
  for (const SolvedPoint& p : solved) {
    impulse[p.manifold] += p.normal_impulse;
    moment[p.manifold] += p.normal_impulse * p.point;
    if (rest_speed && p.approach_speed > *rest_speed) collision[p.manifold] = true;
  }
  for (size_t m = 0; m < manifolds.size(); ++m) {
    if (!collision[m] || !(impulse[m] > 0.0)) continue;
    ContactPoint c = manifolds[m].manifold.detector_contact;
    c.point = moment[m] / impulse[m];
    c.normal = manifolds[m].manifold.normal;
    c.depth = manifolds[m].manifold.depth;
    events_.push_back(
        {time, step_, bodies_[manifolds[m].a].name, bodies_[manifolds[m].b].name, c, impulse[m]});
  }
  return impulse;
}

void World::integrate_bodies(const std::vector<bool>& moved) {
  // Gravity is already in the velocities for the symplectic scheme.
  const std::vector<ShapeFacts>& facts = shape_facts();
  for (size_t i = 0; i < bodies_.size(); ++i) {
    RigidBody& b = bodies_[i];
    if (moved[i]) continue;  // already carried through the step by its time of impact
    if (sim_.integrator == Integrator::Symplectic)
      integrate_symplectic(b, Vec3::Zero(), sim_.dt, &facts[i].principal);
    else
      integrate(b, sim_, sim_.dt, &facts[i].principal);
  }
}

bool World::separated(int i, int j) {
  const RigidBody &a = bodies_[i], &b = bodies_[j];
  const std::vector<ShapeFacts>& facts = shape_facts();
  // The pair's tolerance, 1e-9 x the larger size, is the larger of the two bodies' own.
  const double margin = separation_margin(std::max(facts[i].own_tol, facts[j].own_tol),
                                          facts[i].reach, facts[j].reach);
  const long long key = static_cast<long long>(i) * static_cast<long long>(bodies_.size()) + j;
  const auto kept = witnesses_.find(key);
  if (kept != witnesses_.end() &&
      gap_along(*a.shape, a.pose(), *b.shape, b.pose(), b.orientation * kept->second) > margin)
    return true;
  const Vec3 u = find_separating_axis(*a.shape, a.pose(), *b.shape, b.pose(), margin);
  if (u != Vec3::Zero()) {
    witnesses_[key] = b.orientation.conjugate() * u;
    return true;
  }
  if (kept != witnesses_.end()) witnesses_.erase(kept);
  return false;
}

std::vector<bool> World::time_of_impact_step(const std::vector<PairManifold>& manifolds,
                                             const ContactSolverSettings& settings) {
  const double dt = sim_.dt;
  const size_t n = bodies_.size();
  std::vector<bool> moved(n, false);
  if (sim_.integrator != Integrator::Symplectic) return moved;  // the seed's Euler: no TOI
  // Per body: thickness and bounding radius (fixed by the shape), sweep over the step.
  const std::vector<ShapeFacts>& facts = shape_facts();
  std::vector<double> sweep(n);
  double thinnest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i) {
    sweep[i] = sweep_length(bodies_[i], dt);
    thinnest = std::min(thinnest, facts[i].thickness);
  }
  std::set<std::pair<int, int>> touching;
  for (const PairManifold& pm : manifolds) touching.insert({pm.a, pm.b});
  // Candidates: a pair whose relative sweep exceeds toi_pair_sweep of the thinner thickness
  // (below that, the next step's detection after penetration finds the contact: nothing can
  // pass through) and whose swept spheres meet. The faster body of such a pair sweeps more
  // than half of that, toi_body_sweep of the thinnest body, which keeps the search to the
  // fast bodies.
  std::vector<std::tuple<double, int, int>> hits;  // (time of impact, i, j), i < j
  for (size_t i = 0; i < n; ++i) {
    if (!(sweep[i] > tunables_.toi_body_sweep * thinnest)) continue;
    for (size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      if (sweep[j] > sweep[i] || (sweep[j] == sweep[i] && j < i)) continue;  // the faster one asks
      const int lo = static_cast<int>(std::min(i, j)), hi = static_cast<int>(std::max(i, j));
      if (touching.count({lo, hi})) continue;
      if (!(sweep[i] + sweep[j] >
            tunables_.toi_pair_sweep * std::min(facts[i].thickness, facts[j].thickness)))
        continue;
      const RigidBody &a = bodies_[lo], &b = bodies_[hi];
      // Swept spheres (the bounding check along the step): the centres' closest approach over
      // the step within the radii sum; the radius about the centre of mass bounds every
      // orientation, so rotation needs no margin.
      const Vec3 p = a.position - b.position, q = (a.velocity - b.velocity) * dt;
      const double s =
          q.squaredNorm() > 0.0 ? std::clamp(-p.dot(q) / q.squaredNorm(), 0.0, 1.0) : 0.0;
      if ((p + s * q).norm() > facts[lo].radius + facts[hi].radius) continue;
      if (const auto t = time_of_impact(a, b, dt, variant_)) hits.emplace_back(*t, lo, hi);
    }
  }
  // Every other new contact (departure from the seed, whose detection after penetration resolves
  // a contact at whatever depth a step first sees it, along a plane and from a point that depend
  // on that depth): a pair apart at the step's start whose poses at its end, moved with the
  // step's velocities, touch is moved to its first touch like the fast pairs above, so an impact
  // is resolved where it begins whatever its phase in the step.
  ahead_.clear();
  for (const RigidBody& b : bodies_) ahead_.push_back(b.is_static ? b : advanced(b, dt));
  std::set<std::pair<int, int>> asked;
  for (const auto& [t, i, j] : hits) asked.insert({i, j});
  for (const BodyPair& pair : ahead_broad_phase_.find_pairs(ahead_)) {
    const auto [i, j] = pair;
    const RigidBody &a = ahead_[i], &b = ahead_[j];
    if ((a.is_static && b.is_static) || touching.count(pair) || asked.count(pair)) continue;
    const double margin = separation_margin(std::max(facts[i].own_tol, facts[j].own_tol),
                                            facts[i].reach, facts[j].reach);
    if (find_separating_axis(*a.shape, a.pose(), *b.shape, b.pose(), margin) != Vec3::Zero())
      continue;  // still apart at the step's end
    if (const auto t = time_of_impact(bodies_[i], bodies_[j], dt, variant_))
      hits.emplace_back(*t, i, j);
  }
  std::sort(hits.begin(), hits.end());
  for (const auto& [t, i, j] : hits) {
    // One time of impact per body and step (the earliest): the rest waits for the next step.
    if (moved[i] || moved[j]) continue;
    RigidBody &a = bodies_[i], &b = bodies_[j];
    a = advanced(a, t);
    b = advanced(b, t);
    if (auto m = build_manifold(*a.shape, a.pose(), *b.shape, b.pose(), variant_)) {
      const std::vector<PairManifold> one = {{i, j, std::move(*m), a.pose(), b.pose()}};
      const auto approach = normal_velocities(bodies_, one);
      // Every impact here is a collision: its event whatever its approach speed.
      record_events(one, solve_contact_velocities(bodies_, one, approach, settings), time_ + t,
                    std::nullopt);
    }
    a = advanced(a, dt - t);
    b = advanced(b, dt - t);
    moved[i] = !a.is_static;
    moved[j] = !b.is_static;
  }
  return moved;
}

}  // namespace rbx
