// Impulse response: conservation laws, closed forms, and the seed corrections 3 and 4.
#include "engine/response.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::box_body;

// Random unit vector from a fixed-seed generator.
Vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

// Two spinning, moving, rotated boxes of unequal mass and a contact point between them.
struct Pair {
  RigidBody a, b;
  ContactPoint c;
};

Pair random_pair(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Quat qa = Quat(Eigen::AngleAxisd(3 * u(rng), random_unit(rng)));
  const Quat qb = Quat(Eigen::AngleAxisd(3 * u(rng), random_unit(rng)));
  Pair p{box_body("A", Vec3(1, 2, 0.5), 1.5, Vec3(u(rng), u(rng), u(rng)), qa,
                  Vec3(u(rng), u(rng), u(rng)), 2 * Vec3(u(rng), u(rng), u(rng))),
         box_body("B", Vec3(0.7, 0.3, 1.1), 4.0, Vec3(u(rng), u(rng), u(rng)) + Vec3(2, 0, 0), qb,
                  Vec3(u(rng), u(rng), u(rng)), 2 * Vec3(u(rng), u(rng), u(rng))),
         {}};
  p.c.point = 0.5 * (p.a.position + p.b.position) + 0.3 * Vec3(u(rng), u(rng), u(rng));
  p.c.normal = random_unit(rng);
  return p;
}

// Momentum of the pair: linear, and angular about the world origin.
Vec3 linear(const Pair& p) { return p.a.linear_momentum() + p.b.linear_momentum(); }
Vec3 angular(const Pair& p) { return p.a.angular_momentum() + p.b.angular_momentum(); }
double energy(const Pair& p) { return p.a.kinetic_energy() + p.b.kinetic_energy(); }

TEST(Response, MomentumConservedForAnyRestitution) {
  std::mt19937 rng(7);
  int applied = 0;
  for (int trial = 0; trial < 500; ++trial) {
    for (double e : {0.0, 0.3, 1.0}) {
      Pair p = random_pair(rng);
      const Vec3 l0 = linear(p), h0 = angular(p);
      const double scale = 1.0 + l0.norm() + h0.norm();
      if (apply_impulse(p.a, p.b, p.c, e) > 0) ++applied;
      // Round-off: a few operations on O(1) numbers, relative 1e-13 of the momentum scale.
      EXPECT_LT((linear(p) - l0).norm(), 1e-13 * scale);
      EXPECT_LT((angular(p) - h0).norm(), 1e-13 * scale);
    }
  }
  // The random contacts must actually exercise the impulse (about half approach).
  EXPECT_GT(applied, 400);
}

TEST(Response, EnergyConservedElasticNeverGainedInelastic) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 500; ++trial) {
    Pair elastic = random_pair(rng);
    Pair inelastic = elastic;
    const double e0 = energy(elastic);
    apply_impulse(elastic.a, elastic.b, elastic.c, 1.0);
    apply_impulse(inelastic.a, inelastic.b, inelastic.c, 0.5);
    // e = 1 conserves kinetic energy exactly in exact arithmetic; round-off ~1e-14 relative.
    EXPECT_NEAR(energy(elastic), e0, 1e-12 * e0);
    EXPECT_LE(energy(inelastic), e0 * (1 + 1e-12));
  }
}

TEST(Response, HeadOnUnequalMassesMatchOneDimensionalClosedForm) {
  // Two boxes on the x axis, A left moving right, B right moving left; contact normal from B
  // toward A is -x. 1-D closed form: v1' = (m1 v1 + m2 v2 + m2 e (v2 - v1)) / (m1 + m2),
  // v2' = (m1 v1 + m2 v2 + m1 e (v1 - v2)) / (m1 + m2).
  const double m1 = 1.0, m2 = 3.0, v1 = 2.0, v2 = -1.0;
  for (double e : {0.0, 0.25, 0.5, 1.0}) {
    RigidBody a =
        box_body("A", Vec3::Ones(), m1, Vec3(-0.5, 0, 0), Quat::Identity(), Vec3(v1, 0, 0));
    RigidBody b =
        box_body("B", Vec3::Ones(), m2, Vec3(0.5, 0, 0), Quat::Identity(), Vec3(v2, 0, 0));
    ContactPoint c{Vec3::Zero(), Vec3(-1, 0, 0), 0.0, "face"};
    apply_impulse(a, b, c, e);
    const double v1p = (m1 * v1 + m2 * v2 + m2 * e * (v2 - v1)) / (m1 + m2);
    const double v2p = (m1 * v1 + m2 * v2 + m1 * e * (v1 - v2)) / (m1 + m2);
    EXPECT_NEAR(a.velocity.x(), v1p, 1e-14);  // a handful of flops on O(1) values
    EXPECT_NEAR(b.velocity.x(), v2p, 1e-14);
    EXPECT_NEAR(a.angular_velocity.norm(), 0.0, 1e-14);  // central impact: no spin
  }
}

