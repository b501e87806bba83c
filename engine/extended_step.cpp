// The extended engine's step (engine/extended_step.h). A departure from the seed in every stage
// but detection; the seed's own step is engine/seed_step.cpp.
#include "engine/extended_step.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <tuple>
#include <utility>

#include "engine/bounding.h"
#include "engine/contact_solver.h"
#include "engine/distance.h"
#include "engine/integrate.h"
#include "engine/manifold.h"
#include "engine/separation.h"
#include "engine/time_of_impact.h"

namespace rbx {

namespace {

// A time of impact its search could not certify: the world's guard stops the run on it
// (World::check_state), naming the pair, rather than pass a step that may have let one body
// through the other. The first such pair of a step is named; the step is counted as the guard
// counts it, by the state it would end at.
void report_uncertified(WorldState& world, int i, int j) {
  if (!world.uncertain.empty()) return;
  std::ostringstream s;
  s << "time of impact of bodies " << world.bodies[i].name << " and " << world.bodies[j].name
    << " not certified at step " << world.step + 1 << " (t = " << (world.step + 1) * world.sim.dt
    << " s): they skim past each other too fast for " << world.tunables.toi_max_samples
    << " samples in one step; lower sim.dt";
  world.uncertain = s.str();
}

// `to` made `from`, for a look-ahead body kept from step to step: the shape, and with it the
// name, copied only when the shape differs (once: no string copy and no reference count each
// step; a look-ahead body's name is never read), the rest always: what advanced() reads and the
// pose.
void refresh(RigidBody& to, const RigidBody& from) {
  if (to.shape != from.shape) {
    to = from;
    return;
  }
  to.shape_kind = from.shape_kind;
  to.box_size = from.box_size;
  to.shape_origin_offset = from.shape_origin_offset;
  to.is_static = from.is_static;
  to.mass = from.mass;
  to.inertia_body = from.inertia_body;
  to.inverse_mass = from.inverse_mass;
  to.inverse_inertia_body = from.inverse_inertia_body;
  to.position = from.position;
  to.orientation = from.orientation;
  to.velocity = from.velocity;
  to.angular_velocity = from.angular_velocity;
}

}  // namespace

// The step as a list of stages: detect, approach velocities, forces, solve, events, time of
// impact, integrate, project.
ExtendedStep::ExtendedStep(const WorldSettings& tunables)
    : ahead_broad_phase_(BroadPhaseMethod::Tree, tunables) {}

void ExtendedStep::advance(WorldState& world) {
  ++steps_;
  std::vector<PairManifold> manifolds = detect_manifolds(world);
  // Approach velocities before this step's forces: the restitution law's v_n0.
  const std::vector<std::vector<double>> approach = normal_velocities(world.bodies, manifolds);
  // Symplectic: forces first (Guendelman et al. 2003), so the contacts see this step's gravity
  // and a resting body ends the step at rest. The seed's Euler adds gravity after the move;
  // there the solve runs before it, as the seed's impulses do.
  if (world.sim.integrator == Integrator::Symplectic)
    for (RigidBody& b : world.bodies)
      if (!b.is_static) b.velocity += world.sim.gravity * world.sim.dt;
  const ContactSolverSettings settings = solver_settings(world);
  const std::vector<SolvedPoint> solved =
      solve_contact_velocities(world.bodies, manifolds, approach, settings);
  // One event per manifold that was a collision.
  const std::vector<double> impulse =
      record_events(world, manifolds, solved, world.time, settings.rest_speed);
  // Time of impact: pairs separated at the step's start that the step's motion brings into
  // contact (engine/time_of_impact.h) are moved to their first contact, resolved there, and
  // moved on for the rest of the step: an adaptive step for those two bodies only.
  const std::vector<bool> moved = time_of_impact_step(world, manifolds, settings);
  integrate_bodies(world, moved, ahead_filled_ ? &ahead_ : nullptr);
  // Only pairs that pressed together (a normal impulse) are projected apart: a penetration
  // that no approach caused, such as two overlapping bodies moving together
  // (stress/zero_relative_velocity), is left as it is, as the seed leaves it.
  std::vector<PairManifold> pressed;
  for (size_t m = 0; m < manifolds.size(); ++m)
    if (impulse[m] > 0.0) pressed.push_back(std::move(manifolds[m]));
  project_contact_positions(world.bodies, pressed, world.tunables);
}

double ExtendedStep::look_ahead_growth(const WorldState& world) {
  // The seed's Euler has no look-ahead.
  if (world.sim.integrator != Integrator::Symplectic) return 0.0;
  // Each body's reach over the step at its start velocity with this step's gravity (|v + g dt|
  // <= |v| + |g| dt), doubled: room for the contact solve to exchange speeds between bodies.
  const double dt = world.sim.dt;
  double most = 0.0, least_radius = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < world.bodies.size(); ++i) {
    const RigidBody& b = world.bodies[i];
    if (b.is_static) continue;
    most =
        std::max(most, travel_bound(b, world.facts[i].turn_rate, world.facts[i].centre_reach, dt) +
                           world.sim.gravity.norm() * dt * dt);
    least_radius = std::min(least_radius, world.facts[i].radius);
  }
  // Worth it only while the growth keeps the spheres near their size (a fast body would grow
  // every sphere): then the look-ahead runs its own broad phase.
  const double grow = 2.0 * most;
  return std::isfinite(grow) && grow <= 0.05 * least_radius ? grow : 0.0;
}

