// Simultaneous impulses: restitution, Coulomb friction, energy, position projection.
#include "engine/contact_solver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "engine/response.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::box_body;

// A one-pair problem: the manifold of bodies[0] and bodies[1] at their poses.
std::vector<PairManifold> manifolds_of(const std::vector<RigidBody>& bodies) {
  const RigidBody &a = bodies[0], &b = bodies[1];
  auto m = build_manifold(*a.shape, a.pose(), *b.shape, b.pose(), DetectorVariant::Faithful);
  if (!m) return {};
  return {{0, 1, *m, a.pose(), b.pose()}};
}

ContactSolverSettings settings(double e, double mu) {
  ContactSolverSettings s;
  s.restitution = e;
  s.friction = mu;
  return s;
}

double kinetic(const std::vector<RigidBody>& bodies) {
  double k = 0.0;
  for (const RigidBody& b : bodies) k += b.kinetic_energy();
  return k;
}

TEST(ContactSolver, OnePointFrictionlessIsTheSeedImpulse) {
  // A corner-down cube hitting a free cube off-centre (seed/vertex_corner's kind): one manifold
  // point, so the simultaneous solve must equal the single-point formula (seed correction 3 ((1 +
  // e) on the whole impulse, only while approaching)-4).
  const Quat q = Quat(Eigen::AngleAxisd(std::atan(std::sqrt(2.0)), Vec3(1, -1, 0).normalized()));
  std::vector<RigidBody> bodies = {
      box_body("A", Vec3::Ones(), 1.0, Vec3(0.25, 0.1, std::sqrt(3.0) / 2 + 0.5 - 0.001), q,
               Vec3(0.1, 0, -1), Vec3(0.3, -0.2, 0.5)),
      box_body("B", Vec3::Ones(), 2.0, Vec3::Zero(), Quat::Identity(), Vec3::Zero(),
               Vec3(0, 0.1, 0))};
  const auto m = manifolds_of(bodies);
  ASSERT_EQ(m.size(), 1u);
  ASSERT_EQ(m[0].manifold.points.size(), 1u);
  std::vector<RigidBody> seed = bodies;
  ContactPoint c = m[0].manifold.detector_contact;
  c.point = m[0].manifold.points[0].point;
  apply_impulse(seed[0], seed[1], c, 0.5);
  solve_contact_velocities(bodies, m, normal_velocities(bodies, m), settings(0.5, 0.0));
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR((bodies[i].velocity - seed[i].velocity).norm(), 0.0, 1e-14);
    EXPECT_NEAR((bodies[i].angular_velocity - seed[i].angular_velocity).norm(), 0.0, 1e-14);
  }
}