TEST(Response, SeparatingContactGetsNoImpulse) {
  RigidBody a = box_body("A", Vec3::Ones(), 1, Vec3(-0.5, 0, 0), Quat::Identity(), Vec3(-1, 0, 0));
  RigidBody b = box_body("B", Vec3::Ones(), 1, Vec3(0.5, 0, 0));
  const ContactPoint c{Vec3::Zero(), Vec3(-1, 0, 0), 0.0, "face"};
  EXPECT_EQ(apply_impulse(a, b, c, 1.0), 0.0);
  EXPECT_EQ(a.velocity, Vec3(-1, 0, 0));
}

TEST(Response, StaticBodyReflectsVelocityScaledByRestitution) {
  // A box falling face-first onto a static slab: v' = -e v, the slab does not move.
  for (double e : {0.0, 0.5, 1.0}) {
    RigidBody a = box_body("A", Vec3::Ones(), 2, Vec3(0, 0, 0.5), Quat::Identity(), Vec3(0, 0, -3));
    RigidBody slab = box_body("B", Vec3(10, 10, 1), 5, Vec3(0, 0, -0.5), Quat::Identity(),
                              Vec3::Zero(), Vec3::Zero(), true);
    const ContactPoint c{Vec3::Zero(), Vec3(0, 0, 1), 0.0, "face"};
    const double j = apply_impulse(a, slab, c, e);
    EXPECT_NEAR(j, 2 * 3 * (1 + e), 1e-13);  // j = (1 + e) m |v|
    EXPECT_NEAR(a.velocity.z(), 3 * e, 1e-14);
    EXPECT_EQ(slab.velocity, Vec3::Zero());
    EXPECT_EQ(slab.angular_velocity, Vec3::Zero());
  }
}

TEST(Response, CornerImpactClosedForm) {
  // Unit cube (m = 1, I = m a^2 / 6 = 1/6 isotropic) hits a static floor with its corner at
  // r = (-1/2, -1/2, -1/2) from the COM, v = (0, 0, -1), normal n = +z.
  // r x n = (-1/2, 1/2, 0); (r x n).I^-1(r x n) = 6 * 1/2 = 3; j = (1 + e) * 1 / (1 + 3).
  // v' = v + j n; w' = I^-1 (r x j n) = 6 j (-1/2, 1/2, 0).
  for (double e : {0.5, 1.0}) {
    RigidBody a = box_body("A", Vec3::Ones(), 1, Vec3(0, 0, 0.5), Quat::Identity(), Vec3(0, 0, -1));
    RigidBody floor = box_body("B", Vec3(10, 10, 1), 1, Vec3(0, 0, -0.5), Quat::Identity(),
                               Vec3::Zero(), Vec3::Zero(), true);
    const ContactPoint c{Vec3(-0.5, -0.5, 0), Vec3(0, 0, 1), 0.0, "vertex"};
    const double j = apply_impulse(a, floor, c, e);
    const double j_true = (1 + e) / 4.0;
    EXPECT_NEAR(j, j_true, 1e-14);
    EXPECT_LT((a.velocity - Vec3(0, 0, -1 + j_true)).norm(), 1e-14);
    EXPECT_LT((a.angular_velocity - 6 * j_true * Vec3(-0.5, 0.5, 0)).norm(), 1e-13);
  }
}

// The seed's printed impulse: (1 + e) on the linear term only, the angular terms added outside,
// j = (-(1+e)(v_a - v_b).n + (r_a x n).w_a - (r_b x n).w_b) / denominator.
double literal_seed_impulse(const RigidBody& a, const RigidBody& b, const ContactPoint& c,
                            double e) {
  const Vec3 ra = c.point - a.position, rb = c.point - b.position, n = c.normal;
  const Vec3 ran = ra.cross(n), rbn = rb.cross(n);
  const double denom = a.inverse_mass + b.inverse_mass + ran.dot(a.inverse_inertia_world() * ran) +
                       rbn.dot(b.inverse_inertia_world() * rbn);
  return (-(1 + e) * (a.velocity - b.velocity).dot(n) + ran.dot(a.angular_velocity) -
          rbn.dot(b.angular_velocity)) /
         denom;
}

