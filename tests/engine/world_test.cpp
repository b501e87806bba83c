// The world step: detection + response + integration on whole runs, events, guards, determinism.
#include "engine/world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <type_traits>
#include <utility>
#include <vector>

#include "engine/detect.h"
#include "engine/response.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::box_body;

SimSettings sim_with(double dt, double duration, double e) {
  SimSettings s;
  s.dt = dt;
  s.duration = duration;
  s.restitution = e;
  return s;
}

TEST(World, HeadOnElasticEqualMassesExchangeVelocities) {
  // Unit cubes 0.5 m apart (gap between faces), closing at 2 m/s: one face-face impact, after
  // which the 1-D closed form for equal masses and e = 1 is an exchange of velocities.
  std::vector<RigidBody> bodies = {
      box_body("A", Vec3::Ones(), 1, Vec3(-0.75, 0, 0), Quat::Identity(), Vec3(1, 0, 0)),
      box_body("B", Vec3::Ones(), 1, Vec3(0.75, 0, 0), Quat::Identity(), Vec3(-1, 0, 0))};
  World w(sim_with(1e-3, 0.6, 1.0), bodies, ContactModel::Seed);
  const RunResult r = w.run();
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.events.size(), 1u);
  const CollisionEvent& e = r.events.front();
  EXPECT_EQ(e.body_a, "A");
  EXPECT_EQ(e.contact.feature, "face");
  // Normal from B toward A is -x; the impulse is 2 m v_rel / (1/m + 1/m) / ... = 2 N s.
  EXPECT_LT((e.contact.normal - Vec3(-1, 0, 0)).norm(), 1e-12);
  EXPECT_NEAR(e.impulse, 2.0, 1e-12);
  // Detection happens after penetration: contact within one step of t = 0.25 s.
  EXPECT_NEAR(e.time, 0.25, 1e-3 + 1e-12);
  EXPECT_LT((r.bodies[0].velocity - Vec3(-1, 0, 0)).norm(), 1e-12);
  EXPECT_LT((r.bodies[1].velocity - Vec3(1, 0, 0)).norm(), 1e-12);
  EXPECT_LT(r.bodies[0].angular_velocity.norm(), 1e-12);  // central: no spin
}

TEST(World, CrossedBarsCollideEdgeOnEdge) {
  // scenes/analytic/crossed_bars.toml built by hand: two 2 x 0.2 x 0.2 bars turned 45 deg about
  // their long axes, A (along x) falling at 1 m/s onto B (along y). Their edges cross at one
  // point, so the world must resolve it through the edge test with the edge-edge normal
  // e_A x e_B = (0, 0, 1), and the impulse is the scene's closed form j = 101/152 N s.
  const double h = 0.1 * std::sqrt(2.0);
  std::vector<RigidBody> bodies = {
      box_body("A", Vec3(2, 0.2, 0.2), 1, Vec3(-0.5, 0, h + 0.05 + h),
               Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX())), Vec3(0, 0, -1)),
      box_body("B", Vec3(0.2, 2, 0.2), 1, Vec3(0, 0.3, 0),
               Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY())))};
  World w(sim_with(1e-3, 0.15, 1.0), bodies, ContactModel::Seed);
  const RunResult r = w.run();
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.events.size(), 1u);
  const CollisionEvent& e = r.events.front();
  EXPECT_EQ(e.contact.feature, "edge");
  EXPECT_LT((e.contact.normal - Vec3(0, 0, 1)).norm(), 1e-12);
  // The edges cross on the line x = y = 0; detection after penetration puts the point up to
  // one step's travel (1 mm) below the touching height h.
  EXPECT_LT(std::abs(e.contact.point.x()) + std::abs(e.contact.point.y()), 1e-12);
  EXPECT_NEAR(e.contact.point.z(), h, 1e-3 + 1e-12);
  // Pure translation before the impact leaves r x n unchanged: the impulse is exact.
  EXPECT_NEAR(e.impulse, 101.0 / 152.0, 1e-12);
}