std::vector<PairManifold> ExtendedStep::detect_manifolds(WorldState& world) {
  // One manifold per pair passing the bounding check, at the step's start poses. With a growth,
  // the broad phase's pairs are those of spheres grown by it, kept for the look-ahead; here the
  // seed's test on the start spheres keeps exactly the bounding check's pairs, in its order.
  std::vector<PairManifold> manifolds;
  // Which bodies are where the last step's look-ahead put them (ahead_, still the last step's):
  // for those, the gaps proved at its end still bound theirs.
  const size_t n = world.bodies.size();
  unmoved_.assign(n, 0);
  if (ahead_filled_ && ahead_.size() == n)
    for (size_t i = 0; i < n; ++i)
      unmoved_[i] = world.bodies[i].position == ahead_[i].position &&
                    world.bodies[i].orientation.coeffs() == ahead_[i].orientation.coeffs();
  place_boxes(world.bodies, world.facts);
  grow_ = look_ahead_growth(world);
  spheres_.resize(n);
  for (size_t i = 0; i < n; ++i) spheres_[i] = bounding_sphere(world.bodies[i], world.facts[i]);
  const std::vector<BodyPair>& pairs = world.broad_phase.find_pairs(world.bodies, spheres_, grow_);
  if (grow_ > 0.0) grown_pairs_.assign(pairs.begin(), pairs.end());
  for (const BodyPair& pair : pairs) {
    const RigidBody &a = world.bodies[pair.first], &b = world.bodies[pair.second];
    if (a.is_static && b.is_static) continue;
    if (grow_ > 0.0 && !spheres_touch(spheres_[pair.first], spheres_[pair.second])) continue;
    if (separated(world, a, b, pair.first, pair.second)) continue;  // the detector finds nothing
    auto m = build_manifold(*a.shape, a.pose(), *b.shape, b.pose(), world.detector,
                            world.tunables.position_slop, detection_, contact_scratch_);
    if (m) manifolds.push_back({pair.first, pair.second, std::move(*m), a.pose(), b.pose()});
  }
  return manifolds;
}

ContactSolverSettings ExtendedStep::solver_settings(const WorldState& world) {
  // Resting threshold: a few steps of gravity (WorldSettings::rest_gravity_steps).
  ContactSolverSettings settings;
  settings.restitution = world.sim.restitution;
  settings.friction = world.sim.friction;
  settings.rest_speed = world.tunables.rest_gravity_steps * world.sim.gravity.norm() * world.sim.dt;
  settings.tunables = world.tunables;
  return settings;
}