TEST(ContactSolver, FlatLandingStopsWithoutTurningAndFrictionTakesMuJ) {
  // Unit cube landing flat at (2, 0, -1) m/s on a static slab, e = 0, mu = 0.3: J = 1 N s,
  // friction mu J = 0.3 N s against the slip, no spin (friction/landing_slide's landing).
  std::vector<RigidBody> bodies = {
      box_body("cube", Vec3::Ones(), 1.0, Vec3(0, 0, 0.4999), Quat::Identity(), Vec3(2, 0, -1)),
      box_body("slab", Vec3(10, 10, 1), 1.0, Vec3(0, 0, -0.5), Quat::Identity(), Vec3::Zero(),
               Vec3::Zero(), true)};
  const auto m = manifolds_of(bodies);
  ASSERT_EQ(m[0].manifold.points.size(), 4u);
  const auto solved =
      solve_contact_velocities(bodies, m, normal_velocities(bodies, m), settings(0.0, 0.3));
  double jn = 0.0;
  Vec3 jt = Vec3::Zero();
  for (const SolvedPoint& p : solved) {
    jn += p.normal_impulse;
    jt += p.friction_impulse;
    // Every corner slides: its friction is on its cone's edge, against the slip (-x).
    EXPECT_NEAR(p.friction_impulse.norm(), 0.3 * p.normal_impulse, 1e-12);
  }
  EXPECT_NEAR(jn, 1.0, 1e-12);
  EXPECT_NEAR((jt - Vec3(-0.3, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((bodies[0].velocity - Vec3(1.7, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(bodies[0].angular_velocity.norm(), 0.0, 1e-12);
}

TEST(ContactSolver, SticksWhenTheConeHoldsTheSlip) {
  // Slow slip (0.1 m/s) under a 1 N s landing with mu = 0.5: stopping the slip needs 0.1 N s
  // < 0.5 N s, so the base sticks: no tangential velocity left.
  std::vector<RigidBody> bodies = {box_body("cube", Vec3::Ones(), 1.0, Vec3(0, 0, 0.4999),
                                            Quat::Identity(), Vec3(0.1, 0.05, -1)),
                                   box_body("slab", Vec3(10, 10, 1), 1.0, Vec3(0, 0, -0.5),
                                            Quat::Identity(), Vec3::Zero(), Vec3::Zero(), true)};
  const auto m = manifolds_of(bodies);
  solve_contact_velocities(bodies, m, normal_velocities(bodies, m), settings(0.0, 0.5));
  EXPECT_NEAR(bodies[0].velocity.norm(), 0.0, 1e-12);
  EXPECT_NEAR(bodies[0].angular_velocity.norm(), 0.0, 1e-12);
}

TEST(ContactSolver, FrictionNeverAddsEnergy) {
  // Fixed-seed random landings of a tilted or flat box on a slab or on a free box, with random
  // velocities, e in [0, 1] and mu in [0, 1.5]: the kinetic energy after the solve never
  // exceeds the energy before (1e-12 relative: round-off), and with e = 1 and mu = 0 on one
  // point it is kept.
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  int contacts = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Quat q = Quat(Eigen::AngleAxisd(0.3 * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized()));
    const bool free_b = trial % 2 == 1;
    std::vector<RigidBody> bodies = {
        box_body("A", Vec3(1, 0.7, 0.5), 1.0 + pos(rng),
                 Vec3(0.3 * u(rng), 0.3 * u(rng), 0.25 + 0.05 * u(rng)), q,
                 Vec3(u(rng), u(rng), -pos(rng)), Vec3(u(rng), u(rng), u(rng))),
        box_body("B", Vec3(3, 3, 1), 2.0, Vec3(0, 0, -0.5), Quat::Identity(),
                 free_b ? Vec3(u(rng), u(rng), 0.2 * pos(rng)) : Vec3::Zero(), Vec3::Zero(),
                 !free_b)};
    const auto m = manifolds_of(bodies);
    if (m.empty()) continue;
    ++contacts;
    const double before = kinetic(bodies);
    const double e = pos(rng), mu = 1.5 * pos(rng);
    solve_contact_velocities(bodies, m, normal_velocities(bodies, m), settings(e, mu));
    EXPECT_LE(kinetic(bodies), before * (1 + 1e-12) + 1e-15)
        << "trial " << trial << " e " << e << " mu " << mu << " points "
        << m[0].manifold.points.size() << " free " << free_b;
  }
  // Keep the sample representative: most trials touch.
  EXPECT_GT(contacts, 200);
}

TEST(ContactSolver, ProjectionMovesPosesOnlyAndUndoesAtMostThePenetration) {
  // A cube 1 cm into a static slab, pressed: the projection lifts it by less than 1 cm, towards
  // the slop, and leaves its velocity alone (no kinetic energy added).
  std::vector<RigidBody> bodies = {
      box_body("cube", Vec3::Ones(), 1.0, Vec3(0, 0, 0.49), Quat::Identity(), Vec3(0.3, 0, -0.2)),
      box_body("slab", Vec3(10, 10, 1), 1.0, Vec3(0, 0, -0.5), Quat::Identity(), Vec3::Zero(),
               Vec3::Zero(), true)};
  const auto m = manifolds_of(bodies);
  const Vec3 v = bodies[0].velocity;
  project_contact_positions(bodies, m);
  EXPECT_EQ(bodies[0].velocity, v);
  EXPECT_GT(bodies[0].position.z(), 0.49);
  EXPECT_LT(bodies[0].position.z(), 0.5);
  EXPECT_NEAR(bodies[0].angular_velocity.norm(), 0.0, 0.0);
}

}  // namespace
}  // namespace rbx