// Six boxes of different masses, poses and spins that collide several times in 0.5 s.
std::vector<RigidBody> six_boxes() {
  std::vector<RigidBody> bodies;
  for (int i = 0; i < 6; ++i)
    bodies.push_back(box_body("b" + std::to_string(i), Vec3(0.5, 0.6, 0.7), 1 + i,
                              Vec3(0.8 * i, 0.1 * (i % 2), 0),
                              Quat(Eigen::AngleAxisd(0.3 * i, Vec3(1, 1, 0).normalized())),
                              Vec3(i % 2 ? -1 : 1, 0.1, 0), Vec3(0, 0, 0.5 * i)));
  return bodies;
}

bool same_bits(const Vec3& a, const Vec3& b) {
  return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
}

// Two runs with collisions, the same number of events and every body's final state bit for bit.
void expect_identical_runs(const RunResult& r1, const RunResult& r2) {
  ASSERT_EQ(r1.events.size(), r2.events.size());
  EXPECT_GT(r1.events.size(), 0u);
  ASSERT_EQ(r1.bodies.size(), r2.bodies.size());
  for (size_t i = 0; i < r1.bodies.size(); ++i) {
    EXPECT_TRUE(same_bits(r1.bodies[i].position, r2.bodies[i].position)) << i;
    EXPECT_TRUE(same_bits(r1.bodies[i].velocity, r2.bodies[i].velocity)) << i;
    EXPECT_TRUE(same_bits(r1.bodies[i].angular_velocity, r2.bodies[i].angular_velocity)) << i;
  }
}

// A world is built with its contact model named: no default picks the seed's for a caller who
// meant the extended engine's.
static_assert(!std::is_constructible_v<World, SimSettings, std::vector<RigidBody>>);
static_assert(std::is_constructible_v<World, SimSettings, std::vector<RigidBody>, ContactModel>);

TEST(World, RunsAreBitwiseDeterministic) {
  for (const ContactModel model : {ContactModel::Seed, ContactModel::Extended}) {
    World w1(sim_with(1e-3, 0.5, 0.8), six_boxes(), model),
        w2(sim_with(1e-3, 0.5, 0.8), six_boxes(), model);
    expect_identical_runs(w1.run(), w2.run());
  }
}

// A response given as a function (World::set_response, the hook behind a researcher's own
// response backend) replaces the seed's impulse: handed the seed's own impulse it reproduces the
// seed's run bit for bit; handed e = 1 on an e = 0.5 scene it bounces elastically.
TEST(World, AResponseFunctionReplacesTheSeedsImpulse) {
  World seed(sim_with(1e-3, 0.5, 0.8), six_boxes(), ContactModel::Seed),
      hooked(sim_with(1e-3, 0.5, 0.8), six_boxes(), ContactModel::Seed);
  hooked.set_response([](const RigidBody& a, const RigidBody& b, const ContactPoint& c,
                         double e) -> Vec3 { return impulse_magnitude(a, b, c, e) * c.normal; });
  expect_identical_runs(seed.run(), hooked.run());
  std::vector<RigidBody> pair = {
      box_body("A", Vec3::Ones(), 1, Vec3(-0.75, 0, 0), Quat::Identity(), Vec3(1, 0, 0)),
      box_body("B", Vec3::Ones(), 1, Vec3(0.75, 0, 0), Quat::Identity(), Vec3(-1, 0, 0))};
  World elastic(sim_with(1e-3, 0.6, 0.5), pair, ContactModel::Seed);
  elastic.set_response([](const RigidBody& a, const RigidBody& b, const ContactPoint& c,
                          double) -> Vec3 { return impulse_magnitude(a, b, c, 1.0) * c.normal; });
  const RunResult r = elastic.run();
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_LT((r.bodies[0].velocity - Vec3(-1, 0, 0)).norm(), 1e-12);  // e = 1's exchange
  World broken(sim_with(1e-3, 0.6, 0.5), pair, ContactModel::Seed);
  broken.set_response([](const RigidBody&, const RigidBody&, const ContactPoint&, double) {
    return Vec3(NAN, 0, 0);
  });
  EXPECT_THROW(broken.run(), std::runtime_error);
}