std::vector<double> ExtendedStep::record_events(WorldState& world,
                                                const std::vector<PairManifold>& manifolds,
                                                const std::vector<SolvedPoint>& solved, double time,
                                                std::optional<double> rest_speed) {
  // A manifold's event: its total normal impulse at the centre of the normal impulses (the
  // centre of pressure), with the detector's contact for the rest.
  std::vector<double> impulse(manifolds.size(), 0.0);
  std::vector<Vec3> moment(manifolds.size(), Vec3::Zero());
  std::vector<bool> collision(manifolds.size(), !rest_speed);
  for (const SolvedPoint& p : solved) {
    const PairManifold& pm = manifolds[p.manifold];
    world.step_contacts.push_back({pm.a, pm.b, p.point, pm.manifold.normal,
                                   pm.manifold.points[p.index].depth,
                                   p.normal_impulse * pm.manifold.normal + p.friction_impulse,
                                   pm.pose_a.position, pm.pose_b.position});
    impulse[p.manifold] += p.normal_impulse;
    moment[p.manifold] += p.normal_impulse * p.point;
    if (rest_speed && p.approach_speed > *rest_speed) collision[p.manifold] = true;
  }
  for (size_t m = 0; m < manifolds.size(); ++m) {
    if (!collision[m] || !(impulse[m] > 0.0)) continue;
    ContactPoint c = manifolds[m].manifold.contact;
    c.point = moment[m] / impulse[m];
    c.normal = manifolds[m].manifold.normal;
    c.depth = manifolds[m].manifold.depth;
    world.add_event(manifolds[m].a, manifolds[m].b, c, impulse[m], time);
  }
  return impulse;
}

void ExtendedStep::integrate_bodies(WorldState& world, const std::vector<bool>& moved,
                                    const std::vector<RigidBody>* ahead) {
  // Gravity is already in the velocities for the symplectic scheme.
  const std::vector<BodyFacts>& facts = world.facts;
  for (size_t i = 0; i < world.bodies.size(); ++i) {
    RigidBody& b = world.bodies[i];
    if (moved[i]) continue;  // already carried through the step by its time of impact
    if (world.sim.integrator == Integrator::Symplectic && ahead &&
        ahead->size() == world.bodies.size()) {
      // The time of impact's look ahead already made this very move (advanced() is the same
      // integration with no gravity), and nothing touched the body since.
      const RigidBody& moved_ahead = (*ahead)[i];
      b.position = moved_ahead.position;
      b.orientation = moved_ahead.orientation;
      b.velocity = moved_ahead.velocity;
      b.angular_velocity = moved_ahead.angular_velocity;
    } else if (world.sim.integrator == Integrator::Symplectic)
      integrate_symplectic(b, Vec3::Zero(), world.sim.dt, &facts[i].principal);
    else
      integrate(b, world.sim, world.sim.dt, &facts[i].principal);
  }
}

const std::vector<BodyPair>& ExtendedStep::look_ahead_pairs(const WorldState& world) {
  // The start's grown pairs hold every pair whose spheres touch at the step's end while no
  // sphere centre moved more than half the growth (two centres then close in by at most the
  // growth, which each grown radius adds): filtered by the seed's test on the end spheres, they
  // are the look-ahead broad phase's pairs, in its order. Otherwise that broad phase runs.
  const size_t n = ahead_.size();
  bool within = grow_ > 0.0;
  for (size_t i = 0; within && i < n; ++i)
    within = rates_[i].over(world.facts[i].centre_reach, world.sim.dt) <= 0.5 * grow_;
  spheres_.resize(n);
  for (size_t i = 0; i < n; ++i) spheres_[i] = bounding_sphere(ahead_[i], world.facts[i]);
  if (!within) return ahead_broad_phase_.find_pairs(ahead_, spheres_);
  ahead_pairs_.clear();
  for (const BodyPair& p : grown_pairs_)
    if (spheres_touch(spheres_[p.first], spheres_[p.second])) ahead_pairs_.push_back(p);
  return ahead_pairs_;
}

