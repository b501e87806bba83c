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

namespace rbx {

World::World(SimSettings sim, std::vector<RigidBody> bodies, ContactModel model, Detector detector,
             BroadPhaseMethod broad_phase, const WorldSettings& tunables)
    : state_(std::move(sim), std::move(bodies), detector, broad_phase, tunables),
      contact_model_(model),
      extended_(tunables) {
  // Energy guard budget: the initial kinetic energy, or the work gravity could do over the
  // bodies' own sizes, whichever is larger, so a scene starting at rest is not flagged.
  energy0_ = energy();
  double kinetic = 0.0, gravity_work = 0.0;
  for (const RigidBody& b : state_.bodies) {
    kinetic += b.kinetic_energy();
    if (!b.is_static)
      gravity_work += b.mass * state_.sim.gravity.norm() * bounding_sphere(b).radius;
  }
  energy_scale_ = std::max({kinetic, gravity_work, 1e-300});
}

double World::energy() const {
  double e = 0.0;
  for (const RigidBody& b : state_.bodies)
    if (!b.is_static) e += b.kinetic_energy() - b.mass * state_.sim.gravity.dot(b.position);
  return e;
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
  if (!state_.uncertain.empty()) {
    failure_ = state_.uncertain;
    return false;
  }
  auto fail = [&](const RigidBody& b, const char* what) {
    std::ostringstream s;
    s << "non-finite " << what << " of body " << b.name << " at step " << state_.step
      << " (t = " << state_.time << " s)";
    failure_ = s.str();
    return false;
  };
  // The total energy is summed on the way, term for term as energy() sums it.
  double e = 0.0;
  for (const RigidBody& b : state_.bodies) {
    if (!b.position.allFinite()) return fail(b, "position");
    if (!b.velocity.allFinite()) return fail(b, "velocity");
    if (!b.angular_velocity.allFinite()) return fail(b, "angular velocity");
    if (!b.orientation.coeffs().allFinite()) return fail(b, "orientation");
    // Finite states can still overflow the energy (1/2 m v^2 at v = 1e155 m/s); the growth test
    // below would then compare inf - inf = NaN, which no bound catches.
    if (b.is_static) continue;
    const double kinetic = b.kinetic_energy();
    const double potential = b.mass * state_.sim.gravity.dot(b.position);
    if (!std::isfinite(kinetic)) return fail(b, "kinetic energy");
    if (!std::isfinite(potential)) return fail(b, "potential energy");
    e += kinetic - potential;
  }
  // The sum of finite energies can still overflow.
  if (!std::isfinite(e)) {
    std::ostringstream s;
    s << "non-finite total energy (" << e << " J, the sum over the bodies) at step " << state_.step
      << " (t = " << state_.time << " s)";
    failure_ = s.str();
    return false;
  }
  // Negated, so that NaN fails too (an infinite start makes the growth inf - inf).
  if (!(e - energy0_ <= (state_.sim.max_energy_ratio - 1.0) * energy_scale_)) {
    std::ostringstream s;
    s << "energy grew from " << shortest(energy0_) << " J to " << shortest(e)
      << " J (more than max_energy_ratio = " << shortest(state_.sim.max_energy_ratio)
      << " times the budget) at step " << state_.step << " (t = " << state_.time << " s)";
    failure_ = s.str();
    return false;
  }
  return true;
}

bool World::step() {
  if (!failure_.empty()) return false;
  state_.step_contacts.clear();
  if (contact_model_ == ContactModel::Extended)
    extended_.advance(state_);  // manifolds, friction, resting contact, time of impact
  else
    seed_.advance(state_);
  ++state_.step;
  state_.time = state_.step * state_.sim.dt;
  return check_state();
}

RunResult World::run() {
  RunResult r;
  const long steps = state_.sim.steps();
  while (state_.step < steps && step()) {
  }
  r.ok = failure_.empty();
  r.message = failure_;
  r.steps_taken = state_.step;
  r.events = state_.events;
  r.bodies = state_.bodies;
  return r;
}

RunResult run_world(const WorldDefinition& definition, ContactModel model, Detector detector,
                    BroadPhaseMethod broad_phase) {
  std::vector<RigidBody> bodies;
  for (const BodySpec& spec : definition.bodies) bodies.push_back(make_body(spec));
  World world(definition.sim, std::move(bodies), model, detector, broad_phase);
  return world.run();
}

}  // namespace rbx