TEST(World, NonFiniteStateStopsTheRunNamingBodyAndQuantity) {
  std::vector<RigidBody> bodies = {
      box_body("A", Vec3::Ones(), 1, Vec3::Zero(), Quat::Identity(), Vec3(NAN, 0, 0))};
  World w(sim_with(1e-3, 1.0, 1.0), bodies, ContactModel::Seed);
  const RunResult r = w.run();
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.steps_taken, 1);
  EXPECT_NE(r.message.find("non-finite position of body A at step 1"), std::string::npos)
      << r.message;
}

TEST(World, EnergyGuardStopsARunawayRun) {
  // The seed's explicit Euler gains m g^2 dt^2 / 2 of energy per step in free fall; a guard
  // set just above 1 catches it on the first step.
  SimSettings s = sim_with(1e-2, 1.0, 1.0);
  s.integrator = Integrator::Euler;
  s.gravity = Vec3(0, 0, -9.81);
  s.max_energy_ratio = 1.0 + 1e-9;
  World w(s, {box_body("A", Vec3::Ones(), 1, Vec3::Zero())}, ContactModel::Seed);
  const RunResult r = w.run();
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("energy grew"), std::string::npos) << r.message;
  // The default guard (1e3) lets the same run finish.
  s.max_energy_ratio = 1e3;
  World ok(s, {box_body("A", Vec3::Ones(), 1, Vec3::Zero())}, ContactModel::Seed);
  EXPECT_TRUE(ok.run().ok);
}

TEST(World, EnergyGuardCatchesAnInfiniteInitialEnergy) {
  // v = 1e155 m/s is finite, but 1/2 m v^2 = 5e309 J overflows to inf; the growth test then
  // compared inf - inf = NaN, which is never greater than a bound, and the run went on.
  World w(sim_with(1e-3, 1.0, 1.0),
          {box_body("A", Vec3::Ones(), 1, Vec3::Zero(), Quat::Identity(), Vec3(1e155, 0, 0))},
          ContactModel::Seed);
  const RunResult r = w.run();
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.steps_taken, 1);
  EXPECT_EQ(r.message, "non-finite kinetic energy of body A at step 1 (t = 0.001 s)");
}

TEST(World, EnergyGuardCatchesATotalThatOverflows) {
  // Two bodies of 1.69e308 J each (m = 2 kg, v = 1.3e154 m/s): each finite (the limit is
  // 1.8e308), their sum inf.
  const double v = 1.3e154;
  World w(sim_with(1e-3, 1.0, 1.0),
          {box_body("A", Vec3::Ones(), 2, Vec3::Zero(), Quat::Identity(), Vec3(v, 0, 0)),
           box_body("B", Vec3::Ones(), 2, Vec3(0, 0, 10), Quat::Identity(), Vec3(v, 0, 0))},
          ContactModel::Seed);
  const RunResult r = w.run();
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.steps_taken, 1) << r.message;
  EXPECT_EQ(r.message.rfind("non-finite total energy (inf J", 0), 0u) << r.message;
}

TEST(World, EnergyGuardMessageShowsTheRatioAsGiven) {
  // Explicit Euler in free fall gains m g^2 dt^2 / 2 = 0.0048 J on the first step, far past a
  // budget of 1e-6 times the gravity work scale; the ratio must print as 1.000001, not as "1".
  SimSettings s = sim_with(1e-2, 1.0, 1.0);
  s.integrator = Integrator::Euler;
  s.gravity = Vec3(0, 0, -9.81);
  s.max_energy_ratio = 1.000001;
  World w(s, {box_body("A", Vec3::Ones(), 1, Vec3::Zero())}, ContactModel::Seed);
  const RunResult r = w.run();
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.message.find("(more than max_energy_ratio = 1.000001 times the budget) at step 1"),
            std::string::npos)
      << r.message;
}