void ExtendedStep::place_boxes(const std::vector<RigidBody>& bodies,
                               const std::vector<BodyFacts>& facts) {
  const size_t n = bodies.size();
  if (static_lo_.size() != n) {
    static_lo_.assign(n, Vec3::Zero());
    static_hi_.assign(n, Vec3::Zero());
    for (size_t i = 0; i < n; ++i) {
      if (!bodies[i].is_static) continue;
      const Pose pose = bodies[i].pose();
      static_lo_[i] = static_hi_[i] = pose.apply(bodies[i].shape->vertices().front());
      for (const Vec3& v : bodies[i].shape->vertices()) {
        const Vec3 w = pose.apply(v);
        static_lo_[i] = static_lo_[i].cwiseMin(w);
        static_hi_[i] = static_hi_[i].cwiseMax(w);
      }
    }
  }
  box_lo_.resize(n);
  box_hi_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const RigidBody& b = bodies[i];
    box_lo_[i] = b.is_static ? static_lo_[i] : Vec3(b.position.array() - facts[i].radius);
    box_hi_[i] = b.is_static ? static_hi_[i] : Vec3(b.position.array() + facts[i].radius);
  }
}

bool ExtendedStep::separated(const WorldState& world, const RigidBody& a, const RigidBody& b, int i,
                             int j, double travel) {
  const std::vector<BodyFacts>& facts = world.facts;
  // The pair's tolerance, 1e-9 x the larger size, is the larger of the two bodies' own.
  const double margin = separation_margin(std::max(facts[i].own_tol, facts[j].own_tol),
                                          facts[i].reach, facts[j].reach);
  // Apart along a world axis by their boxes (a wall beside a body): no axis to keep.
  const Vec3 gap_ab = box_lo_[i] - box_hi_[j], gap_ba = box_lo_[j] - box_hi_[i];
  if (gap_ab.maxCoeff() > margin || gap_ba.maxCoeff() > margin) return true;
  const long long key = static_cast<long long>(i) * static_cast<long long>(world.bodies.size()) + j;
  Witness* kept = witnesses_.find(key);
  // Proved at the step's start with room for both bodies' travel along the step (no point moves
  // farther): still apart at its end.
  if (travel >= 0.0 && kept && kept->step == steps_ && kept->gap - travel > margin) {
    kept->end_gap = kept->gap - travel;
    kept->end_step = steps_;
    return true;
  }
  // At the step's start, the bound the last step's end left, while neither body has moved since
  // (no time of impact, no projection).
  if (travel < 0.0 && kept && kept->end_step == steps_ - 1 && kept->end_gap > margin &&
      unmoved_[i] && unmoved_[j]) {
    kept->gap = kept->end_gap;
    kept->step = steps_;
    return true;
  }
  if (kept) {
    // The bounding boxes' bound first (exact for boxes), the vertices only when it falls short.
    const Vec3 u = b.orientation * kept->axis;
    double gap = gap_bound_along(*a.shape, a.pose(), *b.shape, b.pose(), u);
    if (!(gap > margin)) gap = gap_along(*a.shape, a.pose(), *b.shape, b.pose(), u);
    if (gap > margin) {
      kept->gap = gap;
      kept->step = steps_;
      if (travel >= 0.0) {
        kept->end_gap = gap;
        kept->end_step = steps_;
      }
      return true;
    }
  }
  const Vec3 u = find_separating_axis(*a.shape, a.pose(), *b.shape, b.pose(), margin);
  if (u != Vec3::Zero()) {
    const double gap = gap_along(*a.shape, a.pose(), *b.shape, b.pose(), u);
    witnesses_.put(key,
                   {b.orientation.conjugate() * u, gap, steps_, gap, travel >= 0.0 ? steps_ : -1});
    return true;
  }
  if (travel >= 0.0 && apart_through_step(world, a, b, i, j, margin)) return true;
  if (kept) witnesses_.drop(key);
  return false;
}

