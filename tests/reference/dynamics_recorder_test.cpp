// DynamicsRecorder: what every dynamics adapter records the same way. Samples at t = 0 and
// after every sample_every steps; the states before the step of the first impulse, read no more
// after it; the first impulse from all the step's events or from its first event alone.
#include "reference/dynamics_recorder.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "tests/common/fixtures.h"

namespace rbx {
namespace {

// A fake run: one body whose velocity is the step count, and the events a test adds.
struct FakeRun {
  long steps = 0;
  int reads = 0;  // how many times the recorder read the states
  std::vector<CollisionEvent> events;
  std::vector<BodyFinal> states() {
    ++reads;
    BodyFinal a;
    a.name = "a";
    a.position = Vec3(0.0, 1.0, 0.0);
    a.velocity = Vec3(0.0, -static_cast<double>(steps), 0.0);
    BodyFinal floor;
    floor.name = "floor";
    return {a, floor};
  }
  // An event of the pair (a, floor) at `point` (m), normal +y, at the current step.
  void hit(const Vec3& point, double impulse) {
    CollisionEvent ev;
    ev.step = steps;
    ev.body_a = "a";
    ev.body_b = "floor";
    ev.contact.point = point;
    ev.contact.normal = Vec3::UnitY();
    ev.contact.depth = 0.001;
    ev.impulse = impulse;
    events.push_back(ev);
  }
};

TEST(DynamicsRecorder, SamplesAtTheStartAndEverySampleEverySteps) {
  DynamicsResult result;
  FakeRun run;
  DynamicsRecorder recorder(result, {0.0, 2}, [&] { return run.states(); });
  recorder.start();
  for (long k = 0; k < 5; ++k) {
    recorder.before_step(run.events);
    ++run.steps;
    recorder.after_step(k + 1, (k + 1) * 0.1);
  }
  ASSERT_EQ(result.samples.size(), 3u);
  EXPECT_EQ(result.samples[0].time, 0.0);
  EXPECT_EQ(result.samples[1].time, 2 * 0.1);
  EXPECT_EQ(result.samples[2].time, 4 * 0.1);
  EXPECT_EQ(result.samples[2].bodies[0].velocity.y(), -4.0);
}

TEST(DynamicsRecorder, NoSamplesWhenNotAsked) {
  DynamicsResult result;
  FakeRun run;
  DynamicsRecorder recorder(result, {}, [&] { return run.states(); });
  recorder.start();
  recorder.after_step(1, 0.1);
  EXPECT_TRUE(result.samples.empty());
}

TEST(DynamicsRecorder, TheFirstImpulseComesFromTheStepsEventsAndTheStatesBeforeIt) {
  DynamicsResult result;
  FakeRun run;
  DynamicsRecorder recorder(result, {}, [&] { return run.states(); });
  recorder.start();
  // Two quiet steps, then a step with two points of the pair, then one more event.
  for (long k = 0; k < 4; ++k) {
    recorder.before_step(run.events);
    ++run.steps;
    if (k == 2) {
      run.hit(Vec3(-0.1, 0.0, 0.0), 1.0);
      run.hit(Vec3(0.1, 0.0, 0.0), 2.0);
    }
    if (k == 3) run.hit(Vec3::Zero(), 5.0);
    recorder.first_impulse_from_step(run.events, 0.01);
  }
  const FirstImpulse& f = result.first_impulse;
  ASSERT_TRUE(f.seen);
  EXPECT_EQ(f.step, 3);
  EXPECT_EQ(f.contact_points, 2);
  EXPECT_EQ(f.impulse, 3.0);
  EXPECT_EQ(f.point, Vec3::Zero());
  // Before the step of the impulse the body moved at -2 m/s toward the floor.
  EXPECT_EQ(f.approach_speed, 2.0);
  // States were read before each step up to that one, and not after it.
  EXPECT_EQ(run.reads, 3);
}

TEST(DynamicsRecorder, AFirstEventOfMergedPointsTakesTheLibrarysCount) {
  DynamicsResult result;
  FakeRun run;
  DynamicsRecorder recorder(result, {}, [&] { return run.states(); });
  recorder.before_step(run.events);
  EXPECT_EQ(recorder.first_new_event(run.events), nullptr);  // nothing added yet
  run.hit(Vec3::Zero(), 4.0);
  const CollisionEvent* first = recorder.first_new_event(run.events);
  ASSERT_EQ(first, &run.events[0]);
  recorder.first_impulse_from_event(*first, 0.01, 4);
  EXPECT_TRUE(result.first_impulse.seen);
  EXPECT_EQ(result.first_impulse.contact_points, 4);
  // Seen: the next step's events are not a first impulse.
  recorder.before_step(run.events);
  run.hit(Vec3::Zero(), 1.0);
  EXPECT_EQ(recorder.first_new_event(run.events), nullptr);
}

TEST(DynamicsRecorder, AFiniteRunKeepsItsStatusAndANonFiniteOneIsAnError) {
  DynamicsResult result;
  FakeRun run;
  DynamicsRecorder recorder(result, {}, [&] { return run.states(); });
  recorder.finish("Lib");
  EXPECT_EQ(result.status, Status::Ok);
  EXPECT_EQ(result.finals.size(), 2u);

  DynamicsResult bad;
  DynamicsRecorder broken(bad, {}, [&] {
    std::vector<BodyFinal> states = run.states();
    states[0].velocity.x() = std::numeric_limits<double>::quiet_NaN();
    return states;
  });
  broken.finish("Lib");
  EXPECT_EQ(bad.status, Status::Error);
  EXPECT_EQ(bad.message, "Lib: non-finite final state of a");
  EXPECT_EQ(bad.finals.size(), 2u);
}

}  // namespace
}  // namespace rbx