TEST(World, StaticPairsAndDistantPairsProduceNoEvents) {
  std::vector<RigidBody> bodies = {
      box_body("A", Vec3::Ones(), 1, Vec3::Zero(), Quat::Identity(), Vec3::Zero(), Vec3::Zero(),
               true),
      box_body("B", Vec3::Ones(), 1, Vec3(0.5, 0, 0), Quat::Identity(), Vec3::Zero(), Vec3::Zero(),
               true),
      box_body("C", Vec3::Ones(), 1, Vec3(10, 0, 0), Quat::Identity(), Vec3(1, 0, 0))};
  World w(sim_with(1e-3, 0.1, 1.0), bodies, ContactModel::Seed);
  const RunResult r = w.run();
  EXPECT_TRUE(r.ok);
  EXPECT_TRUE(r.events.empty());
  EXPECT_NEAR(r.bodies[2].position.x(), 10.1, 1e-12);
}

TEST(World, VertexOnStaticSlabBouncesWithClosedFormSpin) {
  // A unit cube (I = m/6, isotropic) rotated so one corner points straight down falls onto a
  // static slab at 1 m/s. Corner r = (0, 0, -sqrt(3)/2), n = +z: r x n = 0, so the impact is
  // central: j = (1 + e) m v and no spin, v' = e v up. The detector must find the vertex.
  const Quat q = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3(0, 0, -1));
  const double h = std::sqrt(3.0) / 2;
  std::vector<RigidBody> bodies = {
      box_body("A", Vec3::Ones(), 1, Vec3(0, 0, h + 0.05), q, Vec3(0, 0, -1)),
      box_body("B", Vec3(4, 4, 1), 1, Vec3(0, 0, -0.5), Quat::Identity(), Vec3::Zero(),
               Vec3::Zero(), true)};
  World w(sim_with(1e-3, 0.2, 0.5), bodies, ContactModel::Seed);
  const RunResult r = w.run();
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_GE(r.events.size(), 1u);
  EXPECT_EQ(r.events.front().contact.feature, "vertex");
  EXPECT_LT((r.events.front().contact.normal - Vec3(0, 0, 1)).norm(), 1e-9);
  // Round-off only: the corner lies on the axis through the COM up to 1e-15.
  EXPECT_NEAR(r.bodies[0].velocity.z(), 0.5, 1e-9);
  EXPECT_LT(r.bodies[0].angular_velocity.norm(), 1e-9);
}