bool ExtendedStep::apart_through_step(const WorldState& world, const RigidBody& a,
                                      const RigidBody& b, int i, int j, double margin) {
  // At the step's end the pairs the axes leave are new contacts, or near misses the axes do not
  // prove apart: two boxes' edges passing crosswise. The direction between the closest points
  // proves those apart at the end, and is kept like any other axis.
  const auto apart = [margin](const RigidBody& p, const RigidBody& q,
                              const Separation& s) -> std::optional<GapAlong> {
    if (s.overlapping || !(s.distance > margin)) return std::nullopt;
    const Vec3 u = (s.point_a - s.point_b) / s.distance;
    return GapAlong{u, gap_along(*p.shape, p.pose(), *q.shape, q.pose(), u)};
  };
  const auto distance = [](const RigidBody& p, const RigidBody& q) {
    return shape_distance(*p.shape, p.pose(), *q.shape, q.pose());
  };
  end_distance_ = distance(a, b);
  const std::optional<GapAlong> end = apart(a, b, *end_distance_);
  if (!end || !(end->gap > margin)) return false;
  const long long key = static_cast<long long>(i) * static_cast<long long>(world.bodies.size()) + j;
  const Witness* kept = witnesses_.find(key);
  const RigidBody &a0 = world.bodies[i], &b0 = world.bodies[j];
  // Apart at both ends is not apart between (a corner can clip another mid-step): the gap at
  // the start, the one kept this step or else the distance's, and the end's cover the step.
  const std::optional<GapAlong> start =
      kept && kept->step == steps_
          ? std::optional<GapAlong>(GapAlong{b0.orientation * kept->axis, kept->gap})
          : apart(a0, b0, distance(a0, b0));
  witnesses_.put(key, {b.orientation.conjugate() * end->u, end->gap, steps_, end->gap, steps_});
  return start &&
         apart_through(a0, b0, world.facts[i], world.facts[j], *start, *end, margin, world.sim.dt);
}