namespace rbx {
namespace {

TEST(DynamicsRecorder, ScoresTheContactLawsOnTheVelocitiesAroundEachStep) {
  // Body a falls faster every step (velocity -k before step k, -(k+1) after it): a contact that
  // pushed 1 N s up and yet leaves the bodies approaching at 1 m/s misses complementarity by
  // 1 N s x 1 m/s; its friction, 0.3 < mu j_n = 0.5 with no slip, obeys the cone.
  DynamicsResult result;
  FakeRun run;
  DynamicsRecorder recorder(result, {}, [&] { return run.states(); });
  WorldDefinition scene;
  scene.sim.restitution = 0.0;
  scene.sim.friction = 0.5;
  scene.bodies = {test::box_spec("a", Vec3::Ones(), Vec3(0.0, 1.0, 0.0)),
                  test::box_spec("floor", Vec3::Ones(), Vec3::Zero())};
  scene.bodies[1].is_static = true;
  recorder.measure_contact_laws(scene);
  recorder.start();
  for (long k = 0; k < 3; ++k) {
    recorder.before_step(run.events);
    ++run.steps;
    if (k == 0) {
      SolvedContact c;
      c.a = 0;
      c.b = 1;
      c.point = Vec3(0.0, 0.5, 0.0);
      c.normal = Vec3::UnitY();
      c.impulse = Vec3(0.3, 1.0, 0.0);
      recorder.contact_at_start(c);
    }
    recorder.after_step(k + 1, (k + 1) * 0.1);
  }
  EXPECT_FALSE(result.laws.measured);  // filled when the run ends
  recorder.finish_laws();
  ASSERT_TRUE(result.laws.measured);
  EXPECT_EQ(result.laws.contacts, 1);
  for (Law law : kAllLaws)
    EXPECT_DOUBLE_EQ(result.laws.residuals[static_cast<int>(law)].worst,
                     law == Law::Complementarity ? 1.0 : 0.0)
        << to_string(law);
}

TEST(DynamicsRecorder, FollowsTheFrictionBeyondTheConeAtPointsThatCarryNoNormalImpulse) {
  // A unit cube (1 kg, inertia 1/6 about z) sliding at 1 m/s along x on a static floor, two
  // steps of 0.01 s. Each step one corner pushes (0.5 N s up, at y = +0.5) and one carries no
  // normal impulse yet a friction impulse of 0.01 N s against the slide (at y = -0.5): all of
  // it beyond the cone.
  DynamicsResult result;
  auto states = [] {
    BodyFinal a;
    a.name = "a";
    a.position = Vec3(0.0, 0.0, 0.5);
    a.velocity = Vec3(1.0, 0.0, 0.0);
    BodyFinal floor;
    floor.name = "floor";
    return std::vector<BodyFinal>{a, floor};
  };
  DynamicsRecorder recorder(result, {}, states);
  WorldDefinition scene;
  scene.sim.friction = 0.5;
  scene.bodies = {test::box_spec("a", Vec3::Ones(), Vec3(0.0, 0.0, 0.5)),
                  test::box_spec("floor", Vec3(4.0, 4.0, 1.0), Vec3(0.0, 0.0, -0.5))};
  scene.bodies[1].is_static = true;
  recorder.measure_contact_laws(scene);
  recorder.start();
  std::vector<CollisionEvent> events;
  for (long k = 0; k < 2; ++k) {
    recorder.before_step(events);
    SolvedContact loaded;
    loaded.a = 0;
    loaded.b = 1;
    loaded.point = Vec3(0.5, 0.5, 0.0);
    loaded.normal = Vec3::UnitZ();
    loaded.impulse = Vec3(0.0, 0.0, 0.5);
    SolvedContact unloaded = loaded;
    unloaded.point = Vec3(0.5, -0.5, 0.0);
    // Its normal impulse is round-off (a library's friction direction off the plane by 1e-17):
    // no load, judged against the step's largest normal impulse.
    unloaded.impulse = Vec3(-0.01, 0.0, 1e-21);
    recorder.contact_at_start(loaded);
    recorder.contact_at_start(unloaded);
    recorder.after_step(k + 1, (k + 1) * 0.01);
  }
  recorder.finish_laws();
  ASSERT_EQ(result.laws.cone_excess.size(), 1u);
  const ConeExcess& u = result.laws.cone_excess[0];
  EXPECT_EQ(u.body, 0);
  EXPECT_EQ(u.points, 2);
  // Torque about z of the unloaded corner: ((0.5, -0.5, -0.5) x (-0.01, 0, 0)) . z = -0.005 N m s;
  // the loaded corner's Coulomb damping: mu j_n (r . x)^2 / |v| = 0.5 x 0.5 x 0.25 = 0.0625. The
  // step's friction directions were set before its excess turned the cube, so each step damps
  // the yaw rate it started with: the first step's excess is undamped until the second.
  const double inertia = 1.0 / 6.0, torque = -0.005, damping = 0.0625;
  const double w1 = torque / inertia;
  const double w2 = w1 / (1.0 + damping / inertia) + torque / inertia;
  EXPECT_NEAR(u.turn_rad, (w1 + w2) * 0.01, 1e-15);
  // Along the slide: -0.01 N s at 1 m/s on 1 kg, each step.
  EXPECT_NEAR(u.push_m2s2, -0.02, 1e-15);
}

TEST(DynamicsRecorder, FindsNoConeExcessWhereEveryFrictionPointPushesEnough) {
  DynamicsResult result;
  FakeRun run;
  DynamicsRecorder recorder(result, {}, [&] { return run.states(); });
  WorldDefinition scene;
  scene.sim.friction = 0.5;
  scene.bodies = {test::box_spec("a", Vec3::Ones(), Vec3(0.0, 1.0, 0.0)),
                  test::box_spec("floor", Vec3::Ones(), Vec3::Zero())};
  scene.bodies[1].is_static = true;
  recorder.measure_contact_laws(scene);
  recorder.start();
  recorder.before_step(run.events);
  SolvedContact c;
  c.a = 0;
  c.b = 1;
  c.normal = Vec3::UnitY();
  c.impulse = Vec3(0.3, 1.0, 0.0);
  recorder.contact_at_start(c);
  recorder.after_step(1, 0.1);
  recorder.finish_laws();
  EXPECT_TRUE(result.laws.cone_excess.empty());
}

TEST(DynamicsRecorder, MeasuresNoContactLawsUnlessAsked) {
  DynamicsResult result;
  FakeRun run;
  DynamicsRecorder recorder(result, {}, [&] { return run.states(); });
  recorder.start();
  recorder.before_step(run.events);
  recorder.contact_at_start({});
  recorder.after_step(1, 0.1);
  recorder.finish_laws();
  EXPECT_FALSE(result.laws.measured);
}

}  // namespace
}  // namespace rbx
