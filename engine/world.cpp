#include "engine/world.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "engine/bounding.h"
#include "engine/format.h"
#include "engine/integrate.h"
#include "engine/response.h"
#include "engine/time_of_impact.h"

namespace rbx {

World::World(SimSettings sim, std::vector<RigidBody> bodies, DetectorVariant variant,
             BroadPhaseMethod broad_phase, const WorldSettings& tunables)
    : sim_(std::move(sim)),
      bodies_(std::move(bodies)),
      variant_(variant),
      tunables_(tunables),
      broad_phase_(broad_phase, tunables),
      ahead_broad_phase_(BroadPhaseMethod::Tree, tunables) {
  // Energy guard budget: the initial kinetic energy, or the work gravity could do over the
  // bodies' own sizes, whichever is larger, so a scene starting at rest is not flagged.
  energy0_ = energy();
  double kinetic = 0.0, gravity_work = 0.0;
  for (const RigidBody& b : bodies_) {
    kinetic += b.kinetic_energy();
    if (!b.is_static) gravity_work += b.mass * sim_.gravity.norm() * bounding_sphere(b).radius;
  }
  energy_scale_ = std::max({kinetic, gravity_work, 1e-300});
}

double World::energy() const {
  double e = 0.0;
  for (const RigidBody& b : bodies_)
    if (!b.is_static) e += b.kinetic_energy() - b.mass * sim_.gravity.dot(b.position);
  return e;
}

void World::collide_pair(int i, int j, bool bounded) {
  RigidBody& a = bodies_[i];
  RigidBody& b = bodies_[j];
  if (a.is_static && b.is_static) return;
  if (!bounded && !bounding_check(a, b)) return;
  // The seed's order: face, vertex, edge; each resolved as soon as it hits. After the first
  // impulse the pair separates at the contact, so later hits add an impulse only if the new
  // velocities still approach at their own point.
  // Responses change velocities only, so the pair is placed once for the three tests.
  detection_.prepare(*a.shape, a.pose(), *b.shape, b.pose(), variant_);
  for (Feature feature : {Feature::Face, Feature::Vertex, Feature::Edge}) {
    const auto contact = detection_.test(feature);
    if (!contact) continue;
    if (response_) {
      // A researcher's response (set_response): its impulse vector, applied as given.
      const Vec3 impulse = response_(a, b, *contact, sim_.restitution);
      if (!impulse.allFinite())
        throw std::runtime_error("the response returned a non-finite impulse");
      if (impulse.isZero(0.0)) continue;
      apply_impulse_at(a, b, contact->point, impulse);
      events_.push_back({time_, step_, a.name, b.name, *contact, impulse.dot(contact->normal)});
      continue;
    }
    const double j_mag = apply_impulse(a, b, *contact, sim_.restitution);
    if (j_mag > 0.0) events_.push_back({time_, step_, a.name, b.name, *contact, j_mag});
  }
}

namespace {

// Shortest decimal that reads back as the same double, so that a message never shows two
// different numbers alike (max_energy_ratio = 1.000001 printed "1" with 6 digits).
std::string shortest(double v) {
  NumberFormat f;
  f.digits = 0;
  f.signed_zero = true;
  return format_number(v, f);
}

}  // namespace

bool World::check_state() {
  auto fail = [&](const RigidBody& b, const char* what) {
    std::ostringstream s;
    s << "non-finite " << what << " of body " << b.name << " at step " << step_ << " (t = " << time_
      << " s)";
    failure_ = s.str();
    return false;
  };
  for (const RigidBody& b : bodies_) {
    if (!b.position.allFinite()) return fail(b, "position");
    if (!b.velocity.allFinite()) return fail(b, "velocity");
    if (!b.angular_velocity.allFinite()) return fail(b, "angular velocity");
    if (!b.orientation.coeffs().allFinite()) return fail(b, "orientation");
    // Finite states can still overflow the energy (1/2 m v^2 at v = 1e155 m/s); the growth test
    // below would then compare inf - inf = NaN, which no bound catches.
    if (b.is_static) continue;
    if (!std::isfinite(b.kinetic_energy())) return fail(b, "kinetic energy");
    if (!std::isfinite(b.mass * sim_.gravity.dot(b.position))) return fail(b, "potential energy");
  }
  // The sum of finite energies can still overflow.
  const double e = energy();
  if (!std::isfinite(e)) {
    std::ostringstream s;
    s << "non-finite total energy (" << e << " J, the sum over the bodies) at step " << step_
      << " (t = " << time_ << " s)";
    failure_ = s.str();
    return false;
  }
  // Negated, so that NaN fails too (an infinite start makes the growth inf - inf).
  if (!(e - energy0_ <= (sim_.max_energy_ratio - 1.0) * energy_scale_)) {
    std::ostringstream s;
    s << "energy grew from " << shortest(energy0_) << " J to " << shortest(e)
      << " J (more than max_energy_ratio = " << shortest(sim_.max_energy_ratio)
      << " times the budget) at step " << step_ << " (t = " << time_ << " s)";
    failure_ = s.str();
    return false;
  }
  return true;
}

bool World::step() {
  if (!failure_.empty()) return false;
  if (contact_model_ == ContactModel::Extended)
    step_extended();  // manifolds, friction, resting contact, time of impact
  else
    step_seed();
  ++step_;
  time_ = step_ * sim_.dt;
  return check_state();
}

void World::step_seed() {
  // Bounding check, detection and response, in index order (deterministic). Responses change
  // velocities only, never poses, so the pairs passing the bounding check are fixed for the
  // whole step and the broad phase can find them all first; it returns them in the seed's
  // (i, j) order, so the contacts are resolved in the same order as by the double loop.
  if (broad_phase_.method() == BroadPhaseMethod::AllPairs) {
    // The seed's double loop, kept as it was (the oracle of the broad phase).
    const int n = static_cast<int>(bodies_.size());
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) collide_pair(i, j, false);
  } else {
    for (const BodyPair& pair : broad_phase_.find_pairs(bodies_))
      collide_pair(pair.first, pair.second, true);
  }
  const std::vector<ShapeFacts>& facts = shape_facts();
  for (size_t i = 0; i < bodies_.size(); ++i)
    integrate(bodies_[i], sim_, sim_.dt, &facts[i].principal);
}

const std::vector<World::ShapeFacts>& World::shape_facts() {
  if (facts_.size() != bodies_.size()) {
    facts_.assign(bodies_.size(), {});
    for (size_t k = 0; k < bodies_.size(); ++k) {
      const ConvexPolyhedron& shape = *bodies_[k].shape;
      ShapeFacts& f = facts_[k];
      f.thickness = shape_thickness(shape);
      for (const Vec3& v : shape.vertices()) f.radius = std::max(f.radius, v.norm());
      f.reach = tolerance_reach(shape);
      f.own_tol = point_in_mesh_tolerance(shape, shape);
      f.principal = principal_frame(bodies_[k].inertia_body);
    }
  }
  return facts_;
}

RunResult World::run() {
  RunResult r;
  const long steps = sim_.steps();
  while (step_ < steps && step()) {
  }
  r.ok = failure_.empty();
  r.message = failure_;
  r.steps_taken = step_;
  r.events = events_;
  r.bodies = bodies_;
  return r;
}

RunResult run_scene(const Scene& scene, DetectorVariant variant, BroadPhaseMethod broad_phase) {
  std::vector<RigidBody> bodies;
  for (const BodySpec& spec : scene.bodies) bodies.push_back(make_body(spec));
  World world(scene.sim, std::move(bodies), variant, broad_phase);
  return world.run();
}

}  // namespace rbx