// The step skips the detector on pairs it proves apart, by bounds carried from step to step
// (ExtendedStep::separated): none of them may be a pair in contact. Flat boxes sliding and
// spinning on a floor in a walled bin, so that pairs meet, push, slide along each other and
// part: every pair the detector finds touching at a step's start has its points solved in that
// step. (One layer: boxes piled under gravity make friction solves that are slow, a known limit
// of the solver, docs/ensemble.md.)
TEST(World, EveryPairTouchingAtAStepsStartIsSolvedInThatStep) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.2, 0.4);
  SimSettings sim;
  sim.dt = 0.005;
  sim.gravity = Vec3(0.0, 0.0, -9.81);
  sim.restitution = 0.3;
  sim.friction = 0.2;
  std::vector<RigidBody> bodies;
  const auto wall = [&](const Vec3& extent, const Vec3& at) {
    bodies.push_back(test::box_body("wall", extent, 1.0, at, Quat::Identity(), Vec3::Zero(),
                                    Vec3::Zero(), true));
  };
  wall(Vec3(3, 3, 0.2), Vec3(0, 0, -0.1));
  wall(Vec3(0.2, 3, 1), Vec3(-1.1, 0, 0.5));
  wall(Vec3(0.2, 3, 1), Vec3(1.1, 0, 0.5));
  wall(Vec3(3, 0.2, 1), Vec3(0, -1.1, 0.5));
  wall(Vec3(3, 0.2, 1), Vec3(0, 1.1, 0.5));
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 4; ++y) {
      const Vec3 extent(size(rng), size(rng), 0.1);
      const Vec3 at(-0.75 + 0.5 * x, -0.75 + 0.5 * y, 0.05);
      const Quat q(Eigen::AngleAxisd(3.0 * u(rng), Vec3::UnitZ()));
      const Vec3 v = 3.0 * Vec3(u(rng), u(rng), 0.0);
      bodies.push_back(test::box_body("box", extent, 1.0, at, q, v, Vec3(0, 0, 10.0 * u(rng))));
    }
  World world(sim, bodies, ContactModel::Extended);
  long touching_pairs = 0, between_boxes = 0;
  for (int step = 0; step < 400; ++step) {
    const std::vector<RigidBody>& now = world.bodies();
    std::vector<std::pair<int, int>> touching;
    for (int i = 0; i < static_cast<int>(now.size()); ++i)
      for (int j = i + 1; j < static_cast<int>(now.size()); ++j)
        if (!(now[i].is_static && now[j].is_static) &&
            detect(*now[i].shape, now[i].pose(), *now[j].shape, now[j].pose(),
                   Detector::Accelerated))
          touching.emplace_back(i, j);
    ASSERT_TRUE(world.step()) << world.failure();
    for (const std::pair<int, int>& pair : touching) {
      // Named, not bound: a lambda may not capture a structured binding before C++20.
      const int i = pair.first, j = pair.second;
      ++touching_pairs;
      if (!now[i].is_static && !now[j].is_static) ++between_boxes;
      const bool solved = std::any_of(
          world.step_contacts().begin(), world.step_contacts().end(),
          [&](const SolvedContact& c) { return std::minmax(c.a, c.b) == std::minmax(i, j); });
      EXPECT_TRUE(solved) << "step " << step << ": bodies " << i << " and " << j;
    }
  }
  // Contacts of every kind over the run: on the floor, against the walls, between boxes.
  EXPECT_GT(touching_pairs, 2000);
  EXPECT_GT(between_boxes, 100);
}

}  // namespace
}  // namespace rbx

namespace rbx {
namespace {

TEST(World, StepContactsAreTheSolvedPointsWithTheirImpulses) {
  // A unit cube resting on a static floor: the last step's points carry the impulse that holds
  // its weight for one step, pushing it up, at its centre's height minus half its size.
  SimSettings sim;
  sim.dt = 0.01;
  sim.gravity = Vec3(0.0, 0.0, -9.81);
  sim.restitution = 0.0;
  sim.friction = 0.5;
  const RigidBody floor = test::box_body("floor", Vec3(10.0, 10.0, 1.0), 1.0, Vec3(0.0, 0.0, -0.5),
                                         Quat::Identity(), Vec3::Zero(), Vec3::Zero(), true);
  const RigidBody cube = test::box_body("cube", Vec3::Ones(), 2.0, Vec3(0.0, 0.0, 0.5));
  World world(sim, {floor, cube}, ContactModel::Extended);
  EXPECT_TRUE(world.step_contacts().empty());
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(world.step());
  Vec3 total = Vec3::Zero();
  for (const SolvedContact& c : world.step_contacts()) {
    EXPECT_EQ(c.a, 0);
    EXPECT_EQ(c.b, 1);
    EXPECT_NEAR(c.point.z(), 0.0, 1e-9);
    // Its centre at detection: the cube rests, so where it is now, to round-off.
    EXPECT_LT((c.centre_b - world.bodies()[1].position).norm(), 1e-15);
    total += c.impulse;  // on the floor, so the cube takes -total
  }
  EXPECT_GE(world.step_contacts().size(), 3u);
  // Round-off of the solve: 1e-12 of the weight's impulse.
  EXPECT_NEAR(-total.z(), 2.0 * 9.81 * sim.dt, 1e-12 * 2.0 * 9.81 * sim.dt);
  EXPECT_NEAR(total.head<2>().norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace rbx
