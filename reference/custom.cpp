#include "reference/custom.h"

#include <exception>
#include <string>
#include <utility>

#include "engine/detect.h"
#include "engine/distance.h"
#include "engine/manifold.h"
#include "engine/sweep.h"
#include "reference/dynamics_recorder.h"

namespace rbx {

namespace {

// The contact of the `custom` backend on either detector: the manifold its world steps with
// (engine/manifold.h), its one-point contact first (the plane of least overlap and the centre of
// the contact region for shapes proved to overlap, the detector's point for the rest), then every
// point of the manifold, all on the manifold's normal. One detection cache, one contact
// scratch and one manifold per thread, reused by every query as a world's step reuses its own:
// their lists are allocated once. Answers do not depend on them.
ContactResult engine_contact(const RigidBody& a, const RigidBody& b, Detector detector) {
  thread_local DetectionCache cache;
  thread_local ContactScratch scratch;
  thread_local ContactManifold m;
  ContactResult r;
  if (!build_manifold(*a.shape, a.pose(), *b.shape, b.pose(), detector,
                      WorldSettings{}.position_slop, cache, scratch, m))
    return r;
  r.contacts.reserve(1 + m.points.size());  // no reallocation below: `feature` stays valid
  r.contacts.push_back(std::move(m.contact));
  const std::string& feature = r.contacts.front().feature;
  for (const ManifoldPoint& p : m.points)
    r.contacts.push_back({p.point, m.normal, p.depth, feature});
  return r;
}

// `custom`: the accelerated detector where one is needed.
ContactResult custom_contact(const RigidBody& a, const RigidBody& b) {
  return engine_contact(a, b, Detector::Accelerated);
}

// Variant "faithful" of `custom`: the seed's loops over every primitive (the accelerated
// detector's reference) where a detector is needed; the same answer, slower on touching poses.
ContactResult custom_faithful_contact(const RigidBody& a, const RigidBody& b) {
  return engine_contact(a, b, Detector::Faithful);
}

BodyFinal final_of(const RigidBody& b) {
  return {b.name, b.position, b.orientation, b.velocity, b.angular_velocity};
}

DynamicsResult run_dynamics(const WorldDefinition& scene, const DynamicsOptions& opt,
                            ContactModel model, const ResponseFn& response = {}) {
  DynamicsResult r;
  try {
    SimSettings sim = scene.sim;
    if (opt.dt > 0) sim.dt = opt.dt;
    // A studied budget caps the projections' iterations per island solve (custom_budget).
    WorldSettings tunables;
    tunables.iteration_budget = opt.budget;
    World world(sim, make_bodies(scene), model, Detector::Accelerated, BroadPhaseMethod::Tree,
                tunables);
    world.set_response(response);
    const long steps = sim.steps();
    DynamicsRecorder recorder(r, opt, [&] {
      std::vector<BodyFinal> states;
      for (const RigidBody& b : world.bodies()) states.push_back(final_of(b));
      return states;
    });
    recorder.measure_contact_laws(scene);
    recorder.start();
    while (world.steps_taken() < steps) {
      recorder.before_step(world.events());
      if (!world.step()) break;
      // The first impulse from the step's events (the engine's: one per resolved contact).
      recorder.first_impulse_from_step(world.events(), sim.dt);
      // Every solved point with its centres at detection (a time of impact's are mid-step).
      for (const SolvedContact& c : world.step_contacts()) recorder.contact(c);
      recorder.after_step(world.steps_taken(), world.time());
    }
    recorder.finish_laws();
    if (!world.failure().empty()) {
      r.status = Status::Error;
      r.message = world.failure();
    }
    r.events = world.events();
    for (const RigidBody& b : world.bodies()) r.finals.push_back(final_of(b));
  } catch (const std::exception& e) {
    r.status = Status::Error;
    r.message = e.what();
  }
  return r;
}

// `custom`: the extended engine (manifolds, Coulomb friction, resting contact, time of impact).
DynamicsResult custom_dynamics(const WorldDefinition& scene, const DynamicsOptions& opt) {
  return run_dynamics(scene, opt, ContactModel::Extended);
}

// `custom-seed`: the seed's algorithm and its corrections only (first hit, single-point
// frictionless impulse, no time of impact).
DynamicsResult custom_seed_dynamics(const WorldDefinition& scene, const DynamicsOptions& opt) {
  return run_dynamics(scene, opt, ContactModel::Seed);
}

// `custom`'s distance query: the engine's GJK (engine/distance.h), as it is.
DistanceResult custom_distance(const RigidBody& a, const RigidBody& b) {
  const Separation s = shape_distance(*a.shape, a.pose(), *b.shape, b.pose());
  DistanceResult r;
  r.overlapping = s.overlapping;
  r.distance = s.distance;
  r.point_a = s.point_a;
  r.point_b = s.point_b;
  return r;
}

// `custom`'s time of impact: conservative advancement on its GJK (engine/sweep.h), as it is.
ToiResult custom_toi(const RigidBody& a, const RigidBody& b, double dt) {
  const SweepImpact s =
      sweep_time_of_impact(*a.shape, {a.pose(), a.velocity, a.angular_velocity}, *b.shape,
                           {b.pose(), b.velocity, b.angular_velocity}, dt);
  ToiResult r;
  if (!s.certified) {
    r.status = Status::Error;
    r.message = "conservative advancement reached its step limit before a touch or the end";
    return r;
  }
  r.hit = s.hit;
  r.fraction = s.hit ? s.time / dt : 1.0;
  r.located = s.located;
  r.point = s.point;
  r.normal = s.normal;
  return r;
}

}  // namespace

DynamicsResult custom_seed_dynamics_with(const WorldDefinition& scene, const DynamicsOptions& opt,
                                         const ResponseFn& response) {
  return run_dynamics(scene, opt, ContactModel::Seed, response);
}

// The budget studied: the projected Gauss-Seidel iterations of one island solve, both stages
// together (WorldSettings::iteration_budget). The engine itself has no budget: it solves to
// convergence (configured 0), and islands of up to 32 points are settled by active sets first,
// which no budget limits.
SolverBudget custom_budget() {
  return {
      "iteration_budget (projected Gauss-Seidel iterations per island solve, after the active "
      "sets)",
      {1, 10, 100, 1000},
      0,
      0};
}

const Adapter& custom_adapter() {
  // The engine's own code: not isolated (library = false); the seed model has no friction.
  static const Adapter adapter = {
      {
          with_budget(
              {"custom",
               "rbx engine, extended: the plane of least overlap, the contact patch clipped on "
               "it (Moore & Wilhelms tests where overlap is not proved), the same manifold for "
               "the query and the step, Coulomb friction, resting contact, time of impact for "
               "every new contact",
               custom_contact, custom_dynamics, nullptr, false},
              custom_budget())
              .measuring(custom_distance)
              .sweeping(custom_toi)
              .drawn("#0072B2", "o")
              .timed(8192, 2048),
          Backend{"custom-seed",
                  "rbx engine, the seed's algorithm: first hit, single-point frictionless impulse",
                  nullptr, custom_seed_dynamics, nullptr, false, false}
              .drawn("#56B4E9", "s"),
      },
      {
          {"custom",
           "faithful",
           "custom on the faithful detector: the seed's loops over every primitive (the "
           "accelerated detector's reference), the same chosen plane",
           custom_faithful_contact,
           {2048, 512}},
      }};
  return adapter;
}

}  // namespace rbx