std::vector<bool> ExtendedStep::time_of_impact_step(WorldState& world,
                                                    const std::vector<PairManifold>& manifolds,
                                                    const ContactSolverSettings& settings) {
  const double dt = world.sim.dt;
  const size_t n = world.bodies.size();
  std::vector<bool> moved(n, false);
  ahead_filled_ = false;
  if (world.sim.integrator != Integrator::Symplectic) return moved;  // the seed's Euler: no TOI
  // Per body: thickness and bounding radius (fixed by the shape), sweep over the step.
  const std::vector<BodyFacts>& facts = world.facts;
  std::vector<double> sweep(n);
  double thinnest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i) {
    sweep[i] = sweep_length(world.bodies[i], facts[i].radius, dt);
    thinnest = std::min(thinnest, facts[i].thickness);
  }
  // The pairs in contact at the start, sorted (a few per body, looked up for every candidate).
  touching_.clear();
  for (const PairManifold& pm : manifolds) touching_.emplace_back(pm.a, pm.b);
  std::sort(touching_.begin(), touching_.end());
  const auto touching = [&](const BodyPair& p) {
    return std::binary_search(touching_.begin(), touching_.end(), p);
  };
  // Candidates: a pair whose relative sweep exceeds toi_pair_sweep of the thinner thickness
  // (below that, the next step's detection after penetration finds the contact: nothing can
  // pass through) and whose swept spheres meet. The faster body of such a pair sweeps more
  // than half of that, toi_body_sweep of the thinnest body, which keeps the search to the
  // fast bodies.
  std::vector<std::tuple<double, int, int>> hits;  // (time of impact, i, j), i < j
  for (size_t i = 0; i < n; ++i) {
    if (!(sweep[i] > world.tunables.toi_body_sweep * thinnest)) continue;
    for (size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      if (sweep[j] > sweep[i] || (sweep[j] == sweep[i] && j < i)) continue;  // the faster one asks
      const int lo = static_cast<int>(std::min(i, j)), hi = static_cast<int>(std::max(i, j));
      if (touching({lo, hi})) continue;
      if (!(sweep[i] + sweep[j] >
            world.tunables.toi_pair_sweep * std::min(facts[i].thickness, facts[j].thickness)))
        continue;
      const RigidBody &a = world.bodies[lo], &b = world.bodies[hi];
      // Swept spheres (the bounding check along the step): the centres' closest approach over
      // the step within the radii sum; the radius about the centre of mass bounds every
      // orientation, so rotation needs no margin.
      const Vec3 p = a.position - b.position, q = (a.velocity - b.velocity) * dt;
      const double s =
          q.squaredNorm() > 0.0 ? std::clamp(-p.dot(q) / q.squaredNorm(), 0.0, 1.0) : 0.0;
      if ((p + s * q).norm() > facts[lo].radius + facts[hi].radius) continue;
      const TimeOfImpact t =
          time_of_impact(a, b, dt, world.detector, world.tunables.toi_max_samples, &facts[lo],
                         &facts[hi], &detection_);
      if (!t.certified) report_uncertified(world, lo, hi);
      if (t.time) hits.emplace_back(*t.time, lo, hi);
    }
  }
  // Every other new contact (departure from the seed, whose detection after penetration resolves
  // a contact at whatever depth a step first sees it, along a plane and from a point that depend
  // on that depth): a pair apart at the step's start whose poses at its end, moved with the
  // step's velocities, touch is moved to its first touch like the fast pairs above, so an impact
  // is resolved where it begins whatever its phase in the step.
  std::vector<double> travel(n, 0.0);
  rates_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    rates_[i] = travel_rate(world.bodies[i], facts[i].turn_rate);
    travel[i] = rates_[i].over(facts[i].radius, dt);
  }
  // advanced(), in place: the same integration on the kept copy.
  ahead_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    refresh(ahead_[i], world.bodies[i]);
    if (!ahead_[i].is_static)
      integrate_symplectic(ahead_[i], Vec3::Zero(), dt, &facts[i].principal);
  }
  ahead_filled_ = true;
  // The pairs the fast search above asked (few: fast bodies only).
  std::vector<BodyPair> asked;
  for (const auto& [t, i, j] : hits) asked.emplace_back(i, j);
  std::sort(asked.begin(), asked.end());
  place_boxes(ahead_, facts);
  for (const BodyPair& pair : look_ahead_pairs(world)) {
    const auto [i, j] = pair;
    const RigidBody &a = ahead_[i], &b = ahead_[j];
    if ((a.is_static && b.is_static) || touching(pair) ||
        std::binary_search(asked.begin(), asked.end(), pair))
      continue;
    // Still apart at the step's end: by the gap proved at its start less both bodies' travel,
    // else by the pair's kept axis or a new one.
    end_distance_.reset();
    if (separated(world, a, b, i, j, travel[i] + travel[j])) continue;
    // The end's distance, when separated() took it, is the search's own sample at dt: a and b
    // are where advanced() puts the pair, and the search's poses are those bit for bit.
    const TimeOfImpact t = time_of_impact(world.bodies[i], world.bodies[j], dt, world.detector,
                                          world.tunables.toi_max_samples, &facts[i], &facts[j],
                                          &detection_, end_distance_ ? &*end_distance_ : nullptr);
    if (!t.certified) report_uncertified(world, i, j);
    if (t.time) hits.emplace_back(*t.time, i, j);
  }
  std::sort(hits.begin(), hits.end());
  for (const auto& [t, i, j] : hits) {
    // One time of impact per body and step (the earliest): the rest waits for the next step.
    if (moved[i] || moved[j]) continue;
    RigidBody &a = world.bodies[i], &b = world.bodies[j];
    a = advanced(a, t, &facts[i].principal);
    b = advanced(b, t, &facts[j].principal);
    if (auto m = build_manifold(*a.shape, a.pose(), *b.shape, b.pose(), world.detector,
                                world.tunables.position_slop, detection_, contact_scratch_)) {
      const std::vector<PairManifold> one = {{i, j, std::move(*m), a.pose(), b.pose()}};
      const auto approach = normal_velocities(world.bodies, one);
      // Every impact here is a collision: its event whatever its approach speed.
      record_events(world, one, solve_contact_velocities(world.bodies, one, approach, settings),
                    world.time + t, std::nullopt);
    }
    a = advanced(a, dt - t, &facts[i].principal);
    b = advanced(b, dt - t, &facts[j].principal);
    moved[i] = !a.is_static;
    moved[j] = !b.is_static;
  }
  return moved;
}

}  // namespace rbx