TEST(Response, SeedNote3LiteralImpulseBreaksEnergyConservation) {
  // A spinning box hits a static floor: the literal formula mis-weights the angular part of
  // the relative velocity, so an elastic impact changes the kinetic energy; ours does not.
  // w = (0, -1, 0): the corner's velocity v + w x r = (0.5, 0, -1.5) approaches the floor.
  RigidBody a = box_body("A", Vec3::Ones(), 1, Vec3(0, 0, 0.5), Quat::Identity(), Vec3(0, 0, -1),
                         Vec3(0, -1, 0));
  RigidBody floor = box_body("B", Vec3(10, 10, 1), 1, Vec3(0, 0, -0.5), Quat::Identity(),
                             Vec3::Zero(), Vec3::Zero(), true);
  const ContactPoint c{Vec3(-0.5, -0.5, 0), Vec3(0, 0, 1), 0.0, "vertex"};
  const double e0 = a.kinetic_energy();
  const double j_seed = literal_seed_impulse(a, floor, c, 1.0);
  RigidBody seed = a;
  const Vec3 imp = j_seed * c.normal, ra = c.point - a.position;
  seed.velocity += seed.inverse_mass * imp;
  seed.angular_velocity += seed.inverse_inertia_world() * ra.cross(imp);
  EXPECT_GT(std::abs(seed.kinetic_energy() - e0), 0.1 * e0);  // the literal text fails
  // Ours: j = 2 * 1.5 / 4 = 0.75; the literal text gives (2 - 0.5) / 4 = 0.375.
  EXPECT_NEAR(j_seed, 0.375, 1e-14);
  EXPECT_NEAR(apply_impulse(a, floor, c, 1.0), 0.75, 1e-14);
  EXPECT_NEAR(a.kinetic_energy(), e0, 1e-13 * e0);  // the corrected one conserves energy
}

TEST(Response, SeedNote4LiteralUpdatesBreakMomentumConservation) {
  // The seed: v_a -= J/m_a n and v_b -= J/m_b n (both subtract). Total momentum changes by
  // -2 J n, whereas the corrected update conserves it.
  std::mt19937 rng(3);
  Pair p = random_pair(rng);
  p.a.velocity = Vec3(1, 0, 0);
  p.b.velocity = Vec3(-1, 0, 0);
  p.c.normal = Vec3(-1, 0, 0);
  const double j = impulse_magnitude(p.a, p.b, p.c, 1.0);
  ASSERT_GT(j, 0);
  const Vec3 seed_total = (p.a.velocity - j * p.a.inverse_mass * p.c.normal) * p.a.mass +
                          (p.b.velocity - j * p.b.inverse_mass * p.c.normal) * p.b.mass;
  const Vec3 l0 = linear(p);
  EXPECT_NEAR((seed_total - l0).norm(), 2 * j, 1e-12);
  apply_impulse(p.a, p.b, p.c, 1.0);
  EXPECT_LT((linear(p) - l0).norm(), 1e-13);
}

TEST(Response, WorldInverseInertiaUsesRotation) {
  // seed correction 5 (world-frame inverse inertia, static bodies zero): the impulse uses R Ib^-1
  // R^T. A 1 x 2 x 3 box rotated 90 deg about z swaps its x and y principal moments in the world
  // frame.
  const Quat q(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
  RigidBody a = box_body("A", Vec3(1, 2, 3), 12, Vec3::Zero(), q);
  const Mat3 iw = a.inertia_world();
  // Body moments: m (b^2 + c^2)/12 = 13, m (a^2 + c^2)/12 = 10, m (a^2 + b^2)/12 = 5.
  EXPECT_NEAR(iw(0, 0), 10, 1e-12);
  EXPECT_NEAR(iw(1, 1), 13, 1e-12);
  EXPECT_NEAR(iw(2, 2), 5, 1e-12);
  EXPECT_LT((a.inverse_inertia_world() * iw - Mat3::Identity()).norm(), 1e-13);
}

TEST(Response, ImpulseOnARotatedBodyUsesTheWorldInertia) {
  // seed correction 5 (world-frame inverse inertia, static bodies zero) inside the impulse. The
  // same box (world moments 10, 13, 5) moves at -1 m/s along x into a static body; contact normal n
  // = +x at r = (0, 0, 1) from its centre, so r x n = (0, 1, 0) and only the world yy moment (13)
  // enters:
  //   j = -(1 + e) v_rel.n / (1/m + 1/13) = 2 / (1/12 + 1/13) = 12.48 (e = 1),
  //   dw = I_w^-1 (r x j n) = (0, j/13, 0) = (0, 0.96, 0),  dv = j/m n = (1.04, 0, 0).
  // With the body-frame inverse the yy moment would be 10: j = 10.909, dw_y = 1.0909.
  const Quat q(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
  RigidBody a = box_body("A", Vec3(1, 2, 3), 12, Vec3::Zero(), q, Vec3(-1, 0, 0));
  RigidBody b = box_body("B", Vec3(1, 1, 1), 1, Vec3(-5, 0, 0), Quat::Identity(), Vec3::Zero(),
                         Vec3::Zero(), true);
  ContactPoint c;
  c.point = Vec3(0, 0, 1);
  c.normal = Vec3(1, 0, 0);
  const double j = apply_impulse(a, b, c, 1.0);
  // A handful of operations on O(10) numbers.
  EXPECT_NEAR(j, 12.48, 1e-12);
  EXPECT_LT((a.angular_velocity - Vec3(0, 0.96, 0)).norm(), 1e-13);
  EXPECT_LT((a.velocity - Vec3(0.04, 0, 0)).norm(), 1e-13);
  EXPECT_EQ(b.velocity, Vec3::Zero());
}

}  // namespace
}  // namespace rbx
